//! Mirror of `glsl/slab_scan.comp` (the `slab_scan` stage); shared helpers in `slab.rs`.
use super::bindings::Bindings;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::SlabPush;

/// Each slab's first pair, then the total (the stage's scan, whole).
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

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let (mut counts, mut start) = (b.take(Res::SlabCounts), b.take(Res::SlabStart));
    slab_scan(&d.push_as(), &mut counts, &mut start);
    b.put(Res::SlabCounts, counts);
    b.put(Res::SlabStart, start);
    Ok(())
}
