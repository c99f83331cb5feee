//! Which OME-Zarr chunks a read takes from the file: only those a view may see
//! (`may_see_voxels`), and none that a `ChunkCache` holds. A view that moves, and so reads a new
//! part of the image (`VolumeHints::crop` and `view`), reads from the file only the chunks it did
//! not read before, while the cache holds them. Chunks are let go least recently used first.
use crate::error::Result;
use std::collections::{HashMap, HashSet};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// One chunk of one image: the image's folder, the level's array path, the fixed indices before
/// the spatial axes (time point, channel) and the chunk's index in the array's chunk grid.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) struct ChunkKey {
    pub image: PathBuf,
    pub level: String,
    pub lead: Vec<u64>,
    pub chunk: Vec<u64>,
}

/// What a `ChunkCache` has done since it was made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ChunkCacheStats {
    /// Chunks read from the file and decoded (not held when asked for).
    pub reads: u64,
    /// Chunks found held.
    pub hits: u64,
    /// Chunks let go to stay within the budget.
    pub evicted: u64,
    /// Bytes of decoded samples held now.
    pub held_bytes: u64,
}

struct Inner {
    budget: u64,
    /// Uses so far: each held chunk keeps the count at its last use.
    clock: u64,
    /// The clock when the latest read began (`begin_read`): chunks used since serve that read.
    read_began: u64,
    /// The chunks the latest read will use, when it said (`ZarrReader::pin`).
    pinned: HashSet<ChunkKey>,
    chunks: HashMap<ChunkKey, (Arc<Samples>, u64)>,
    stats: ChunkCacheStats,
}

/// Decoded chunks of OME-Zarr images (the spatial part of one chunk at one time point and channel;
/// 8- and 16-bit integers held as stored, other samples as f32) held within a byte budget and
/// shared by the reads given it (`VolumeHints::chunk_cache`). Clones share one cache. A chunk
/// larger than the budget is read and not held. Room is made by letting go of the least recently
/// used chunk, but never of one the current read has used or will use (`ZarrReader::pin`): a read
/// of more than the budget keeps its first chunks, and a read of another part keeps those of its
/// chunks that are held until it reaches them (least recently used alone would let each go
/// before the next read, in the same order, reached it). Reads on several threads may share one
/// cache and each gets the right samples, but the pins are those of the read that began last: a
/// concurrent read's chunks may be let go and read again.
#[derive(Clone)]
pub struct ChunkCache(Arc<Mutex<Inner>>);

impl std::fmt::Debug for ChunkCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = self.stats();
        write!(f, "ChunkCache {{ budget: {}, {s:?} }}", self.budget())
    }
}

impl ChunkCache {
    /// A cache holding at most `budget_bytes` of decoded samples, checked against the host budget
    /// (`set_host_budget`) and the memory available.
    pub fn new(budget_bytes: u64) -> Result<Self> {
        crate::error::check_host_memory(budget_bytes, "the OME-Zarr chunk cache")?;
        Ok(ChunkCache(Arc::new(Mutex::new(Inner {
            budget: budget_bytes,
            clock: 0,
            // No read begun: none kept from being let go.
            read_began: u64::MAX,
            pinned: HashSet::new(),
            chunks: HashMap::new(),
            stats: ChunkCacheStats::default(),
        }))))
    }

    fn inner(&self) -> std::sync::MutexGuard<'_, Inner> {
        // A read that failed while another held the lock left the map whole: take it.
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Its budget in bytes.
    pub fn budget(&self) -> u64 {
        self.inner().budget
    }

    /// What it has done so far.
    pub fn stats(&self) -> ChunkCacheStats {
        self.inner().stats
    }

    /// A new read begins (a reader of one level and part): neither the chunks it uses from now
    /// on nor those `pinned` (the chunks it will use, where known) are let go while it lasts.
    pub(super) fn begin_read(&self, pinned: HashSet<ChunkKey>) {
        let mut c = self.inner();
        c.read_began = c.clock + 1;
        c.pinned = pinned;
    }

    /// The chunk at `key`: held, or `read` and then held when it fits the budget (the least
    /// recently used let go to make room, unless the current read used it or will).
    pub(super) fn get_or_read(&self, key: ChunkKey, read: impl FnOnce() -> Result<Samples>) -> Result<Arc<Samples>> {
        {
            let mut c = self.inner();
            c.clock += 1;
            let now = c.clock;
            if let Some((values, used)) = c.chunks.get_mut(&key) {
                *used = now;
                let values = values.clone();
                c.stats.hits += 1;
                return Ok(values);
            }
        }
        // Read with the lock let go: a read takes milliseconds, and fails without touching the map.
        let values = Arc::new(read()?);
        let bytes = values.bytes();
        let mut c = self.inner();
        c.stats.reads += 1;
        if bytes > c.budget {
            return Ok(values);
        }
        while c.stats.held_bytes + bytes > c.budget {
            let began = c.read_began;
            let free = c.chunks.iter().filter(|(k, (_, used))| *used < began && !c.pinned.contains(*k));
            let Some(oldest) = free.min_by_key(|(_, (_, used))| *used).map(|(k, _)| k.clone()) else {
                // Every chunk held serves this read: the new one is not held.
                return Ok(values);
            };
            let (gone, _) = c.chunks.remove(&oldest).expect("found above");
            c.stats.held_bytes -= gone.bytes();
            c.stats.evicted += 1;
        }
        let now = c.clock;
        if let Some((old, _)) = c.chunks.insert(key, (values.clone(), now)) {
            // Another clone read the same chunk meanwhile: count it once.
            c.stats.held_bytes -= old.bytes();
        }
        c.stats.held_bytes += bytes;
        Ok(values)
    }
}

/// Whether `camera` may see voxels `start..end` (x, y, z) of `grid` (a level's, centred) or the
/// brick around them, whose gradients and levels of detail read them (`Camera::may_see_box`,
/// `margin` pixels past the image's edges).
pub(super) fn may_see_voxels(
    camera: &crate::Camera,
    margin: f32,
    grid: &crate::Grid,
    start: [u64; 3],
    end: [u64; 3],
) -> bool {
    let pad = glam::Vec3::splat(crate::constants::BRICK_SIDE as f32);
    let [lo, hi] = [start, end.map(|e| e - 1)].map(|c| glam::Vec3::from(c.map(|v| v as f32)));
    let [lo, hi] = grid.world_box(lo - pad, hi + pad);
    camera.may_see_box(lo, hi, margin)
}

/// Where a subset of an array with `lead` axes before the spatial ones lies: its first voxel and
/// shape along z, y, x.
pub(super) fn spatial(s: &zarrs::array::ArraySubset, lead: usize) -> Block {
    let (start, shape) = (s.start(), s.shape());
    ([0, 1, 2].map(|a| start[lead + a]), [0, 1, 2].map(|a| shape[lead + a]))
}

/// Whether the view `seen` (camera and margin; `None`: every voxel) may see `block` of `grid`.
pub(super) fn may_see_block(seen: Option<&(crate::Camera, f32)>, grid: &crate::Grid, (start, shape): Block) -> bool {
    // Array order is z, y, x.
    let (xyz, end) = ([2, 1, 0].map(|a| start[a]), [2, 1, 0].map(|a| start[a] + shape[a]));
    seen.is_none_or(|(camera, margin)| may_see_voxels(camera, *margin, grid, xyz, end))
}

/// A chunk's samples, decoded: 8- and 16-bit integers as the file stores them (a cache holds four
/// or two times the chunks it would as f32), the others as f32.
#[derive(Debug)]
pub(super) enum Samples {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    F32(Vec<f32>),
}

impl Samples {
    pub fn len(&self) -> usize {
        match self {
            Samples::U8(v) => v.len(),
            Samples::I8(v) => v.len(),
            Samples::U16(v) => v.len(),
            Samples::I16(v) => v.len(),
            Samples::F32(v) => v.len(),
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        let size = match self {
            Samples::U8(_) | Samples::I8(_) => 1,
            Samples::U16(_) | Samples::I16(_) => 2,
            Samples::F32(_) => 4,
        };
        self.len() as u64 * size
    }

    /// Samples `from..from + out.len()` as f32 into `out`.
    fn row_into(&self, from: usize, out: &mut [f32]) {
        let n = out.len();
        match self {
            Samples::U8(v) => out.iter_mut().zip(&v[from..from + n]).for_each(|(o, &s)| *o = s.into()),
            Samples::I8(v) => out.iter_mut().zip(&v[from..from + n]).for_each(|(o, &s)| *o = s.into()),
            Samples::U16(v) => out.iter_mut().zip(&v[from..from + n]).for_each(|(o, &s)| *o = s.into()),
            Samples::I16(v) => out.iter_mut().zip(&v[from..from + n]).for_each(|(o, &s)| *o = s.into()),
            Samples::F32(v) => out.copy_from_slice(&v[from..from + n]),
        }
    }

    /// All of them as f32.
    pub fn into_f32(self) -> Vec<f32> {
        match self {
            Samples::F32(v) => v,
            other => {
                let mut out = vec![0.0; other.len()];
                other.row_into(0, &mut out);
                out
            }
        }
    }
}

/// A box of samples in array order (z, y, x): its first voxel and its shape.
pub(super) type Block = ([u64; 3], [u64; 3]);

/// The part `part` of `block` (its samples `values`, x fastest) copied into `out`, the samples of
/// the box `to` (x fastest).
pub(super) fn copy_part(out: &mut [f32], to: Block, block: Block, values: &Samples, part: Block) {
    let ((os, on), (bs, bn), (ps, pn)) = (to, block, part);
    let row = pn[2] as usize;
    for z in ps[0]..ps[0] + pn[0] {
        for y in ps[1]..ps[1] + pn[1] {
            let at = (((z - os[0]) * on[1] + y - os[1]) * on[2] + ps[2] - os[2]) as usize;
            let from = (((z - bs[0]) * bn[1] + y - bs[1]) * bn[2] + ps[2] - bs[2]) as usize;
            values.row_into(from, &mut out[at..at + row]);
        }
    }
}

/// Refuses a level that stores no chunk (`holds_a_chunk`): missing chunks read as the fill value,
/// so the array is one value throughout, and reading it (a 24 KB file declaring 2048^3) ran for
/// minutes before drawing nothing.
pub(super) fn some_chunk_stored(dir: &std::path::Path, level: u32, path: &str, what: &str) -> Result<()> {
    if holds_a_chunk(dir) {
        return Ok(());
    }
    Err(super::bad(
        what,
        format!("level {level} ({path}) stores no chunk: every voxel is the array's fill value, nothing to draw"),
    ))
}

/// Whether an array's folder holds a file besides its metadata: a stored chunk (v2 `0.0.0` or
/// `0/0/0`, v3 `c/0/0/0`, or a shard). Stops at the first.
fn holds_a_chunk(dir: &std::path::Path) -> bool {
    let mut folders = vec![dir.to_path_buf()];
    while let Some(d) = folders.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let name = e.file_name();
            match e.file_type() {
                Ok(t) if t.is_dir() => folders.push(e.path()),
                Ok(_)
                    if ![".zarray", ".zattrs", ".zgroup", ".zmetadata", "zarr.json"]
                        .contains(&&*name.to_string_lossy()) =>
                {
                    return true
                }
                _ => {}
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(i: u64) -> ChunkKey {
        ChunkKey { image: "a.zarr".into(), level: "0".into(), lead: vec![], chunk: vec![i, 0, 0] }
    }

    #[test]
    fn the_least_recently_used_chunk_goes_first_and_a_chunk_past_the_budget_is_not_held() {
        // Room for two chunks of 4 samples.
        let cache = ChunkCache::new(32).unwrap();
        let read = |v: f32| move || Ok(Samples::F32(vec![v; 4]));
        let first = |s: Arc<Samples>| {
            let mut v = [0.0];
            s.row_into(0, &mut v);
            v[0]
        };
        assert_eq!(first(cache.get_or_read(key(0), read(0.0)).unwrap()), 0.0);
        assert_eq!(first(cache.get_or_read(key(1), read(1.0)).unwrap()), 1.0);
        // Chunk 0 used again: chunk 1 is the older when chunk 2 comes.
        let held = cache.get_or_read(key(0), || panic!("held")).unwrap();
        assert_eq!(first(held), 0.0);
        cache.get_or_read(key(2), read(2.0)).unwrap();
        let s = cache.stats();
        assert_eq!((s.reads, s.hits, s.evicted, s.held_bytes), (3, 1, 1, 32));
        cache.get_or_read(key(0), || panic!("still held")).unwrap();
        assert_eq!(first(cache.get_or_read(key(1), read(1.5)).unwrap()), 1.5, "chunk 1 was let go and read again");
        // Nine samples are 36 bytes: read, handed back, not held.
        let big = cache.get_or_read(key(3), || Ok(Samples::F32(vec![3.0; 9]))).unwrap();
        assert_eq!(big.len(), 9);
        let s = cache.stats();
        assert_eq!((s.reads, s.hits, s.evicted, s.held_bytes), (5, 2, 2, 32));
        // A failed read holds nothing.
        let e = cache.get_or_read(key(4), || Err(crate::Error::InvalidArgument("broken".into())));
        assert!(e.is_err());
        assert_eq!(cache.stats().reads, 5);
        // 8-bit samples are held as stored: 32 of them fit where 8 f32 do, and read back as f32.
        let cache = ChunkCache::new(32).unwrap();
        let bytes = (0..32u8).collect::<Vec<_>>();
        let held = cache.get_or_read(key(0), || Ok(Samples::U8(bytes))).unwrap();
        assert_eq!(cache.stats().held_bytes, 32);
        let mut row = [0.0; 3];
        held.row_into(29, &mut row);
        assert_eq!(row, [29.0, 30.0, 31.0]);
        assert_eq!(Samples::I16(vec![-3, 7]).into_f32(), vec![-3.0, 7.0]);
    }

    #[test]
    fn a_read_larger_than_the_budget_keeps_its_first_chunks_for_the_next() {
        // Room for two of the three chunks each read uses, in the same order each time.
        let cache = ChunkCache::new(32).unwrap();
        for _ in 0..3 {
            cache.begin_read(HashSet::new());
            for i in 0..3 {
                cache.get_or_read(key(i), || Ok(Samples::F32(vec![i as f32; 4]))).unwrap();
            }
        }
        // Least recently used alone would let chunk 0 go for chunk 2, then 1 for 0, and so on:
        // no read would find any held.
        let s = cache.stats();
        assert_eq!((s.reads, s.hits, s.evicted, s.held_bytes), (5, 4, 0, 32));
        // A read that will use chunks 1 and 2 keeps them when chunk 5 comes: chunk 0 goes.
        cache.begin_read([key(1), key(2)].into_iter().collect());
        cache.get_or_read(key(5), || Ok(Samples::F32(vec![5.0; 4]))).unwrap();
        cache.get_or_read(key(1), || panic!("kept")).unwrap();
        assert_eq!(cache.stats().evicted, 1);
        // A read of other chunks lets the earlier read's go.
        cache.begin_read(HashSet::new());
        cache.get_or_read(key(7), || Ok(Samples::F32(vec![7.0; 4]))).unwrap();
        assert_eq!(cache.stats().evicted, 2);
        cache.get_or_read(key(7), || panic!("held")).unwrap();
    }
}
