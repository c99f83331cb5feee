//! Mirror of `glsl/brick_quads.comp` (the `brick_quads` stage): `brick_params`' splats as screen quads.
use super::bindings::Bindings;
use super::brick::*;
use super::tile::screen_record;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{BrickPush, ScreenQuad, SplatParams};

/// Each voxel's splat of the batch (`brick_params`) as its footprint in screen space.
pub fn brick_quads(inputs: &BrickInputs<'_>, push: &BrickPush, voxels: &[[u32; 2]], quads: &mut [ScreenQuad]) {
    let mut params = vec![SplatParams::default(); push.splats as usize];
    super::brick_params::brick_params(inputs, push, voxels, &mut params);
    for (s, v) in voxels.iter().enumerate().take(push.splats as usize) {
        if voxel_level(*v) == 0 {
            quads[s] = screen_record(inputs.frame, &params[s]);
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let mut quads = b.take(Res::Quads);
    brick_quads(&inputs_for(b, v)?, &args.push_as(), b.get(Res::BrickVoxels), bytemuck::cast_slice_mut(&mut quads));
    b.put(Res::Quads, quads);
    Ok(())
}
