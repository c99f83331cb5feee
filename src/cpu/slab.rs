//! Helpers the slab stages' mirrors share (`slab_count.rs`, `slab_scan.rs`, `slab_scatter.rs`).
use super::bindings::Bindings;
use crate::constants::SLAB_CHUNK;
use crate::dispatch::{Res, Variant};
use crate::gpu_types::{SlabPush, SplatParams};
use glam::Vec3;

pub(crate) fn slab_pos(pc: &SlabPush, slab: u32) -> u32 {
    if pc.ftb != 0 {
        slab
    } else {
        pc.slabs - 1 - slab
    }
}

pub(crate) fn slab_of(pc: &SlabPush, z: f32) -> u32 {
    ((z - pc.z0) / pc.dz).floor().clamp(0.0, (pc.slabs - 1) as f32) as u32
}

/// First and last slab a splat's kernel overlaps; `None` when it is culled. With `voxels` (the
/// `AXIS_SHEETS` build: a bricked batch's voxels from `brick_order`), splat `s`'s voxel plane
/// along `pc.axis`.
pub fn slab_range(pc: &SlabPush, s: usize, p: &SplatParams, voxels: Option<&[[u32; 2]]>) -> Option<(u32, u32)> {
    if p.center[3] == 0.0 {
        return None;
    }
    if let Some(v) = voxels {
        let sheet = super::brick::voxel_ijk(v[s])[pc.axis as usize];
        return Some((sheet, sheet));
    }
    // The kernel's depth extent: anti-aliasing widens it on the screen only.
    let r = Vec3::new(p.axis_v[0], p.axis_v[1], p.axis_v[2]).length() / p.screen[3] * 1.0001;
    Some((slab_of(pc, p.screen[0] - r), slab_of(pc, p.screen[0] + r)))
}

pub(crate) fn chunk_range(pc: &SlabPush, chunk: u32) -> std::ops::Range<usize> {
    (chunk * SLAB_CHUNK) as usize..((chunk + 1) * SLAB_CHUNK).min(pc.n) as usize
}

/// The batch's voxels in `AXIS_SHEETS` builds.
pub(crate) fn sheet_voxels<'b>(b: &'b Bindings<'_>, v: &Variant) -> Option<&'b [[u32; 2]]> {
    (v.defines == "AXIS_SHEETS").then(|| b.get(Res::BrickVoxels))
}
