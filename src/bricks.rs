//! The bricked, compact store of a scalar volume (issue 23, first piece; host side only so far):
//! the grid cut into bricks of `BRICK`³ voxels, each non-empty brick a 16-byte header and a 64-byte
//! occupancy mask, each candidate voxel (value above the volume's minimum) a 4-byte record of its
//! position in the brick and its value quantised to 16 bits. Empty voxels are not stored: their
//! value is the minimum, which normalises to 0, so every value (and so every gradient) of the
//! volume is recovered from the store (`value_at`), up to the quantisation.
//!
//! B = 8 by measurement on the real volumes: 16-byte headers cost 0.05-0.19 bytes per stored voxel
//! at B = 8 (0.33-0.75 at B = 4), while at B = 16 nearly every brick of the stent holds a voxel and
//! nothing is left to cull. With the 64-byte masks (for the neighbour lookups of gradients) the
//! store takes 4.26 bytes per stored voxel on bonsai and 4.54 on the stent (tests/bricks.rs).
//! Not yet on the device: the GPU path still draws `SplatSet`s.
use crate::classify::{classify_field, Shading, TransferFunction};
use crate::error::{Error, Result};
use crate::volume::{Grid, ScalarVolume, SplatSet};
use bytemuck::{Pod, Zeroable};

/// Voxels along each side of a brick.
pub const BRICK: u32 = 8;
const BRICK_VOXELS: usize = (BRICK * BRICK * BRICK) as usize;
/// Largest value of a quantised scalar.
const Q: f32 = 65535.0;

/// A non-empty brick. Keep in step with the GPU side when it arrives (16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct BrickHeader {
    /// Brick coordinates, 10 bits each: x | y << 10 | z << 20.
    pub brick: u32,
    /// Its first record.
    pub first: u32,
    /// Its records (at most `BRICK`³).
    pub count: u32,
    /// Its smallest and largest quantised value: min | max << 16.
    pub range: u32,
}

const _: () = assert!(std::mem::size_of::<BrickHeader>() == 16);

/// A scalar volume as bricks of compact records.
#[derive(Clone, Debug)]
pub struct BrickStore {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel spacing.
    pub spacing: [f32; 3],
    /// The raw values normalisation maps to [0, 1] (the volume's finite min and max).
    pub range: (f32, f32),
    /// Non-empty bricks, in brick order (x fastest).
    pub headers: Vec<BrickHeader>,
    /// Per non-empty brick, which of its voxels are stored (bit x + 8y + 64z).
    pub masks: Vec<[u64; BRICK_VOXELS / 64]>,
    /// Records: local index (x + 8y + 64z, 9 bits) | quantised value << 16, brick by brick, in
    /// local index order.
    pub records: Vec<u32>,
    /// Brick id (x + nbx (y + nby z)) -> index into `headers`, or `u32::MAX` when empty.
    index: Vec<u32>,
}

impl BrickStore {
    /// Cut `vol` into bricks, keeping every voxel whose value lies above the minimum.
    pub fn build(vol: &ScalarVolume) -> Result<Self> {
        let [nx, ny, nz] = vol.dims;
        if vol.dims.iter().any(|&d| d == 0 || d > BRICK << 10) {
            return Err(Error::InvalidArgument(format!(
                "a bricked volume is 1 to {} voxels a side, not {:?}",
                BRICK << 10,
                vol.dims
            )));
        }
        let (lo, hi) = vol
            .values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) };
        let span = if hi > lo { hi - lo } else { 1.0 };
        let nb = vol.dims.map(|d| d.div_ceil(BRICK));
        let mut store = Self {
            dims: vol.dims,
            spacing: vol.spacing,
            range: (lo, hi),
            headers: Vec::new(),
            masks: Vec::new(),
            records: Vec::new(),
            index: vec![u32::MAX; nb[0] as usize * nb[1] as usize * nb[2] as usize],
        };
        for bz in 0..nb[2] {
            for by in 0..nb[1] {
                for bx in 0..nb[0] {
                    let first = store.records.len() as u32;
                    let mut mask = [0u64; BRICK_VOXELS / 64];
                    let (mut qmin, mut qmax) = (u32::MAX, 0u32);
                    for l in 0..BRICK_VOXELS as u32 {
                        let (x, y, z) = (bx * BRICK + l % BRICK, by * BRICK + l / BRICK % BRICK, bz * BRICK + l / 64);
                        if x >= nx || y >= ny || z >= nz {
                            continue;
                        }
                        let v = vol.values[(x + nx * (y + ny * z)) as usize];
                        if !(v.is_finite() && v > lo) {
                            continue;
                        }
                        let q = ((v - lo) / span * Q).round().clamp(0.0, Q) as u32;
                        mask[l as usize / 64] |= 1 << (l % 64);
                        store.records.push(l | q << 16);
                        (qmin, qmax) = (qmin.min(q), qmax.max(q));
                    }
                    let count = store.records.len() as u32 - first;
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

    /// Stored voxels.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether no voxel is stored.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Bytes the store takes on a device: headers, masks and records.
    pub fn bytes(&self) -> u64 {
        (self.headers.len() * (std::mem::size_of::<BrickHeader>() + BRICK_VOXELS / 8) + self.records.len() * 4) as u64
    }

    /// The normalised value in [0, 1] at voxel (i, j, k), indices clamped to the grid (as the
    /// CPU classification reads it): 0 where nothing is stored.
    pub fn value_at(&self, i: i64, j: i64, k: i64) -> f32 {
        let [x, y, z] = [i, j, k].map(|c| c.max(0) as u32);
        let [x, y, z] = [x.min(self.dims[0] - 1), y.min(self.dims[1] - 1), z.min(self.dims[2] - 1)];
        let nb = self.dims.map(|d| d.div_ceil(BRICK));
        let id = (x / BRICK + nb[0] * (y / BRICK + nb[1] * (z / BRICK))) as usize;
        let h = self.index[id];
        if h == u32::MAX {
            return 0.0;
        }
        let mask = &self.masks[h as usize];
        let l = (x % BRICK + BRICK * (y % BRICK) + BRICK * BRICK * (z % BRICK)) as usize;
        if mask[l / 64] >> (l % 64) & 1 == 0 {
            return 0.0;
        }
        // The record's rank among the brick's: stored voxels below it in local index order.
        let below = mask[..l / 64].iter().map(|w| w.count_ones()).sum::<u32>()
            + (mask[l / 64] & ((1u64 << (l % 64)) - 1)).count_ones();
        let rec = self.records[(self.headers[h as usize].first + below) as usize];
        (rec >> 16) as f32 / Q
    }

    /// Classify the stored volume (as `classify::classify` does a dense one), reading every value
    /// and gradient through the store.
    pub fn classify(&self, tf: &TransferFunction, shading: Option<Shading>) -> Result<SplatSet> {
        let (lo, hi) = self.range;
        let span = if hi > lo { hi - lo } else { 1.0 };
        // The transfer function's own range, if it sets one, re-maps the stored normalisation.
        let (tlo, thi) = tf.range.unwrap_or((lo, hi));
        let tspan = if thi > tlo { thi - tlo } else { 1.0 };
        let remap = |d: f32| if tf.range.is_some() { (lo + d * span - tlo) / tspan } else { d };
        let grid = Grid::centered(self.dims, self.spacing)?;
        classify_field(grid, self.spacing, tf, shading, |i, j, k| remap(self.value_at(i, j, k)))
    }
}
