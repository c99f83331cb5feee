//! Mirror of `brick_hidden.comp`: between waves of a bricked frame drawn front to back, the
//! entries whose footprints lie wholly over pixels earlier waves closed (`tile_occlusion`).
use super::bindings::Bindings;
use super::brick::{corner, inputs, BrickInputs};
use super::tile_occlusion::box_hidden;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::BrickPush;
use glam::{IVec4, Mat4, Vec2, Vec4};

/// Per entry of the batch, 1 when its footprints' screen box covers no open pixel of `occlusion`.
pub fn brick_hidden(
    inputs: &BrickInputs<'_>,
    list: &[[u32; 4]],
    push: &BrickPush,
    occlusion: &[u32],
    hidden: &mut [u32],
) {
    let f = inputs.frame;
    let vp = Mat4::from_cols_array_2d(&f.view_proj);
    let size = Vec2::new(f.blur[2], f.blur[3]);
    let is_hidden = |h: u32, level: u32, b: [u32; 3]| {
        // A blurred quad reaches back along its path, past the footprint box.
        if f.blur[0] > 0.0 {
            return false;
        }
        let morph = if inputs.bf.grad[1] > 0.0 { inputs.morphs[h as usize] } else { 0.0 };
        // A node above the brick (level 3 + its tree level) does not morph.
        let k = level.saturating_sub(3);
        let (lo, hi) = inputs.footprint_box(b, k, (1u32 << level) as f32 * (1.0 + morph));
        let (mut slo, mut shi) = (Vec2::splat(1e30), Vec2::splat(-1e30));
        for c in 0..8 {
            let q: Vec4 = vp * corner(lo, hi, c).extend(1.0);
            if q.w <= 0.0 {
                return false;
            }
            let s = (Vec2::new(q.x, q.y) / q.w * 0.5 + 0.5) * size;
            (slo, shi) = (slo.min(s), shi.max(s));
        }
        let a = (slo - 1.0).clamp(Vec2::ZERO, size - 1.0).floor();
        let z = (shi + 1.0).clamp(Vec2::ZERO, size - 1.0).floor();
        box_hidden(f, occlusion, IVec4::new(a.x as i32, a.y as i32, z.x as i32, z.y as i32))
    };
    for (e, entry) in list[push.first as usize..(push.first + push.count) as usize].iter().enumerate() {
        hidden[e] = u32::from(is_hidden(entry[0], entry[3] >> 16, inputs.store.headers[entry[0] as usize].coords()));
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let mut hidden = b.take(Res::BrickHidden);
    brick_hidden(&inputs(b)?, b.get(Res::BrickList), &args.push_as(), b.get(Res::Occlusion), &mut hidden);
    b.put(Res::BrickHidden, hidden);
    Ok(())
}
