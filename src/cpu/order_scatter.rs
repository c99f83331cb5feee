//! Mirror of `glsl/order_scatter.comp` (the `order_scatter` stage); shared helpers in `order.rs`.
use super::bindings::Bindings;
use super::order::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{Frame, Splat};

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

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, _: &Variant) -> Result<()> {
    let mut out = b.take(Res::Order);
    let set = &b.prep.set;
    order_scatter(&b.frame, set.splats(), set.row_start(), b.get(Res::RowSplit), b.get(Res::Segments), &mut out);
    b.put(Res::Order, out);
    Ok(())
}
