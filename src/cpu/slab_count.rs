//! Mirror of `glsl/slab_count.comp` (the `slab_count` stage); shared helpers in `slab.rs`.
use super::bindings::Bindings;
use super::slab::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{SlabPush, SplatParams};

/// Each (slab, chunk) cell's count of pairs (the stage's loops, whole).
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

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let mut counts = b.take(Res::SlabCounts);
    slab_count(&d.push_as(), b.get(Res::Params), sheet_voxels(b, v), &mut counts);
    b.put(Res::SlabCounts, counts);
    Ok(())
}
