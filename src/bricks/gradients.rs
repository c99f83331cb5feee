//! Each stored voxel's central differences, computed once per store: a shaded or gradient-weighted
//! frame's `brick_params` reads one word per splat instead of six neighbours through the store
//! (each a brick lookup, a mask word, its count and a record: 55 % of that stage on the shaded
//! bonsai, docs/RESULTS.md). The differences are of quantised values (exact: 8 bytes a voxel, the
//! neighbours' lookups gave what the store holds), so only the density remap scales them.
use super::{BrickHeader, BrickStore, BRICK};
use rayon::prelude::*;

/// Packs the central differences `d` of quantised values (each within ±65535), exactly: each plus
/// 65536 in 17 bits, x in bits 0-16 of the first word, y in its bits 17-31 and the second's 0-1,
/// z in the second's 2-18.
pub fn pack_differences(d: [i32; 3]) -> [u32; 2] {
    let [x, y, z] = d.map(|v| (v.clamp(-65535, 65535) + 65536) as u32);
    [x | (y & 0x7fff) << 17, y >> 15 | z << 2]
}

/// The differences `pack_differences` packed, times `scale` (mirror of `stored_differences`'
/// arithmetic in glsl/shared/brick.glsl).
pub fn unpack_differences(w: [u32; 2], scale: f32) -> [f32; 3] {
    let d = [w[0] & 0x1ffff, w[0] >> 17 | (w[1] & 3) << 15, w[1] >> 2];
    d.map(|v| (v as i32 - 65536) as f32 * scale)
}

impl BrickStore {
    /// `Res::BrickGradients` and `BrickGradientsHi`: each per header the index of its first word,
    /// then per brick, in the order of its records (local index order; all 512 voxels of a uniform
    /// brick), the first (second) word of each voxel's packed central differences of the quantised
    /// values around it (`pack_differences`; indices clamped to the grid, 0 where nothing is
    /// stored, as `value_at` reads them). Bricks that `draws` leaves out (the transfer function
    /// draws none of their values) keep zeros.
    pub fn gradient_words(&self, draws: impl Fn(&BrickHeader) -> bool + Sync) -> [Vec<u32>; 2] {
        let n = self.gradient_len() as usize;
        let (mut lo, mut hi) = (vec![0u32; n], vec![0u32; n]);
        let mut at = self.headers.len() as u32;
        for (hd, f) in self.headers.iter().zip(lo.iter_mut().zip(hi.iter_mut())) {
            (*f.0, *f.1) = (at, at);
            at += hd.count;
        }
        // Each brick's slices of the output, so the bricks fill theirs in parallel.
        let (mut rest_lo, mut rest_hi) = (&mut lo[self.headers.len()..], &mut hi[self.headers.len()..]);
        let mut slices = Vec::with_capacity(self.headers.len());
        for hd in &self.headers {
            let (a, tail_lo) = std::mem::take(&mut rest_lo).split_at_mut(hd.count as usize);
            let (b, tail_hi) = std::mem::take(&mut rest_hi).split_at_mut(hd.count as usize);
            (rest_lo, rest_hi) = (tail_lo, tail_hi);
            slices.push((hd, a, b));
        }
        slices.into_par_iter().filter(|(hd, ..)| draws(hd)).for_each(|(hd, a, b)| self.brick_differences(hd, a, b));
        [lo, hi]
    }

    /// The length of each of `gradient_words`' two, without making them.
    pub fn gradient_len(&self) -> u64 {
        self.headers.len() as u64 + self.headers.iter().map(|h| h.count as u64).sum::<u64>()
    }

    /// Brick `hd`'s voxels' packed differences, into `lo` and `hi`: its values and the layers of
    /// its face neighbours next to it in a dense block one voxel wider on each side, the grid's
    /// edges clamped as `value_at` clamps them.
    fn brick_differences(&self, hd: &BrickHeader, lo: &mut [u32], hi: &mut [u32]) {
        const A: usize = BRICK as usize + 2;
        // Local (x, y, z), each in -1..=BRICK, in the block.
        let at = |l: [i64; 3]| ((l[0] + 1) + A as i64 * ((l[1] + 1) + A as i64 * (l[2] + 1))) as usize;
        let mut block = [0i32; A * A * A];
        let records = self.brick_records(hd);
        for r in records.iter() {
            block[at(super::local_cell(r & 511).map(|c| c as i64))] = (r >> 16) as i32;
        }
        let b = hd.coords();
        let nb = self.dims.map(|d| d.div_ceil(BRICK));
        for a in 0..3 {
            for side in 0..2 {
                let mut n = b;
                if side == 0 && n[a] == 0 || side == 1 && n[a] + 1 >= nb[a] {
                    continue;
                }
                n[a] = if side == 0 { n[a] - 1 } else { n[a] + 1 };
                let h = self.header_of(n.map(|c| c * BRICK));
                if h == u32::MAX {
                    continue;
                }
                let layer = if side == 0 { BRICK - 1 } else { 0 };
                for r in self.brick_records(&self.headers[h as usize]).iter() {
                    let c = super::local_cell(r & 511);
                    if c[a] == layer {
                        let mut l = c.map(|c| c as i64);
                        l[a] = if side == 0 { -1 } else { BRICK as i64 };
                        block[at(l)] = (r >> 16) as i32;
                    }
                }
            }
        }
        // The grid's edges: the layer past the first (last) voxel along an axis holds its values.
        for a in 0..3 {
            let base = (b[a] * BRICK) as i64;
            let valid = (self.dims[a] as i64 - base).min(BRICK as i64);
            let mut copy = |from: i64, to: i64| {
                let (u, w) = other_axes(a);
                for j in 0..BRICK as i64 {
                    for i in 0..BRICK as i64 {
                        let (mut f, mut t) = ([0; 3], [0; 3]);
                        (f[a], f[u], f[w]) = (from, i, j);
                        (t[a], t[u], t[w]) = (to, i, j);
                        block[at(t)] = block[at(f)];
                    }
                }
            };
            if base == 0 {
                copy(0, -1);
            }
            if base + valid == self.dims[a] as i64 {
                copy(valid - 1, valid);
            }
        }
        let steps = [1, A, A * A];
        for ((a_out, b_out), r) in lo.iter_mut().zip(hi.iter_mut()).zip(records.iter()) {
            let i = at(super::local_cell(r & 511).map(|c| c as i64));
            [*a_out, *b_out] = pack_differences(steps.map(|s| block[i + s] - block[i - s]));
        }
    }
}

/// The two axes other than `a`, in order.
fn other_axes(a: usize) -> (usize, usize) {
    match a {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_differences_come_back_exactly() {
        for d in [[0, 0, 0], [1, -1, 0], [65535, -65535, 17], [-3, 200, -128], [-65535, 65535, -65535]] {
            assert_eq!(unpack_differences(pack_differences(d), 1.0), d.map(|v| v as f32), "{d:?}");
        }
        let mut seed = 12345u32;
        for _ in 0..10_000 {
            let mut r = || {
                seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (seed >> 8) as i32 % 131_071 - 65_535
            };
            let d = [r(), r(), r()];
            assert_eq!(unpack_differences(pack_differences(d), 1.0), d.map(|v| v as f32), "{d:?}");
        }
    }
}
