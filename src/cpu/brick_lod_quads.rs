//! Mirror of `glsl/brick_lod_quads.comp` (the `brick_lod_quads` stage): `brick_lod_params`'
//! splats as screen quads.
use super::bindings::Bindings;
use super::brick::inputs_for;
use super::tile::screen_record;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{BrickPush, ScreenQuad, SplatParams};

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let mut quads = b.take(Res::Quads);
    let quads_out: &mut [ScreenQuad] = bytemuck::cast_slice_mut(&mut quads);
    let (push, lod_splats, voxels) = (args.push_as::<BrickPush>(), b.get(Res::LodSplats), b.get(Res::BrickVoxels));
    let inputs = inputs_for(b, v)?;
    // The coarse splats' parameters at their own positions, then their quads there.
    let mut params = vec![SplatParams::default(); voxels.len()];
    super::brick_lod_params::brick_lod_params(&inputs, lod_splats, &push, voxels, &mut params);
    for &s in &lod_splats[..push.splats as usize] {
        quads_out[s as usize] = screen_record(inputs.frame, &params[s as usize]);
    }
    b.put(Res::Quads, quads);
    Ok(())
}
