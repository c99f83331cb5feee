//! Mirror of `glsl/brick_params.comp` (the `brick_params` stage); shared helpers in `brick.rs`.
use super::bindings::Bindings;
use super::brick::*;
use super::splat_params::{optical_depth, params_at, project_emit};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{BrickPush, SplatParams};
use glam::Vec3;

/// The largest stored value (16 bits), as `brick.glsl`'s Q_MAX.
const Q_MAX: f32 = 65535.0;

/// Pass 3: per splat of the batch, classify its voxel and make its parameters, grown when its
/// brick morphs (coarse cells are `brick_lod_params`').
pub fn brick_params(inputs: &BrickInputs<'_>, push: &BrickPush, voxels: &[[u32; 2]], params: &mut [SplatParams]) {
    let shaded = inputs.bf.light[3] > 0.5;
    for (s, v) in voxels.iter().enumerate().take(push.splats as usize) {
        if voxel_level(*v) != 0 {
            continue;
        }
        let ijk = voxel_ijk(*v);
        let c = inputs.classify_voxel(ijk.map(|c| c as i64), v[1] >> 16, shaded);
        let at = Vec3::from_array(ijk.map(|c| c as f32));
        let grow = if v[1] & VOXEL_MORPHS != 0 { inputs.splat_growth(at, 0) } else { 1.0 };
        let mut p = params_at(inputs.frame, at, 1.0, grow, [c[0], c[1], c[2]], optical_depth(c[3]));
        if inputs.frame.rect[2] != 0 {
            let d = ((v[1] >> 16) as f32 / Q_MAX * inputs.bf.tf[0] + inputs.bf.tf[1]).clamp(0.0, 1.0);
            p.emit = project_emit(inputs.frame.rect[2], d, p.emit[3]);
        }
        params[s] = p;
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let mut params = b.take(Res::Params);
    // A projection with texels draws project_winners' packed voxels.
    let voxels = b.get(if v.defines.contains("PROJECT_VOXELS") { Res::ProjectVoxels } else { Res::BrickVoxels });
    brick_params(&inputs_for(b, v)?, &args.push_as(), voxels, bytemuck::cast_slice_mut(&mut params));
    b.put(Res::Params, params);
    Ok(())
}
