//! Mirror of `glsl/tile_scan.comp` (the `tile_scan` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::FootprintInputs;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::FootprintPush;
use crate::plan::tile_grid;

/// Each tile's row of the count matrix becomes offsets within the tile; `tile_start[t]` its total.
pub fn tile_scan(inputs: &FootprintInputs<'_>, push: &FootprintPush, counts: &mut [u32], tile_start: &mut [u32]) {
    let (tx, ty) = tile_grid(inputs.frame);
    let chunks = push.chunks as usize;
    for t in 0..(tx * ty) as usize {
        let mut carry = 0u32;
        for c in &mut counts[t * chunks..(t + 1) * chunks] {
            let v = *c;
            *c = carry;
            carry += v;
        }
        tile_start[t] = carry;
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut start) = (b.take(Res::TileCounts), b.take(Res::TileStart));
    tile_scan(&b.inputs(d.list), &d.push_as(), &mut counts, &mut start);
    b.put(Res::TileCounts, counts);
    b.put(Res::TileStart, start);
    Ok(())
}
