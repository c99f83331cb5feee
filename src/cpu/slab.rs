//! Mirrors of the slab binning stages `slab_count.comp`, `slab_scan.comp` and `slab_scatter.comp`.
use super::bindings::Bindings;
use crate::constants::SLAB_CHUNK;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{SlabPush, SplatParams};
use glam::Vec3;

fn slab_pos(pc: &SlabPush, slab: u32) -> u32 {
    if pc.ftb != 0 {
        slab
    } else {
        pc.slabs - 1 - slab
    }
}

fn slab_of(pc: &SlabPush, z: f32) -> u32 {
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

fn chunk_range(pc: &SlabPush, chunk: u32) -> std::ops::Range<usize> {
    (chunk * SLAB_CHUNK) as usize..((chunk + 1) * SLAB_CHUNK).min(pc.n) as usize
}

pub fn slab_count(pc: &SlabPush, params: &[SplatParams], voxels: Option<&[[u32; 2]]>, counts: &mut [u32]) {
    for chunk in 0..pc.chunks {
        for pos in 0..pc.slabs {
            counts[(pos * pc.chunks + chunk) as usize] = 0;
        }
        for s in chunk_range(pc, chunk) {
            if let Some((first, last)) = slab_range(pc, s, &params[s], voxels) {
                for slab in first..=last {
                    counts[(slab_pos(pc, slab) * pc.chunks + chunk) as usize] += 1;
                }
            }
        }
    }
}

pub fn slab_scan(pc: &SlabPush, counts: &mut [u32], slab_start: &mut [u32]) {
    let mut carry = 0u32;
    for c in counts.iter_mut().take((pc.slabs * pc.chunks) as usize) {
        let v = *c;
        *c = carry;
        carry += v;
    }
    for pos in 0..pc.slabs {
        slab_start[pos as usize] = counts[(pos * pc.chunks) as usize];
    }
    slab_start[pc.slabs as usize] = carry;
}

pub fn slab_scatter(
    pc: &SlabPush,
    params: &[SplatParams],
    voxels: Option<&[[u32; 2]]>,
    counts: &mut [u32],
    pairs: &mut [u32],
) {
    for chunk in 0..pc.chunks {
        for s in chunk_range(pc, chunk) {
            if let Some((first, last)) = slab_range(pc, s, &params[s], voxels) {
                for slab in first..=last {
                    let cell = (slab_pos(pc, slab) * pc.chunks + chunk) as usize;
                    let at = counts[cell] as usize;
                    counts[cell] += 1;
                    pairs[2 * at] = s as u32;
                    pairs[2 * at + 1] = slab;
                }
            }
        }
    }
}

/// The batch's voxels in `AXIS_SHEETS` builds.
fn sheet_voxels<'b>(b: &'b Bindings<'_>, v: &Variant) -> Option<&'b [[u32; 2]]> {
    (v.defines == "AXIS_SHEETS").then(|| b.get(Res::BrickVoxels))
}

pub(crate) fn slab_count_stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let mut counts = b.take(Res::SlabCounts);
    slab_count(&d.push_as(), b.get(Res::Params), sheet_voxels(b, v), &mut counts);
    b.put(Res::SlabCounts, counts);
    Ok(())
}

pub(crate) fn slab_scan_stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut start) = (b.take(Res::SlabCounts), b.take(Res::SlabStart));
    slab_scan(&d.push_as(), &mut counts, &mut start);
    b.put(Res::SlabCounts, counts);
    b.put(Res::SlabStart, start);
    Ok(())
}

pub(crate) fn slab_scatter_stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let (mut counts, mut pairs) = (b.take(Res::SlabCounts), b.take(Res::SlabPairs));
    slab_scatter(&d.push_as(), b.get(Res::Params), sheet_voxels(b, v), &mut counts, &mut pairs);
    b.put(Res::SlabCounts, counts);
    b.put(Res::SlabPairs, pairs);
    Ok(())
}
