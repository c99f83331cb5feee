//! Mirror of `glsl/footprint_sum.comp` (the `footprint_sum` stage); shared helpers in `footprint.rs`.
use super::bindings::Bindings;
use super::footprint::*;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::FootprintPush;

/// Mirror of `footprint_sum.comp` (its SUM64 build): add `push.count` entries from `push.first` to
/// the fixed-point layers `sums` (layer-major rows of width x 4 channels), channels (r, g) and
/// (b, tau) added as one 64-bit word each, wrapping as the GPU's atomics do (the 32-bit build
/// differs only where a channel's sum wraps, which `SUM_FIXED_SCALE` keeps out of reach).
pub fn footprint_sum(inputs: &FootprintInputs<'_>, push: &FootprintPush, sums: &mut [u32]) {
    let (width, height) = (inputs.frame.blur[2] as usize, inputs.frame.blur[3] as usize);
    for e in push.first..push.first + push.count {
        let Some((splat, layer, weight)) = entry(inputs, push, e) else { continue };
        let p = &inputs.params[splat];
        let Some((inv, bx)) = screen_quad(inputs.frame, p) else { continue };
        let energy = p.emit[3] * p.axis_u[3];
        for y in bx.y..=bx.w {
            for x in bx.x..=bx.z {
                let uv = quad_uv(&inv, x, y);
                if uv.x.abs() > 1.0 || uv.y.abs() > 1.0 {
                    continue;
                }
                let tau = weight.value(uv, Sweep::of(inputs.frame, p), energy, false);
                if tau <= 0.0 {
                    continue;
                }
                let idx = 4 * ((layer * height + y as usize) * width + x as usize);
                let Some(px) = sums.get_mut(idx..idx + 4) else { continue };
                let add = [p.emit[0] * tau, p.emit[1] * tau, p.emit[2] * tau, tau].map(fixed_point);
                for (pair, add) in px.chunks_exact_mut(2).zip(add.chunks_exact(2)) {
                    let word =
                        (pair[0] as u64 | (pair[1] as u64) << 32).wrapping_add(add[0] as u64 | (add[1] as u64) << 32);
                    (pair[0], pair[1]) = (word as u32, (word >> 32) as u32);
                }
            }
        }
    }
}

pub(crate) fn stage(b: &mut Bindings<'_>, d: &Args, _: &Variant) -> Result<()> {
    let mut sums = b.take(Res::Fixed);
    footprint_sum(&b.inputs(d.list), &d.push_as(), &mut sums);
    b.put(Res::Fixed, sums);
    Ok(())
}
