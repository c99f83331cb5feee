//! Building a store from slices (`BrickStore::from_slices`, `from_region`), and its uniform
//! bricks: a full brick whose voxels all hold one value stores no records, only its header (a
//! constant or flat region costs 80 bytes a brick, not 4 a voxel: an all-zero 1024³ file of 1 MB
//! took 4.4 GB).
use super::{local_cell, BrickHeader, BrickStore, BRICK, BRICK_VOXELS, Q};
use crate::error::{Error, Result};
use crate::volume::ScalarVolume;
use std::borrow::Cow;

/// A uniform brick's first record: this bit, then its quantised value from bit 9, so that record
/// `first + r` of it is `r | value << 16` (`record_at`; every voxel stored, rank = local index).
pub const UNIFORM_RECORDS: u32 = 1 << 31;

/// Mirror of `record_at` in glsl/shared/brick.glsl: record `i` of `records`, or of a uniform brick.
pub fn record_at(records: &[u32], i: u32) -> u32 {
    if i & UNIFORM_RECORDS != 0 {
        (i & 511) | ((i >> 9) & 0xffff) << 16
    } else {
        records[i as usize]
    }
}

impl BrickHeader {
    /// Whether the brick stores no records: every voxel of it holds `range`'s one value.
    pub fn is_uniform(&self) -> bool {
        self.first & UNIFORM_RECORDS != 0
    }
}

impl BrickStore {
    /// The records of brick `hd` (made for a uniform brick), reading `records` from `first` (the
    /// store's, or a batch's).
    pub fn records_of<'a>(records: &'a [u32], first: u32, hd: &BrickHeader) -> Cow<'a, [u32]> {
        if first & UNIFORM_RECORDS != 0 {
            Cow::Owned((0..hd.count).map(|r| record_at(records, first + r)).collect())
        } else {
            Cow::Borrowed(&records[first as usize..(first + hd.count) as usize])
        }
    }

    /// The store's records of brick `hd` (`records_of`).
    pub fn brick_records(&self, hd: &BrickHeader) -> Cow<'_, [u32]> {
        Self::records_of(&self.records, hd.first, hd)
    }

    /// Voxels of brick `hd` whose quantised value `emits` extracts: a uniform brick's from its
    /// one value, without making its records.
    pub fn drawn_in(&self, hd: &BrickHeader, emits: impl Fn(u32) -> bool) -> u32 {
        if hd.is_uniform() {
            return if emits(hd.range & 0xffff) { hd.count } else { 0 };
        }
        self.brick_records(hd).iter().filter(|&&r| emits(r >> 16)).count() as u32
    }

    /// Cut `vol` into bricks, keeping every voxel whose value lies above the minimum.
    pub fn build(vol: &ScalarVolume) -> Result<Self> {
        Self::build_over(vol, f32::INFINITY)
    }

    /// `build`, with the empty value at most `background` (`from_slices_over`).
    pub(super) fn build_over(vol: &ScalarVolume, background: f32) -> Result<Self> {
        let plane = vol.dims[0] as usize * vol.dims[1] as usize;
        // The volume is in memory: nothing to keep between the passes.
        Self::from_slices_over(vol.dims, vol.spacing, [[0; 3], vol.dims], background, false, None, |z0, count, out| {
            out.clear();
            out.extend_from_slice(&vol.values[z0 as usize * plane..(z0 + count) as usize * plane]);
            Ok(())
        })
    }

    /// Build the store from z-slices without holding the volume: `read(z0, count, out)` puts
    /// slices `z0..z0 + count` (x fastest) in `out`. Two passes: the value range, then the bricks,
    /// `BRICK` slices at a time; the second reads what the first kept when the samples fit
    /// `SLAB_CACHE_BYTES` (and a quarter of the host budget), else it reads them again. Refused
    /// before any large allocation when the store could exceed the host's available memory.
    pub fn from_slices(
        dims: [u32; 3],
        spacing: [f32; 3],
        read: impl FnMut(u32, u32, &mut Vec<f32>) -> Result<()>,
    ) -> Result<Self> {
        Self::from_slices_over(dims, spacing, [[0; 3], dims], f32::INFINITY, true, None, read)
    }

    /// `from_slices` over the voxels in `region` only (`lo..hi`): `read` puts the region's part
    /// of slices `z0..z0 + count` (x fastest over the region's width) in `out`, as `from_region`
    /// takes it, and the values are normalised by the region's own range. Every other voxel is
    /// empty. A cropped OME-Zarr image is read this way, its chunks outside the region untouched.
    pub fn from_region_slices(
        dims: [u32; 3],
        spacing: [f32; 3],
        region: [[u32; 3]; 2],
        read: impl FnMut(u32, u32, &mut Vec<f32>) -> Result<()>,
    ) -> Result<Self> {
        Self::from_slices_over(dims, spacing, region, f32::INFINITY, true, None, read)
    }

    /// `from_region_slices`, with the empty value at most `background` (a volume with no empty
    /// voxel keeps its minimum); `may_keep`: whether the samples may be kept between the passes;
    /// `progress(read, of)` after each read: slices read so far and slices it reads in all (the
    /// region's twice when the second pass reads them again).
    pub(super) fn from_slices_over(
        dims: [u32; 3],
        spacing: [f32; 3],
        region: [[u32; 3]; 2],
        background: f32,
        may_keep: bool,
        progress: Option<&dyn Fn(u64, u64)>,
        mut read: impl FnMut(u32, u32, &mut Vec<f32>) -> Result<()>,
    ) -> Result<Self> {
        check_dims(dims)?;
        let [r0, r1] = region;
        if (0..3).any(|a| r0[a] >= r1[a] || r1[a] > dims[a]) {
            return Err(Error::InvalidArgument(format!(
                "the region {r0:?}..{r1:?} is empty or leaves the {dims:?} grid"
            )));
        }
        let mut slab = Vec::new();
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        // The samples, kept for the brick pass when they fit, so that a slow reader (a DICOM
        // decoder, compressed chunks) reads each once.
        let plane = (r1[0] - r0[0]) as usize * (r1[1] - r0[1]) as usize;
        let bytes = plane as u64 * (r1[2] - r0[2]) as u64 * 4;
        let keep = may_keep
            && bytes <= SLAB_CACHE_BYTES
            && crate::error::host_budget().is_none_or(|b| bytes <= b / 4)
            && crate::error::check_host_memory(2 * bytes, "").is_ok();
        let mut kept = Vec::new();
        let slices = (r1[2] - r0[2]) as u64;
        let of = if keep { slices } else { 2 * slices };
        let report = |read: u64| {
            if let Some(p) = progress {
                p(read, of)
            }
        };
        // The slabs `from_region` reads: a brick's slices within the region.
        let mut z0 = r0[2];
        while z0 < r1[2] {
            let z1 = ((z0 / BRICK + 1) * BRICK).min(r1[2]);
            read(z0, z1 - z0, &mut slab)?;
            report((z1 - r0[2]) as u64);
            let (l, h) = crate::volume::value_span(&slab);
            (lo, hi) = (lo.min(l), hi.max(h));
            if keep {
                kept.extend_from_slice(&slab);
            }
            z0 = z1;
        }
        let range = store_range(lo.min(background), hi);
        if !keep {
            return Self::from_region(dims, spacing, range, region, |z0, count, out| {
                read(z0, count, out)?;
                report(slices + (z0 + count - r0[2]) as u64);
                Ok(())
            });
        }
        Self::from_region(dims, spacing, range, region, |z0, count, out| {
            let at = (z0 - r0[2]) as usize * plane..(z0 - r0[2] + count) as usize * plane;
            let part = kept.get(at).ok_or_else(|| Error::InvalidArgument("a slab read past the volume".into()))?;
            out.clear();
            out.extend_from_slice(part);
            Ok(())
        })
    }

    /// An OME-Zarr image's store of what `hints.crop` needs (`SliceReader::part`), normalised by
    /// the part's own range.
    #[cfg(feature = "io")]
    pub(super) fn load_cropped(
        mut reader: crate::loaders::SliceReader,
        region: [[u32; 3]; 2],
        progress: Option<&dyn Fn(u64, u64)>,
    ) -> Result<Self> {
        let (dims, spacing) = (reader.dims, reader.spacing);
        Self::from_slices_over(dims, spacing, region, f32::INFINITY, true, progress, |z0, count, out| {
            reader.read_region(z0, count, region, out)
        })
    }

    /// The store of the voxels in `region` (`lo..hi`, voxel coordinates) of a `dims` grid whose
    /// values `range` normalises (the whole volume's: `from_slices` finds it), every other voxel
    /// empty: `read(z0, count, out)` puts the region's part of slices `z0..z0 + count` (x fastest
    /// over the region's width) in `out`. One pass, `BRICK` slices at a time. Sort-last rendering
    /// builds each rank's box (and the layer of voxels around it) this way.
    pub fn from_region(
        dims: [u32; 3],
        spacing: [f32; 3],
        range: (f32, f32),
        region: [[u32; 3]; 2],
        mut read: impl FnMut(u32, u32, &mut Vec<f32>) -> Result<()>,
    ) -> Result<Self> {
        check_dims(dims)?;
        let [r0, r1] = region;
        if (0..3).any(|a| r0[a] > r1[a] || r1[a] > dims[a]) {
            return Err(Error::InvalidArgument(format!("the region {r0:?}..{r1:?} lies outside the {dims:?} grid")));
        }
        let nb = dims.map(|d| d.div_ceil(BRICK));
        let bricks = nb[0] as u64 * nb[1] as u64 * nb[2] as u64;
        let size = [0, 1, 2].map(|a| (r1[a] - r0[a]) as u64);
        let voxels = size[0] * size[1] * size[2];
        // The index and the headers and masks of every brick are known now; records grow with what
        // the volume holds (a uniform brick stores none) and are checked slab by slab as they do.
        let what = format!("a {dims:?} bricked store");
        let fixed = bricks * 4 + voxels.div_ceil(BRICK_VOXELS as u64).min(bricks) * (16 + BRICK_VOXELS as u64 / 8);
        crate::error::check_host_memory(fixed, &what)?;
        let (lo, hi) = range;
        // A constant volume has no background: its voxels are kept (`keeps`: the minimum would drop
        // them all, and a one-voxel opaque volume drew nothing) at quantised 0, which the TF
        // classifies as the dense path does (density 0 without a TF range, the value's own with one).
        // In f64: the span of an f32 range may pass f32's largest value.
        let span = if hi > lo { hi as f64 - lo as f64 } else { 1.0 };
        let mut store = Self {
            dims,
            spacing,
            shear: [0.0; 3],
            range: (lo, hi),
            headers: Vec::new(),
            masks: Vec::new(),
            records: Vec::new(),
            index: vec![u32::MAX; bricks as usize],
        };
        if voxels == 0 {
            return Ok(store);
        }
        let mut slab = Vec::new();
        let (w, plane) = (size[0] as usize, (size[0] * size[1]) as usize);
        let blo = r0.map(|c| c / BRICK);
        let bhi = r1.map(|c| c.div_ceil(BRICK));
        for bz in blo[2]..bhi[2] {
            let z0 = (bz * BRICK).max(r0[2]);
            // Past the budget, or past what the host has left, before this slab's records could be.
            let slab_voxels = size[0] * size[1] * ((bz + 1) * BRICK).min(r1[2]).saturating_sub(z0) as u64;
            let records = store.records.len() as u64 * 4;
            if let Some(b) = crate::error::host_budget().filter(|&b| fixed + records + slab_voxels * 4 > b) {
                return Err(Error::TooLarge(format!(
                    "{what} needs more than {} MiB of host memory for its records and the next slab, past the host \
                     budget of {} MiB",
                    (fixed + records + slab_voxels * 4).div_ceil(1 << 20),
                    b >> 20
                )));
            }
            crate::error::check_host_memory(slab_voxels * 4 + (slab_voxels * 4).min(records), &what)?;
            read(z0, ((bz + 1) * BRICK).min(r1[2]) - z0, &mut slab)?;
            let z1 = ((bz + 1) * BRICK).min(r1[2]);
            for by in blo[1]..bhi[1] {
                for bx in blo[0]..bhi[0] {
                    // A brick with nothing to keep, found row by row (most of a sparse volume).
                    let [x0, x1] = [bx * BRICK, (bx + 1) * BRICK].map(|x| x.clamp(r0[0], r1[0]) - r0[0]);
                    let [y0, y1] = [by * BRICK, (by + 1) * BRICK].map(|y| y.clamp(r0[1], r1[1]) - r0[1]);
                    let row = |z: u32, y: u32| (z - z0) as usize * plane + y as usize * w;
                    let rows = (z0..z1).flat_map(|z| (y0..y1).map(move |y| (z, y)));
                    if !rows.into_iter().any(|(z, y)| {
                        // Without a short cut per value, so the row's test vectorises.
                        slab[row(z, y) + x0 as usize..row(z, y) + x1 as usize]
                            .iter()
                            .fold(false, |k, &v| k | keeps(v, range))
                    }) {
                        continue;
                    }
                    let first = store.records.len() as u32;
                    let mut mask = [0u64; BRICK_VOXELS / 64];
                    let (mut qmin, mut qmax) = (u32::MAX, 0u32);
                    for l in 0..BRICK_VOXELS as u32 {
                        let c = local_cell(l);
                        let v = [bx * BRICK + c[0], by * BRICK + c[1], bz * BRICK + c[2]];
                        if (0..3).any(|a| v[a] < r0[a] || v[a] >= r1[a]) {
                            continue;
                        }
                        let at = (v[2] - z0) as usize * plane + (v[1] - r0[1]) as usize * w + (v[0] - r0[0]) as usize;
                        let v = slab[at];
                        if !keeps(v, range) {
                            continue;
                        }
                        let q = ((v as f64 - lo as f64) / span * Q as f64).round().clamp(0.0, Q as f64) as u32;
                        mask[l as usize / 64] |= 1 << (l % 64);
                        store.records.push(l | q << 16);
                        (qmin, qmax) = (qmin.min(q), qmax.max(q));
                    }
                    let count = store.records.len() as u32 - first;
                    // Every voxel of a full brick at one value: its records go, its header says it.
                    let first = if count as usize == BRICK_VOXELS && qmin == qmax {
                        store.records.truncate(first as usize);
                        UNIFORM_RECORDS | qmin << 9
                    } else {
                        first
                    };
                    if count > 0 {
                        store.index[(bx + nb[0] * (by + nb[1] * bz)) as usize] = store.headers.len() as u32;
                        store.headers.push(BrickHeader {
                            brick: bx | by << 10 | bz << 20,
                            first,
                            count,
                            range: qmin | qmax << 16,
                        });
                        store.masks.push(mask);
                    }
                }
            }
        }
        Ok(store)
    }
}

/// Most bytes of samples `from_slices` keeps from its range pass for its brick pass.
pub const SLAB_CACHE_BYTES: u64 = 1 << 30;

/// The range a store normalises by, from the smallest and largest finite values read (none read:
/// (0, 0)).
pub fn store_range(lo: f32, hi: f32) -> (f32, f32) {
    if lo.is_finite() {
        (lo, hi.max(lo))
    } else {
        (0.0, 0.0)
    }
}

/// Whether a store normalised by `range` keeps value `v`: finite and above the minimum, or any
/// finite value of a constant volume.
pub fn keeps(v: f32, (lo, hi): (f32, f32)) -> bool {
    v.is_finite() && (v > lo || hi <= lo)
}

/// Refuse a grid a bricked store cannot hold.
fn check_dims(dims: [u32; 3]) -> Result<()> {
    if dims.iter().any(|&d| d == 0 || d > BRICK << 10) {
        return Err(Error::InvalidArgument(format!(
            "a bricked volume is 1 to {} voxels a side, not {dims:?}",
            BRICK << 10
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A load tells its progress after each slab: rising to all of it, the file counted twice when
    /// the second pass reads it again, and the same store either way.
    #[test]
    fn progress_rises_to_the_slices_read_in_all() {
        let dims = [9, 7, 21];
        let value = |i: usize| ((i * 37) % 11) as f32;
        let plane = (dims[0] * dims[1]) as usize;
        let mut stores = Vec::new();
        for keep in [true, false] {
            let seen = std::cell::RefCell::new(Vec::new());
            let report = |read: u64, of: u64| seen.borrow_mut().push((read, of));
            let store = BrickStore::from_slices_over(
                dims,
                [1.0; 3],
                [[0; 3], dims],
                f32::INFINITY,
                keep,
                Some(&report),
                |z0, n, out| {
                    *out = (z0 as usize * plane..(z0 + n) as usize * plane).map(value).collect();
                    Ok(())
                },
            )
            .unwrap();
            let seen = seen.into_inner();
            let of = if keep { 21 } else { 42 };
            assert!(seen.iter().all(|&(_, o)| o == of), "keep {keep}: {seen:?}");
            assert!(seen.windows(2).all(|w| w[0].0 < w[1].0), "keep {keep}: rising {seen:?}");
            assert_eq!(seen.last(), Some(&(of, of)), "keep {keep}");
            // Slabs of a brick's slices: 8, 16, 21 for each pass.
            assert_eq!(seen.len(), if keep { 3 } else { 6 }, "keep {keep}: {seen:?}");
            stores.push(store);
        }
        assert_eq!(stores[0].records, stores[1].records);
        assert_eq!(stores[0].headers, stores[1].headers);
    }
}
