//! A series' next time point swapped into a store in place (`BrickStore::patch`), so that a device
//! holding the store rewrites only the bricks that changed (`Renderer::update_volume`).
use super::{BrickHeader, BrickStore, BRICK_VOXELS};
use crate::error::{Error, Result};

/// What `BrickStore::patch` changed: what a device holding the store must rewrite.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Patch {
    /// Bricks whose voxels changed, appeared or went empty.
    pub changed: usize,
    /// Whether the set of non-empty bricks changed: the headers, masks and brick index are
    /// replaced whole (they are small beside the records).
    pub layout: bool,
    /// Whether the records were laid out afresh (holes had passed the live records): all are
    /// rewritten.
    pub compacted: bool,
    /// Positions of the headers (and masks) that changed, when `layout` is false.
    pub headers: Vec<u32>,
    /// The record ranges written: (first record, records).
    pub records: Vec<[u32; 2]>,
}

impl BrickStore {
    /// Make this store `next` (the same grid, normalised by the same range: a time point built
    /// with `from_region(.., self.range, ..)`), keeping the records of every brick that did not
    /// change where they lie. A changed brick's records are written over its old ones when they
    /// fit, else after the last record; a brick that went empty leaves a hole. When the holes
    /// pass the live records, the records are laid out afresh. Values equal `next`'s voxel for
    /// voxel (`value_at`); the returned `Patch` says what moved.
    pub fn patch(&mut self, next: BrickStore) -> Result<Patch> {
        if (self.dims, self.spacing, self.shear) != (next.dims, next.spacing, next.shear) {
            return Err(Error::InvalidArgument(format!(
                "a time point of {:?} voxels spaced {:?} (shear {:?}) replaces one of {:?} spaced {:?} (shear {:?}): \
                 a series keeps its grid",
                next.dims, next.spacing, next.shear, self.dims, self.spacing, self.shear
            )));
        }
        if self.range != next.range {
            return Err(Error::InvalidArgument(format!(
                "a time point normalised by {:?} replaces one normalised by {:?}: build it with \
                 BrickStore::from_region(.., store.range, ..), so that its bricks quantise alike",
                next.range, self.range
            )));
        }
        let layout = self.headers.len() != next.headers.len()
            || self.headers.iter().zip(&next.headers).any(|(a, b)| a.brick != b.brick);
        let mut patch = Patch { layout, ..Default::default() };
        let mut records = std::mem::take(&mut self.records);
        let mut headers = Vec::with_capacity(next.headers.len());
        let nb = self.dims.map(|d| d.div_ceil(super::BRICK));
        for (i, nh) in next.headers.iter().enumerate() {
            let [x, y, z] = nh.coords();
            let old = self.index[(x + nb[0] * (y + nb[1] * z)) as usize];
            let old = (old != u32::MAX).then(|| (self.headers[old as usize], &self.masks[old as usize]));
            let fresh: &[u32] =
                if nh.is_uniform() { &[] } else { &next.records[nh.first as usize..(nh.first + nh.count) as usize] };
            if let Some((oh, om)) = old {
                let same_records = if nh.is_uniform() {
                    oh.first == nh.first
                } else {
                    !oh.is_uniform() && records[oh.first as usize..(oh.first + oh.count) as usize] == *fresh
                };
                if oh.count == nh.count && oh.range == nh.range && *om == next.masks[i] && same_records {
                    headers.push(oh);
                    continue;
                }
            }
            patch.changed += 1;
            let first = match old {
                _ if nh.is_uniform() => nh.first,
                // Over the old records when the new ones fit there.
                Some((oh, _)) if !oh.is_uniform() && nh.count <= oh.count => {
                    records[oh.first as usize..(oh.first + nh.count) as usize].copy_from_slice(fresh);
                    oh.first
                }
                _ => {
                    records.extend_from_slice(fresh);
                    (records.len() - fresh.len()) as u32
                }
            };
            if !nh.is_uniform() {
                patch.records.push([first, nh.count]);
            }
            if !layout {
                patch.headers.push(i as u32);
            }
            headers.push(BrickHeader { first, ..*nh });
        }
        if layout {
            patch.changed += self.headers.iter().filter(|h| next_index(&next, h, nb) == u32::MAX).count();
        }
        let live: usize = headers.iter().filter(|h| !h.is_uniform()).map(|h| h.count as usize).sum();
        if records.len() > 2 * live + BRICK_VOXELS || records.len() >= super::UNIFORM_RECORDS as usize {
            let mut packed = Vec::with_capacity(live);
            for h in headers.iter_mut().filter(|h| !h.is_uniform()) {
                let at = packed.len() as u32;
                packed.extend_from_slice(&records[h.first as usize..(h.first + h.count) as usize]);
                h.first = at;
            }
            records = packed;
            patch.compacted = true;
            patch.records = vec![[0, records.len() as u32]];
        }
        (self.headers, self.masks, self.index, self.records) = (headers, next.masks, next.index, records);
        Ok(patch)
    }
}

/// The header `h`'s brick has in `next` (`u32::MAX`: none).
fn next_index(next: &BrickStore, h: &BrickHeader, nb: [u32; 3]) -> u32 {
    let [x, y, z] = h.coords();
    next.index[(x + nb[0] * (y + nb[1] * z)) as usize]
}
