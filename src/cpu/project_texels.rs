//! Mirror of `glsl/project_texels.comp` and `glsl/shared/texels.glsl`: a projection's texels (MIP,
//! MinIP), per texel the claim of the brightest voxel whose centre falls in it, the only one of
//! them that draws (`project_winners`).
use super::bindings::Bindings;
use super::brick::{corner, inputs, streamed, BrickInputs};
use super::splat_params::{frame_grid, CULL_RADII, PROJECT_SHRINK};
use crate::bricks::{local_cell, BrickStore, BRICK};
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::BrickPush;
use crate::options::Mode;
use glam::{Mat4, Vec2, Vec3};

/// The largest stored value (16 bits), as `brick.glsl`'s Q_MAX.
const Q_MAX: f32 = 65535.0;

/// `ProjectTexels`' words: a batch's drawn voxels (`project_winners`' count), then the texels.
pub const TEXELS_FIRST: usize = 1;

/// Mirror of `brick_claims`: whether brick `b`'s voxels claim texels (each draws wherever it falls:
/// its box clear of the near and far planes and inside every clipping plane).
pub fn brick_claims(inputs: &BrickInputs<'_>, b: [u32; 3]) -> bool {
    let f = inputs.frame;
    let (lo, hi) = inputs.voxel_box(b, 0);
    let (near, far) = inputs.box_depths(lo, hi);
    let margin = CULL_RADII * f.spacing[3] * PROJECT_SHRINK;
    if near - f.forward[3] < margin || f.right[3] - far < margin {
        return false;
    }
    f.clip[..f.rect[1] as usize]
        .iter()
        .all(|q| (0..8).all(|c| Vec3::new(q[0], q[1], q[2]).dot(corner(lo, hi, c)) + q[3] >= 0.0))
}

/// Mirror of `texel_of`: the texel voxel `ijk` of a claiming brick falls in (its word in
/// `ProjectTexels`), `None` where its centre falls outside the image.
pub fn texel_of(inputs: &BrickInputs<'_>, ijk: [u32; 3]) -> Option<usize> {
    let f = inputs.frame;
    let center = frame_grid(f).point(Vec3::from_array(ijk.map(|c| c as f32)));
    let c = Mat4::from_cols_array_2d(&f.view_proj) * center.extend(1.0);
    let n = Vec2::new(f.blur[2], f.blur[3]) * inputs.bf.split[3] as f32;
    let t = ((Vec2::new(c.x, c.y) / c.w * 0.5 + 0.5) * n).floor();
    let inside = c.w > 0.0 && t.x >= 0.0 && t.y >= 0.0 && t.x < n.x && t.y < n.y;
    inside.then(|| TEXELS_FIRST + t.y as usize * n.x as usize + t.x as usize)
}

/// Mirror of `claim_of`: voxel `ijk`'s claim (its key, 16 bits, over a hash of `ijk`).
pub fn claim_of(inputs: &BrickInputs<'_>, ijk: [u32; 3], q: u32) -> u32 {
    let d = (q as f32 / Q_MAX * inputs.bf.tf[0] + inputs.bf.tf[1]).clamp(0.0, 1.0);
    let key = if inputs.frame.rect[2] == Mode::Minip.code() { 1.0 - d } else { d };
    let h = ijk[0].wrapping_mul(73856093) ^ ijk[1].wrapping_mul(19349663) ^ ijk[2].wrapping_mul(83492791);
    ((key * 65535.0).round() as u32) << 16 | h >> 16
}

/// `VoxelTexels`' word for a voxel that claims no texel (`NO_TEXEL`).
pub const NO_TEXEL: u32 = u32::MAX;

/// The batch's bricks' extracted voxels from each brick's first position (in record order; the
/// device's in any order), each with the texel it claims, the largest claim of each texel kept.
pub struct Claims<'a> {
    /// `Res::BrickVoxels`.
    pub voxels: &'a mut [[u32; 2]],
    /// `Res::Order`: each position's own.
    pub order: &'a mut [u32],
    /// `Res::ProjectTexels`.
    pub texels: &'a mut [u32],
    /// `Res::VoxelTexels`.
    pub voxel_texels: &'a mut [u32],
}

/// Per visible brick of the batch (`list` from `push.first`), its extracted voxels and their claims.
pub fn project_texels(inputs: &BrickInputs<'_>, list: &[[u32; 4]], records: &[u32], push: &BrickPush, out: Claims<'_>) {
    for entry in &list[push.first as usize..(push.first + push.count) as usize] {
        let hd = inputs.store.headers[entry[0] as usize];
        let b = hd.coords();
        let mut pos = entry[1] as usize;
        let claims = brick_claims(inputs, b);
        for &rec in BrickStore::records_of(records, entry[2], &hd).iter() {
            if !inputs.emits(rec >> 16) {
                continue;
            }
            let lc = local_cell(rec & 511);
            let ijk = [0, 1, 2].map(|a| b[a] * BRICK + lc[a]);
            out.voxels[pos] = [ijk[0] | ijk[1] << 16, ijk[2] | (rec & 0xffff_0000)];
            out.order[pos] = pos as u32;
            out.voxel_texels[pos] = NO_TEXEL;
            if let Some(t) = texel_of(inputs, ijk).filter(|_| claims) {
                out.texels[t] = out.texels[t].max(claim_of(inputs, ijk, rec >> 16));
                out.voxel_texels[pos] = t as u32;
            }
            pos += 1;
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, v: &Variant) -> Result<()> {
    let (mut voxels, mut order) = (b.take(Res::BrickVoxels), b.take(Res::Order));
    let (mut texels, mut voxel_texels) = (b.take(Res::ProjectTexels), b.take(Res::VoxelTexels));
    let inputs = inputs(b)?;
    let records = if streamed(v) { b.get(Res::BatchRecords) } else { &inputs.store.records[..] };
    let out = Claims {
        voxels: bytemuck::cast_slice_mut(&mut voxels),
        order: &mut order,
        texels: &mut texels,
        voxel_texels: &mut voxel_texels,
    };
    project_texels(&inputs, b.get(Res::BrickList), records, &args.push_as(), out);
    b.put(Res::BrickVoxels, voxels);
    b.put(Res::Order, order);
    b.put(Res::ProjectTexels, texels);
    b.put(Res::VoxelTexels, voxel_texels);
    Ok(())
}
