//! Mirror of `glsl/tile_count.comp` (the `tile_count` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::FootprintInputs;
use super::tile::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, ScreenQuad};

/// The count matrix arrives zeroed (the GPU fills it first).
pub fn tile_count(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32], quads: &mut [ScreenQuad]) {
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for e in chunk_entries(push, chunk) {
            let splat = inputs.draw_list[e] as usize;
            let q = screen_record(inputs.frame, &inputs.params[splat]);
            quads[splat] = q;
            each_tile(inputs.frame, q.bx, |t| counts[t * chunks + chunk as usize] += 1);
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut quads) = (b.take(Res::TileCounts), b.take(Res::Quads));
    tile_count(&b.inputs(d.list), &d.push_as(), &mut counts, bytemuck::cast_slice_mut(&mut quads));
    b.put(Res::TileCounts, counts);
    b.put(Res::Quads, quads);
    Ok(())
}
