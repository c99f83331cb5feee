//! Mirror of `glsl/brick_lod_params.comp` (the `brick_lod_params` stage); shared helpers in `lod.rs`.
use super::bindings::Bindings;
use super::brick::{inputs_for, voxel_ijk, voxel_level, BrickInputs, VOXEL_MORPHS};
use super::splat_params::params_at;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{BrickPush, SplatParams};
use crate::plan::LOD_LEVELS;
use glam::Vec3;

/// Mirror of `brick_lod_params.comp`: the parameters of the coarse splats at positions
/// `lod_splats` (`push.splats` of them) from their pyramid cells.
pub fn brick_lod_params(
    inputs: &BrickInputs<'_>,
    lod_splats: &[u32],
    push: &BrickPush,
    voxels: &[[u32; 2]],
    params: &mut [SplatParams],
) {
    let (shaded, dims) = (inputs.bf.light[3] > 0.5, inputs.frame.dims);
    let (f, grid) = (inputs.frame, super::splat_params::frame_grid(inputs.frame));
    for &s in &lod_splats[..push.splats as usize] {
        let v = voxels[s as usize];
        let (ijk, level) = (voxel_ijk(v), voxel_level(v));
        let at = Vec3::from_array(
            [0, 1, 2].map(|a| ijk[a] as f32 + 0.5 * ((1u32 << level).min(dims[a] - ijk[a]) as f32 - 1.0)),
        );
        let grow = if v[1] & VOXEL_MORPHS != 0 { inputs.splat_growth(at, level) } else { 1.0 };
        let view = if f.eye[3] > 0.5 {
            grid.point(at) - Vec3::new(f.eye[0], f.eye[1], f.eye[2])
        } else {
            Vec3::new(f.forward[0], f.forward[1], f.forward[2])
        };
        let view = grid.index_dir(view.as_dvec3()).as_vec3();
        let (mut c, normal) = if level > LOD_LEVELS {
            inputs.node_color(level - LOD_LEVELS, ijk.map(|c| c >> level), view)
        } else {
            inputs.cell_color(inputs.store.header_of(ijk), v[1] >> 16, view)
        };
        if shaded {
            inputs.shade(&mut c, normal);
        }
        params[s as usize] = params_at(inputs.frame, at, (1u32 << level) as f32, grow, [c[0], c[1], c[2]], c[3]);
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let mut params = b.take(Res::Params);
    brick_lod_params(
        &inputs_for(b, v)?,
        b.get(Res::LodSplats),
        &args.push_as(),
        b.get(Res::BrickVoxels),
        bytemuck::cast_slice_mut(&mut params),
    );
    b.put(Res::Params, params);
    Ok(())
}
