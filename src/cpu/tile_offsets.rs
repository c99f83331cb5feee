//! Mirror of `glsl/tile_offsets.comp` (the `tile_offsets` stage); shared helpers in `tile.rs`.
use super::bindings::Bindings;
use super::footprint::FootprintInputs;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::plan::tile_grid;

/// Exclusive prefix sum of the tiles' totals; `tile_start[tiles]` gets the total.
pub fn tile_offsets(inputs: &FootprintInputs<'_>, tile_start: &mut [u32]) {
    let (tx, ty) = tile_grid(inputs.frame);
    let tiles = (tx * ty) as usize;
    let mut carry = 0u32;
    for v in &mut tile_start[..tiles] {
        let c = *v;
        *v = carry;
        carry += c;
    }
    tile_start[tiles] = carry;
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut start = b.take(Res::TileStart);
    tile_offsets(&b.inputs(d.list), &mut start);
    b.put(Res::TileStart, start);
    Ok(())
}
