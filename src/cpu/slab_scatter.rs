//! Mirror of `glsl/slab_scatter.comp` (the `slab_scatter` stage); shared helpers in `slab.rs`.
use super::bindings::Bindings;
use super::slab::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::{SlabPush, SplatParams};

/// The (splat, slab) pairs written in visiting order (the stage's loops, whole).
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

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, v: &Variant) -> Result<()> {
    let (mut counts, mut pairs) = (b.take(Res::SlabCounts), b.take(Res::SlabPairs));
    slab_scatter(&d.push_as(), b.get(Res::Params), sheet_voxels(b, v), &mut counts, &mut pairs);
    b.put(Res::SlabCounts, counts);
    b.put(Res::SlabPairs, pairs);
    Ok(())
}
