//! Each stored voxel's central differences, computed once per store: a shaded or gradient-weighted
//! frame's `brick_params` reads one word per splat instead of six neighbours through the store
//! (each a brick lookup, a mask word, its count and a record: 55 % of that stage on the shaded
//! bonsai, docs/RESULTS.md). The differences are of quantised values (exact: 8 bytes a voxel, the
//! neighbours' lookups gave what the store holds), so only the density remap scales them.
use super::{BrickHeader, BrickStore, BRICK, BRICK_VOXELS};
use rayon::prelude::*;

/// Words a voxel's differences take.
pub const DIFFERENCE_WORDS: u32 = 2;

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
    /// `Res::BrickGradients`: per header the index of its first word, then per brick, in the
    /// order of its records (local index order; all 512 voxels of a uniform brick), each voxel's
    /// two words of packed central differences of the quantised values around it (`pack_differences`; indices
    /// clamped to the grid, 0 where nothing is stored, as `value_at` reads them). Bricks that
    /// `draws` leaves out (the transfer function draws none of their values) keep zeros.
    pub fn gradient_words(&self, draws: impl Fn(&BrickHeader) -> bool + Sync) -> Vec<u32> {
        let mut words = vec![0u32; self.gradient_len() as usize];
        let (first, mut rest) = words.split_at_mut(self.headers.len());
        // Each brick's slice of the output, so the bricks fill theirs in parallel.
        let mut slices = Vec::with_capacity(self.headers.len());
        let mut at = self.headers.len() as u32;
        for (hd, f) in self.headers.iter().zip(first.iter_mut()) {
            *f = at;
            at += DIFFERENCE_WORDS * hd.count;
            let (mine, tail) = std::mem::take(&mut rest).split_at_mut((DIFFERENCE_WORDS * hd.count) as usize);
            rest = tail;
            slices.push((hd, mine));
        }
        slices.into_par_iter().filter(|(hd, _)| draws(hd)).for_each(|(hd, out)| self.brick_differences(hd, out));
        words
    }

    /// The length of `gradient_words`, without making it.
    pub fn gradient_len(&self) -> u64 {
        self.headers.len() as u64 + DIFFERENCE_WORDS as u64 * self.headers.iter().map(|h| h.count as u64).sum::<u64>()
    }

    /// Brick `hd`'s voxels' packed differences, into `out`: its own values from a dense copy,
    /// its face neighbours' from copies of the layer next to it.
    fn brick_differences(&self, hd: &BrickHeader, out: &mut [u32]) {
        const B: i64 = BRICK as i64;
        let mut dense = [0i32; BRICK_VOXELS];
        let records = self.brick_records(hd);
        for r in records.iter() {
            dense[(r & 511) as usize] = (r >> 16) as i32;
        }
        let b = hd.coords();
        let nb = self.dims.map(|d| d.div_ceil(BRICK));
        // Face 2a + side: the neighbour's layer along axis a below (side 0) or above (1), by the
        // other two local coordinates (x before y before z).
        let mut faces = [[0i32; (BRICK * BRICK) as usize]; 6];
        for a in 0..3 {
            for side in 0..2 {
                let mut n = b;
                if side == 0 && n[a] == 0 || side == 1 && n[a] + 1 >= nb[a] {
                    continue;
                }
                n[a] = if side == 0 { n[a] - 1 } else { n[a] + 1 };
                let h = self.index[(n[0] + nb[0] * (n[1] + nb[1] * n[2])) as usize];
                if h == u32::MAX {
                    continue;
                }
                let layer = if side == 0 { BRICK - 1 } else { 0 };
                for r in self.brick_records(&self.headers[h as usize]).iter() {
                    let c = super::local_cell(r & 511);
                    if c[a] == layer {
                        let (u, w) = other_axes(a);
                        faces[2 * a + side][(c[u] + BRICK * c[w]) as usize] = (r >> 16) as i32;
                    }
                }
            }
        }
        let base = b.map(|c| (c * BRICK) as i64);
        let last = self.dims.map(|d| d as i64 - 1);
        // The quantised value at voxel v, indices clamped to the grid: one step from the brick at
        // most, so outside it along one axis only.
        let q = |v: [i64; 3]| -> i32 {
            let l = [0, 1, 2].map(|a| v[a].clamp(0, last[a]) - base[a]);
            match (0..3).find(|&a| !(0..B).contains(&l[a])) {
                None => dense[(l[0] + B * (l[1] + B * l[2])) as usize],
                Some(a) => {
                    let (u, w) = other_axes(a);
                    faces[2 * a + usize::from(l[a] >= B)][(l[u] + B * l[w]) as usize]
                }
            }
        };
        for (o, r) in out.chunks_exact_mut(DIFFERENCE_WORDS as usize).zip(records.iter()) {
            let [x, y, z] = super::local_cell(r & 511).map(|c| c as i64);
            let v = [base[0] + x, base[1] + y, base[2] + z];
            o.copy_from_slice(&pack_differences([0, 1, 2].map(|a| {
                let (mut lo, mut hi) = (v, v);
                lo[a] -= 1;
                hi[a] += 1;
                q(hi) - q(lo)
            })));
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
