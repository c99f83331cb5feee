//! Mirror of `glsl/project_winners.comp`: a projection's voxels that draw (each texel's winner,
//! and those that claim no texel), packed, their count in the texels' word 0.
use super::bindings::Bindings;
use super::brick::{inputs, voxel_ijk, BrickInputs};
use super::project_texels::{claim_of, NO_TEXEL};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::BrickPush;

/// The batch's voxels that draw, in order (the device's are in any order: a projection's blend
/// is order-free), after `texels[0]` earlier ones.
pub fn project_winners(
    inputs: &BrickInputs<'_>,
    push: &BrickPush,
    voxels: &[[u32; 2]],
    voxel_texels: &[u32],
    texels: &mut [u32],
    out: &mut [[u32; 2]],
) {
    for (v, &t) in voxels.iter().zip(voxel_texels).take(push.splats as usize) {
        let wins = t == NO_TEXEL || texels[t as usize] == claim_of(inputs, voxel_ijk(*v), v[1] >> 16);
        if wins {
            out[texels[0] as usize] = *v;
            texels[0] += 1;
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let (mut texels, mut out) = (b.take(Res::ProjectTexels), b.take(Res::ProjectVoxels));
    let (voxels, voxel_texels) = (b.get(Res::BrickVoxels), b.get(Res::VoxelTexels));
    project_winners(
        &inputs(b)?,
        &args.push_as(),
        voxels,
        voxel_texels,
        &mut texels,
        bytemuck::cast_slice_mut(&mut out),
    );
    b.put(Res::ProjectTexels, texels);
    b.put(Res::ProjectVoxels, out);
    Ok(())
}
