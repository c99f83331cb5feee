//! Mirrors of `order_count.comp`, `order_scan.comp` and `order_scatter.comp`.
use super::bindings::Bindings;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{Frame, Splat};

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

fn dims_split(frame: &Frame) -> ([u32; 3], [u32; 3]) {
    ([frame.dims[0], frame.dims[1], frame.dims[2]], [frame.split[0], frame.split[1], frame.split[2]])
}

/// Pass 1: per row, the count on each side of the i-split, stored at its segment position.
pub fn order_count(frame: &Frame, splats: &[Splat], row_start: &[u32], row_split: &mut [u32], segments: &mut [u32]) {
    let (dims, split) = dims_split(frame);
    for row in 0..(dims[1] * dims[2]) {
        let (start, end) = (row_start[row as usize], row_start[row as usize + 1]);
        let (mut lo, mut hi) = (start, end);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if splats[mid as usize].ijk[0] < split[0] {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let low = lo - start;
        row_split[row as usize] = low;
        let (j, k) = (row % dims[1], row / dims[1]);
        segments[segment_position(j, k, 0, dims, split) as usize] = low;
        segments[segment_position(j, k, 1, dims, split) as usize] = (end - start) - low;
    }
}

/// Pass 2: exclusive prefix sum in place.
pub fn order_scan(frame: &Frame, segments: &mut [u32]) {
    let count = (2 * frame.dims[1] * frame.dims[2]) as usize;
    let mut carry = 0u32;
    for v in segments[..count].iter_mut() {
        let x = *v;
        *v = carry;
        carry += x;
    }
}

/// Pass 3: every splat writes its index at segment offset + outward rank.
pub fn order_scatter(
    frame: &Frame,
    splats: &[Splat],
    row_start: &[u32],
    row_split: &[u32],
    segments: &[u32],
    order: &mut [u32],
) {
    let (dims, split) = dims_split(frame);
    let n = frame.dims[3];
    for s in 0..n {
        let ijk = splats[s as usize].ijk;
        let row = (ijk[1] + dims[1] * ijk[2]) as usize;
        let local = s - row_start[row];
        let low = row_split[row];
        let si = if local < low { 0 } else { 1 };
        let rank = if si == 0 { low - 1 - local } else { local - low };
        let mut pos = segments[segment_position(ijk[1], ijk[2], si, dims, split) as usize] + rank;
        if frame.split[3] != 0 {
            pos = n - 1 - pos;
        }
        order[pos as usize] = s;
    }
}

pub(crate) fn order_count_stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let (mut row_split, mut segments) = (b.take(Res::RowSplit), b.take(Res::Segments));
    let set = &b.prep.set;
    order_count(&b.frame, set.splats(), set.row_start(), &mut row_split, &mut segments);
    b.put(Res::RowSplit, row_split);
    b.put(Res::Segments, segments);
    Ok(())
}

pub(crate) fn order_scan_stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let mut segments = b.take(Res::Segments);
    order_scan(&b.frame, &mut segments);
    b.put(Res::Segments, segments);
    Ok(())
}

pub(crate) fn order_scatter_stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let mut out = b.take(Res::Order);
    let set = &b.prep.set;
    order_scatter(&b.frame, set.splats(), set.row_start(), b.get(Res::RowSplit), b.get(Res::Segments), &mut out);
    b.put(Res::Order, out);
    Ok(())
}
