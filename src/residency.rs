//! What a streamed bricked store keeps on the device across frames: its bricks' records, in a
//! cache of whole-brick slots (`RecordCache`).
use crate::error::{Error, Result};

/// A tag no other cache has had (0 is never one).
fn next_tag() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// A scene's record cache behind a lock; a clone of the scene starts with an empty one (what a
/// device holds belongs to the scene that put it there).
#[derive(Default)]
pub(crate) struct CacheCell(pub std::sync::Mutex<RecordCache>);

impl Clone for CacheCell {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for CacheCell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("CacheCell")
    }
}

/// Words of a slot of the record cache: a brick's most records.
pub const SLOT_WORDS: u64 = (crate::constants::BRICK_SIDE as u64).pow(3);

/// A batch placed in the cache: per brick its slot; the bricks to upload (index, slot).
pub type Placed = (Vec<u32>, Vec<(usize, u32)>);

/// Which bricks' records a streamed store keeps on the device (`Res::BatchRecords`), in slots of
/// `SLOT_WORDS`, across frames: a batch uploads only the records of bricks the cache lacks. Each
/// frame draws a brick once, in nearly the order the last frame did, so plain least-recently-used
/// eviction would drop each brick just before the next frame asks for it again whenever the
/// bricks a frame reads pass the cache. The slot given up is instead the one needed last as far
/// as the last frame tells (Belady's choice): a free slot; else one neither this frame nor the
/// last used (least recently used first); else the one this frame used last (its brick returns
/// latest next frame); else the one the last frame used last. A stable part of the working set
/// so stays, and an orbit re-uploads what it brings into view plus what the cache cannot hold.
/// Valid while the device buffer carries `tag` (`Engine::tag`; a replaced buffer, or another
/// engine, forgets it).
#[derive(Default)]
pub struct RecordCache {
    tag: u64,
    slot_of: std::collections::HashMap<u32, u32>,
    /// Per slot, its brick (`u32::MAX`: free) and the batch that last used it.
    holder: Vec<u32>,
    used: Vec<u64>,
    /// Slots never used yet, the last taken first.
    free: Vec<u32>,
    /// (last use, slot) of the slots that hold a brick, oldest first.
    by_use: std::collections::BTreeSet<(u64, u32)>,
    /// The batch being placed, and the first batch of this frame and of the last.
    batch: u64,
    frame_start: u64,
    last_start: u64,
}

impl RecordCache {
    /// A frame begins with the device buffer tagged `tag` holding `slots` slots: the cache is kept
    /// when it describes that buffer, else emptied and given a new tag (returned: the caller tags
    /// the buffer with it).
    pub fn open(&mut self, tag: u64, slots: u32) -> u64 {
        if tag == 0 || tag != self.tag || self.holder.len() != slots as usize {
            *self = Self {
                tag: next_tag(),
                holder: vec![u32::MAX; slots as usize],
                used: vec![0; slots as usize],
                free: (0..slots).rev().collect(),
                ..Default::default()
            };
        }
        (self.last_start, self.frame_start) = (self.frame_start, self.batch + 1);
        self.tag
    }

    /// Drop every brick (a pass over the whole store, which says nothing of what frames read).
    pub fn forget(&mut self) {
        let slots = self.slots();
        self.slot_of.clear();
        self.holder.fill(u32::MAX);
        self.free = (0..slots).rev().collect();
        self.by_use.clear();
        (self.last_start, self.frame_start) = (self.batch + 1, self.batch + 1);
    }

    /// Drop the bricks of these headers (their records changed), keeping the rest.
    pub fn evict(&mut self, headers: &[u32]) {
        for h in headers {
            if let Some(s) = self.slot_of.remove(h) {
                self.by_use.remove(&(self.used[s as usize], s));
                self.holder[s as usize] = u32::MAX;
                self.free.push(s);
            }
        }
    }

    /// Slots of the cache.
    pub fn slots(&self) -> u32 {
        self.holder.len() as u32
    }

    /// Slots that hold a brick.
    pub fn held(&self) -> u32 {
        self.slots() - self.free.len() as u32
    }

    /// The slot to give up for a brick of the current batch (see the type's note).
    fn victim(&self) -> Option<(u64, u32)> {
        let oldest = self.by_use.first().copied().filter(|&(u, _)| u < self.last_start);
        let this_frame =
            self.by_use.range(..(self.batch, 0)).next_back().copied().filter(|&(u, _)| u >= self.frame_start);
        let last_frame = self.by_use.range(..(self.frame_start, 0)).next_back().copied();
        oldest.or(this_frame).or(last_frame)
    }

    /// Place one batch's bricks (`headers`, at most `slots` of them): per brick its slot, and
    /// the bricks that must be uploaded (index into `headers`, slot). Bricks of this batch are
    /// never evicted for one another.
    pub fn place(&mut self, headers: &[u32]) -> Result<Placed> {
        self.batch += 1;
        let (mut slots, mut new) = (Vec::with_capacity(headers.len()), Vec::new());
        for (i, &h) in headers.iter().enumerate() {
            let slot = match self.slot_of.get(&h) {
                Some(&s) => {
                    self.by_use.remove(&(self.used[s as usize], s));
                    s
                }
                None => {
                    let s = match self.free.pop() {
                        Some(s) => s,
                        None => {
                            let Some((u, s)) = self.victim() else {
                                return Err(Error::TooLarge(format!(
                                    "a batch of {} bricks in a record cache of {} slots",
                                    headers.len(),
                                    self.slots()
                                )));
                            };
                            self.by_use.remove(&(u, s));
                            self.slot_of.remove(&self.holder[s as usize]);
                            s
                        }
                    };
                    self.holder[s as usize] = h;
                    self.slot_of.insert(h, s);
                    new.push((i, s));
                    s
                }
            };
            self.used[slot as usize] = self.batch;
            self.by_use.insert((self.batch, slot));
            slots.push(slot);
        }
        Ok((slots, new))
    }
}
