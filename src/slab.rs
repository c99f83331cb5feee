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
//! This module is the binning stage: a counting sort of (splat, slab) pairs by slab, in visiting
//! order, so every batch of slabs is one contiguous run of instances. It runs on the host each frame
//! (linear in the pairs; measured as `slab_bins` in the stage timings).
use crate::cpu::splat_params::{footprint_scale, optical_depth};
use crate::error::{Error, Result};
use crate::gpu_types::{FootprintPush, Frame, Splat, SHEET_MODE_SLAB};
use crate::order::Direction;
use crate::pipeline::Batch;
use glam::Vec3;

/// Thinnest slab allowed, in voxel spacings (pairs grow as 2R/Δ).
pub const MIN_SLAB_THICKNESS: f32 = 0.25;
/// Most (splat, slab) pairs in one frame (8 bytes each: 1 GiB).
pub const MAX_SLAB_PAIRS: u64 = 1 << 27;

/// One frame's slabs: geometry, the pair list and its batches.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SlabPlan {
    /// Depth of slab 0's near face and the slab thickness, world units.
    pub z0: f32,
    pub dz: f32,
    /// Slabs from the nearest to the farthest kernel extent.
    pub slabs: u32,
    /// (splat, slab) pairs, interleaved, grouped by slab in visiting order (stable in splat index).
    pub pairs: Vec<u32>,
    pub batches: Vec<Batch>,
}

/// Bin `splats` into slabs `thickness` voxel spacings thick, in `direction`'s visiting order, with
/// at most `max_layers` slabs per batch. Mirror of nothing: it is the same code on both paths.
pub fn slab_bins(
    frame: &Frame,
    splats: &[Splat],
    thickness: f32,
    direction: Direction,
    max_layers: u32,
) -> Result<SlabPlan> {
    if !(thickness.is_finite() && thickness >= MIN_SLAB_THICKNESS) {
        return Err(Error::InvalidArgument(format!(
            "slab thickness {thickness} must be at least {MIN_SLAB_THICKNESS} voxel spacings"
        )));
    }
    let v3 = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let (eye, forward, origin, spacing) = (v3(frame.eye), v3(frame.forward), v3(frame.origin), v3(frame.spacing));
    let voxel = frame.spacing[3] / frame.origin[3];
    let dz = thickness * voxel;
    // Depth extents of the splats that can show (zero optical depth draws nothing).
    let mut extents = Vec::with_capacity(splats.len());
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for (s, sp) in splats.iter().enumerate() {
        if optical_depth(sp.color[3]) <= 0.0 {
            continue;
        }
        let ijk = Vec3::new(sp.ijk[0] as f32, sp.ijk[1] as f32, sp.ijk[2] as f32);
        let depth = (origin + ijk * spacing - eye).dot(forward);
        // A hair wider than the shader's radius, so a rounding difference never drops a slice.
        let radius = frame.spacing[3] * footprint_scale(frame, depth) * 1.0001;
        extents.push((s as u32, depth - radius, depth + radius));
        lo = lo.min(depth - radius);
        hi = hi.max(depth + radius);
    }
    if extents.is_empty() {
        return Ok(SlabPlan { dz, ..Default::default() });
    }
    let slabs = ((hi - lo) / dz).floor() as u64 + 1;
    let slab_of = |z: f32| (((z - lo) / dz).floor().max(0.0) as u64).min(slabs - 1);
    let total: u64 = extents.iter().map(|&(_, a, b)| slab_of(b) - slab_of(a) + 1).sum();
    if total > MAX_SLAB_PAIRS || slabs > u32::MAX as u64 {
        return Err(Error::TooLarge(format!(
            "{total} splat-slab pairs over {slabs} slabs (limit {MAX_SLAB_PAIRS}): use thicker slabs"
        )));
    }
    let slabs = slabs as usize;
    // Visiting position of a slab: near to far front to back, far to near back to front.
    let ftb = direction == Direction::FrontToBack;
    let pos = |slab: usize| if ftb { slab } else { slabs - 1 - slab };
    let mut offsets = vec![0u32; slabs + 1];
    for &(_, a, b) in &extents {
        for slab in slab_of(a)..=slab_of(b) {
            offsets[pos(slab as usize) + 1] += 1;
        }
    }
    for i in 0..slabs {
        offsets[i + 1] += offsets[i];
    }
    let mut cursor = offsets.clone();
    let mut pairs = vec![0u32; 2 * total as usize];
    for &(s, a, b) in &extents {
        for slab in slab_of(a)..=slab_of(b) {
            let c = &mut cursor[pos(slab as usize)];
            pairs[2 * *c as usize] = s;
            pairs[2 * *c as usize + 1] = slab as u32;
            *c += 1;
        }
    }
    let layers = max_layers.max(1) as usize;
    let mut batches = Vec::new();
    for start in (0..slabs).step_by(layers) {
        let end = (start + layers).min(slabs);
        let (first, count) = (offsets[start], offsets[end] - offsets[start]);
        if count == 0 {
            continue;
        }
        let base = if ftb { start } else { slabs - 1 - start } as u32;
        batches.push(Batch {
            first_instance: first,
            instances: count,
            layers: (end - start) as u32,
            push: FootprintPush {
                sheet_mode: SHEET_MODE_SLAB,
                rank_base: base,
                rank_dir: if ftb { 1 } else { -1 },
                slab_z0: lo,
                slab_dz: dz,
                ..Default::default()
            },
        });
    }
    Ok(SlabPlan { z0: lo, dz, slabs: slabs as u32, pairs, batches })
}
