//! Mirror of `glsl/tile_scatter.comp` (the `tile_scatter` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::FootprintInputs;
use super::tile::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{FootprintPush, ScreenQuad};

/// Each tile's entries written in draw order (the stage's loops, whole).
pub fn tile_scatter(
    inputs: &FootprintInputs<'_>,
    push: &FootprintPush,
    quads: &[ScreenQuad],
    tile_start: &[u32],
    counts: &mut [u32],
    entries: &mut [u32],
) {
    let chunks = push.chunks as usize;
    for chunk in 0..push.chunks {
        for e in chunk_entries(push, chunk) {
            let splat = inputs.draw_list[e];
            each_tile(inputs.frame, quads[splat as usize].bx, |t| {
                let cell = t * chunks + chunk as usize;
                entries[(tile_start[t] + counts[cell]) as usize] = splat;
                counts[cell] += 1;
            });
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut entries) = (b.take(Res::TileCounts), b.take(Res::TileEntries));
    let (inputs, push) = (b.inputs(d.list), d.push_as());
    tile_scatter(&inputs, &push, b.get(Res::Quads), b.get(Res::TileStart), &mut counts, &mut entries);
    b.put(Res::TileCounts, counts);
    b.put(Res::TileEntries, entries);
    Ok(())
}
