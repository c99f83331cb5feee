//! Mirror of `host_depth.comp`: the host's depth buffer as eye-space depth per pixel.
use super::bindings::Bindings;
use crate::dispatch::{Args, Res, Variant};
use crate::error::Result;
use crate::gpu_types::DepthPush;
use glam::{Mat4, Vec4};

/// Eye-space depth of each texel of `raw` (`push.format`), +inf (1e30) at or past infinity.
pub fn host_depth(push: &DepthPush, raw: &[u32]) -> Vec<f32> {
    let inv = Mat4::from_cols_array_2d(&push.inv_proj);
    let (w, h) = (push.width, push.height);
    (0..w as usize * h as usize)
        .map(|i| {
            let (x, y) = ((i as u32 % w) as f32, (i as u32 / w) as f32);
            let t = raw[i];
            let z = if push.format == 0 { f32::from_bits(t) } else { (t & 0xff_ffff) as f32 / 16777215.0 };
            let ndc = [(x + 0.5) / w as f32 * 2.0 - 1.0, (y + 0.5) / h as f32 * 2.0 - 1.0];
            let e = inv * Vec4::new(ndc[0], ndc[1], z, 1.0);
            if e.w > 0.0 {
                -e.z / e.w
            } else {
                1.0e30
            }
        })
        .collect()
}

pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let push = args.push_as::<DepthPush>();
    let depth = host_depth(&push, b.get(Res::HostDepthRaw));
    b.put(Res::HostDepth, depth.into_iter().map(f32::to_bits).collect());
    Ok(())
}
