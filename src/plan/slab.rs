//! Image-aligned sheet buffers (Mueller & Crawfis 1998): the volume is cut into slabs of constant
//! eye-space depth, parallel to the image plane in orthographic and perspective views alike, so
//! the sheets do not switch axis as the view turns (section 1.2.2.3's *splat ordering problem*).
//!
//! Slab geometry: slab j spans depths [z0 + j·Δ, z0 + (j+1)·Δ) along the view direction, with z0
//! the nearest kernel extent in the scene and Δ the thickness in voxel spacings. A splat at depth d
//! with world radius R is drawn once into every slab its depth range [d - R, d + R] overlaps, each
//! time weighted by the kernel slice between that slab's faces (`Kernel::slice_table`); the
//! footprint quad stays eye-facing and a slab face is measured from the splat's centre along the
//! view axis, the same for every pixel of the footprint (the perspective approximation).
//!
//! Binning is a stable counting sort of (splat, slab) pairs by slab, in visiting order, so every
//! batch of slabs is one contiguous run of instances: three GPU stages after `splat_params`
//! (`slab_count`, `slab_scan`, `slab_scatter`, mirrored in `cpu::slab`). The host only fixes the
//! slab geometry from the grid's bounds (O(1)) and reads back the slabs' first pairs (one u32 per
//! slab) to size the pair buffer and cut the batches.
use super::{footprint_scale, Batch};
use crate::constants::SLAB_CHUNK;
use crate::error::{Error, Result};
use crate::gpu_types::{FootprintPush, Frame, SlabPush, SHEET_MODE_SLAB};
use crate::order::Direction;
use crate::volume::Grid;
use glam::Vec3;

/// Thinnest slab allowed, in voxel spacings (pairs grow as 2R/Δ).
pub const MIN_SLAB_THICKNESS: f32 = 0.25;
/// Most (splat, slab) pairs in one frame (8 bytes each: 128 MiB, the one storage binding every
/// device allows, 2^27 bytes).
pub const MAX_SLAB_PAIRS: u64 = 1 << 24;
/// Most cells of the slab x chunk count matrix (4 bytes each: 64 MiB).
pub const MAX_SLAB_CELLS: u64 = 1 << 24;

/// Where the slabs lie for one frame, as the binning stages' push constants.
pub fn slab_geometry(frame: &Frame, grid: &Grid, n: usize, thickness: f32, direction: Direction) -> Result<SlabPush> {
    if !(thickness.is_finite() && thickness >= MIN_SLAB_THICKNESS) {
        return Err(Error::InvalidArgument(format!(
            "slab thickness {thickness} must be at least {MIN_SLAB_THICKNESS} voxel spacings"
        )));
    }
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let (eye, forward) = (v3(frame.eye), v3(frame.forward));
    let dz = thickness * frame.spacing[3] / frame.origin[3];
    // Depths of the grid's corner voxel centres bound every splat's.
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for c in 0..8u32 {
        let ijk = [0, 1, 2].map(|a| if c >> a & 1 == 1 { grid.dims[a].saturating_sub(1) } else { 0 });
        let d = (grid.position(ijk) - eye).dot(forward);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    // The footprint scale grows with depth; a hair wider, as in the shaders.
    let scale = footprint_scale(frame, lo.max(1e-6)).max(footprint_scale(frame, hi.max(1e-6)));
    let r = frame.spacing[3] * scale * 1.0001;
    let (near, far) = (frame.forward[3], frame.right[3]);
    let z0 = (lo - r).max(near);
    let top = (hi + r).min(far);
    let slabs = if top > z0 { ((top - z0) / dz).floor() as u64 + 1 } else { 1 };
    let chunks = (n as u64).div_ceil(SLAB_CHUNK as u64).max(1);
    if slabs * chunks > MAX_SLAB_CELLS {
        return Err(Error::TooLarge(format!(
            "{slabs} slabs x {chunks} splat chunks exceed {MAX_SLAB_CELLS} binning cells: use thicker slabs"
        )));
    }
    Ok(SlabPush {
        z0,
        dz,
        slabs: slabs as u32,
        chunks: chunks as u32,
        ftb: (direction == Direction::FrontToBack) as u32,
        n: n as u32,
        axis: 0,
        pad: 0,
    })
}

/// The slabs (first, last) that voxels with grid indices in the box `lo..=hi` may reach: their
/// depths lie between the box corners', and their kernels reach no further than `slab_geometry`
/// allows any splat's (the same bound the binning widens by). Splits a bricked frame's slabs
/// between its bricks.
pub fn box_slabs(pc: &SlabPush, frame: &Frame, grid: &Grid, lo: [u32; 3], hi: [u32; 3]) -> (u32, u32) {
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let (eye, forward) = (v3(frame.eye), v3(frame.forward));
    let (mut near, mut far) = (f32::INFINITY, f32::NEG_INFINITY);
    for c in 0..8u32 {
        let ijk = [0, 1, 2].map(|a| if c >> a & 1 == 1 { hi[a] } else { lo[a] });
        let d = (grid.position(ijk) - eye).dot(forward);
        near = near.min(d);
        far = far.max(d);
    }
    let scale = footprint_scale(frame, near.max(1e-6)).max(footprint_scale(frame, far.max(1e-6)));
    let r = frame.spacing[3] * scale * 1.001;
    let slab_of = |z: f32| ((z - pc.z0) / pc.dz).floor().clamp(0.0, (pc.slabs - 1) as f32) as u32;
    (slab_of(near - r), slab_of(far + r))
}

/// A bricked volume's axis-aligned sheets as the binning stages' push constants (`AXIS_SHEETS`
/// builds): one bin per voxel plane along `axis`, in index order, for `n` splats.
pub fn sheet_geometry(grid: &Grid, n: u32, axis: usize) -> Result<SlabPush> {
    let slabs = grid.dims[axis].max(1);
    let chunks = n.div_ceil(SLAB_CHUNK).max(1);
    if slabs as u64 * chunks as u64 > MAX_SLAB_CELLS {
        return Err(Error::TooLarge(format!(
            "{slabs} sheets x {chunks} splat chunks exceed {MAX_SLAB_CELLS} binning cells: draw this volume per splat"
        )));
    }
    Ok(SlabPush { z0: 0.0, dz: 1.0, slabs, chunks, ftb: 1, n, axis: axis as u32, pad: 0 })
}

/// The batches of at most `max_layers` consecutive slabs in visiting order, from each slab's first
/// pair (`slab_start`, slabs + 1 entries). Batches without a pair are dropped.
pub fn slab_batches(pc: &SlabPush, slab_start: &[u32], max_layers: u32) -> Result<Vec<Batch>> {
    let total = slab_start[pc.slabs as usize] as u64;
    if total > MAX_SLAB_PAIRS {
        return Err(Error::TooLarge(format!("{total} splat-slab pairs (limit {MAX_SLAB_PAIRS}): use thicker slabs")));
    }
    let slabs = pc.slabs as usize;
    let layers = max_layers.max(1) as usize;
    let mut batches = Vec::new();
    for start in (0..slabs).step_by(layers) {
        let end = (start + layers).min(slabs);
        let (first, count) = (slab_start[start], slab_start[end] - slab_start[start]);
        if count == 0 {
            continue;
        }
        let base = if pc.ftb != 0 { start } else { slabs - 1 - start } as u32;
        batches.push(Batch {
            first_instance: first,
            instances: count,
            layers: (end - start) as u32,
            push: FootprintPush {
                sheet_mode: SHEET_MODE_SLAB,
                rank_base: base,
                rank_dir: if pc.ftb != 0 { 1 } else { -1 },
                slab_z0: pc.z0,
                slab_dz: pc.dz,
                ..Default::default()
            },
        });
    }
    Ok(batches)
}
