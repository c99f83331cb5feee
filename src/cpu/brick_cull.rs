//! Mirror of `glsl/brick_cull.comp` (the `brick_cull` stage); shared helpers in `brick.rs`.
use super::bindings::Bindings;
use super::brick::*;
use super::brick_words::level_count;
use crate::bricks::BRICK;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;

/// Pass 1: cull each non-empty brick or write its header and count at its draw-order slot
/// (`counts`: a streamed store's drawn voxels per brick, counted on the host), and with levels of
/// detail its splats' morph.
pub fn brick_cull(inputs: &BrickInputs<'_>, counts: Option<&[u32]>, slots: &mut [u32], morphs: &mut [f32]) {
    let store = inputs.store;
    for (h, hd) in store.headers.iter().enumerate() {
        let b = hd.coords();
        let (lo, hi) = (inputs.bf.lo, inputs.bf.hi);
        if (0..3).any(|a| b[a] < lo[a] || b[a] >= hi[a]) || inputs.tf_empty(hd.range & 0xffff, hd.range >> 16) {
            continue;
        }
        let (level, morph) = inputs.brick_level(h as u32, b);
        let k = inputs.node_cut(b);
        if k > 0 {
            // Mirror of the node branch: the node's first drawing brick draws it.
            morphs[h] = 0.0;
            let w = inputs.node_of(k, b);
            if w[5] == h as u32
                && super::brick_words::tau_decode(w[0] & 0xffff) > 0.0
                && !inputs.outside_view(b, k, (BRICK << k) as f32)
            {
                slots[inputs.brick_slot(b) as usize] = (h as u32) << 10 | slot_code(3 + k, 1);
            }
            continue;
        }
        if inputs.outside_view(b, 0, (1u32 << level) as f32 * (1.0 + morph)) {
            continue;
        }
        let drawn = match counts {
            _ if inputs.bf.grad[1] > 0.0 => level_count(inputs.summary, h as u32, level),
            Some(c) => c[h],
            None => store.drawn_in(hd, |q| inputs.emits(q)),
        };
        if drawn > 0 {
            slots[inputs.brick_slot(b) as usize] = (h as u32) << 10 | slot_code(level, drawn);
        }
        if inputs.bf.grad[1] > 0.0 {
            morphs[h] = morph;
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, _: &Args, v: &Variant) -> Result<()> {
    let (mut slots, mut morphs) = (b.take(Res::BrickSlots), b.take(Res::BrickMorph));
    let counts = streamed(v).then(|| b.get::<u32>(Res::BrickCounts));
    brick_cull(&inputs(b)?, counts, &mut slots, bytemuck::cast_slice_mut(&mut morphs));
    b.put(Res::BrickSlots, slots);
    b.put(Res::BrickMorph, morphs);
    Ok(())
}
