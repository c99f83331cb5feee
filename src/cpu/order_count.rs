//! Mirror of `glsl/order_count.comp` (the `order_count` stage); shared helpers in `order.rs`.
use super::bindings::Bindings;
use super::order::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{Frame, Splat};

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

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let (mut row_split, mut segments) = (b.take(Res::RowSplit), b.take(Res::Segments));
    let set = &b.prep.set;
    order_count(&b.frame, set.splats(), set.row_start(), &mut row_split, &mut segments);
    b.put(Res::RowSplit, row_split);
    b.put(Res::Segments, segments);
    Ok(())
}
