//! Mirror of `glsl/tile_count.comp` (the `tile_count` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::FootprintInputs;
use super::tile::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, ScreenQuad};

/// The count matrix arrives zeroed (the GPU fills it first); `quads` are `screen_quads`'.
pub fn tile_count(inputs: &FootprintInputs<'_>, push: &FootprintPush, quads: &[ScreenQuad], counts: &mut [u32]) {
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for e in chunk_entries(push, chunk) {
            let splat = inputs.draw_list[e] as usize;
            each_tile(inputs.frame, quads[splat].bx, |t| counts[t * chunks + chunk as usize] += 1);
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut counts = b.take(Res::TileCounts);
    tile_count(&b.inputs(d.list), &d.push_as(), b.get(Res::Quads), &mut counts);
    b.put(Res::TileCounts, counts);
    Ok(())
}
