//! Helpers the order stages' mirrors share (`order_count.rs`, `order_scan.rs`, `order_scatter.rs`):
//! `glsl/shared/pbtf.glsl`'s segment arithmetic.
use crate::gpu_types::Frame;

/// Cells of an `n`-cell axis on `side` of `split` (glsl/shared/pbtf.glsl).
pub(crate) fn side_count(n: u32, split: u32, side: u32) -> u32 {
    if side == 0 {
        split
    } else {
        n - split
    }
}

/// Rank of `idx` on its `side` of `split`, outward from the eye (glsl/shared/pbtf.glsl).
pub(crate) fn outward(idx: u32, split: u32, side: u32) -> u32 {
    if side == 0 {
        split - 1 - idx
    } else {
        idx - split
    }
}

/// Mirror of `segment_position` in `glsl/shared/pbtf.glsl`.
pub fn segment_position(j: u32, k: u32, si: u32, dims: [u32; 3], split: [u32; 3]) -> u32 {
    let sj = if j < split[1] { 0 } else { 1 };
    let sk = if k < split[2] { 0 } else { 1 };
    let octant = si + 2 * sj + 4 * sk;
    let mut base = 0;
    for o in 0..octant {
        base += side_count(dims[1], split[1], (o >> 1) & 1) * side_count(dims[2], split[2], (o >> 2) & 1);
    }
    let nj = side_count(dims[1], split[1], sj);
    base + outward(k, split[2], sk) * nj + outward(j, split[1], sj)
}

pub(crate) fn dims_split(frame: &Frame) -> ([u32; 3], [u32; 3]) {
    ([frame.dims[0], frame.dims[1], frame.dims[2]], [frame.split[0], frame.split[1], frame.split[2]])
}
