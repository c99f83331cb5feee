//! Mirror of `present.comp`, and of the conversion the device's blit applies on the way into a
//! host's image (`Renderer::render_to`): the bytes a target of each format receives.
use super::bindings::Bindings;
use super::ImageF32;
use crate::dispatch::Res;
use crate::dispatch::{Args, Variant};
use crate::error::{Error, Result};
use crate::gpu_types::{PresentPush, PRESENT_HOST_BGRA, PRESENT_HOST_HALF, PRESENT_OVER};
pub use crate::image::TargetFormat;

/// The sRGB curve's inverse (IEC 61966-2-1), as `present.comp` applies it.
pub fn to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB curve, as the device applies it writing an `_SRGB` texel.
pub fn to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The host's texel `i` of `words` (its image as stored, `Res::HostColor`) as premultiplied
/// display values (`present.comp`'s host_texel): 8-bit texels as stored (an sRGB texel's bytes are
/// its display value), half-float ones encoded from linear.
pub fn host_texel(push: &PresentPush, words: &[u32], i: usize) -> [f32; 4] {
    if push.sources & PRESENT_HOST_HALF != 0 {
        let w = [words[2 * i], words[2 * i + 1]];
        let t = [w[0] & 0xffff, w[0] >> 16, w[1] & 0xffff, w[1] >> 16].map(|h| f16_value(h as u16).clamp(0.0, 1.0));
        if t[3] <= 0.0 {
            return [0.0; 4];
        }
        return [0, 1, 2, 3].map(|c| if c < 3 { to_srgb((t[c] / t[3]).min(1.0)) * t[3] } else { t[3] });
    }
    let t = words[i].to_le_bytes().map(|b| b as f32 / 255.0);
    if push.sources & PRESENT_HOST_BGRA != 0 {
        [t[2], t[1], t[0], t[3]]
    } else {
        t
    }
}

/// One pixel: the mean of its sources, over the background (or, where the push says so, over the
/// host's texel `host`, `host_texel`), clamped, linear if asked (the premultiplied colour
/// un-premultiplied, decoded and premultiplied again).
pub fn present_pixel(push: &PresentPush, accum: [f32; 4], color: [f32; 4], host: [f32; 4]) -> [f32; 4] {
    let (mut sum, mut n) = ([0.0f32; 4], 0.0f32);
    for (bit, v) in [(1, accum), (2, color)] {
        if push.sources & bit != 0 {
            sum = [0, 1, 2, 3].map(|c| sum[c] + v[c]);
            n += 1.0;
        }
    }
    let bg = if push.sources & PRESENT_OVER != 0 { host } else { push.background };
    let c = [0, 1, 2, 3].map(|i| sum[i] / n.max(1.0));
    let mut c = [0, 1, 2, 3].map(|i| (c[i] + (1.0 - c[3]) * bg[i]).clamp(0.0, 1.0));
    if push.linear != 0 && c[3] > 0.0 {
        let a = c[3];
        for v in &mut c[..3] {
            *v = to_linear((*v / a).min(1.0)) * a;
        }
    }
    c
}

/// Mirror of `present.comp`: the presented frame, written into `accum` (over the host's image
/// `host`, its texels as stored, where the push says so).
pub fn present(push: &PresentPush, accum: &mut ImageF32, color: &ImageF32, host: &[u32]) {
    let blank = [0.0f32; 4];
    for (i, px) in accum.pixels.iter_mut().enumerate() {
        let under = if push.sources & PRESENT_OVER != 0 { host_texel(push, host, i) } else { blank };
        *px = present_pixel(push, *px, color.pixels.get(i).copied().unwrap_or(blank), under);
    }
}

/// The stage table's entry point.
pub(crate) fn stage(b: &mut Bindings<'_>, args: &Args, _: &Variant) -> Result<()> {
    let push = args.push_as::<PresentPush>();
    if push.sources & 1 == 0 {
        // The accumulation image is written whole: start it from nothing, as the device does.
        b.accum = ImageF32::new(b.width, b.height);
    }
    let pixels = b.width as usize * b.height as usize;
    let host: Vec<u32> = if push.sources & PRESENT_OVER != 0 {
        let host: &[u32] = b.get(Res::HostColor);
        let needed = if push.sources & PRESENT_HOST_HALF != 0 { 2 * pixels } else { pixels };
        if host.len() < needed {
            return Err(Error::InvalidArgument(format!(
                "present: the host's image holds {} of {needed} words",
                host.len()
            )));
        }
        host[..needed].to_vec()
    } else {
        Vec::new()
    };
    present(&push, &mut b.accum, &b.color, &host);
    Ok(())
}

/// An IEEE half's bits, rounded to nearest even (values here are finite, in [0, 1]).
fn f16_bits(x: f32) -> u16 {
    let bits = x.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exp = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    let mant = bits & 0x7f_ffff;
    if exp >= 31 {
        return sign | 0x7c00;
    }
    if exp <= 0 {
        if exp < -10 {
            return sign;
        }
        let m = mant | 0x80_0000;
        let shift = (14 - exp) as u32;
        let (half, rest) = (m >> shift, m & ((1 << shift) - 1));
        let mid = 1 << (shift - 1);
        let up = rest > mid || (rest == mid && half & 1 == 1);
        return sign | (half + up as u32) as u16;
    }
    let (half, rest) = (((exp as u32) << 10) | (mant >> 13), mant & 0x1fff);
    let up = rest > 0x1000 || (rest == 0x1000 && half & 1 == 1);
    sign | (half + up as u32) as u16
}

/// A half's value.
pub fn f16_value(h: u16) -> f32 {
    let (sign, exp, mant) = (if h & 0x8000 != 0 { -1.0 } else { 1.0 }, ((h >> 10) & 0x1f) as i32, (h & 0x3ff) as f32);
    sign * match exp {
        0 => mant * (2.0f32).powi(-24),
        31 => f32::INFINITY,
        e => (1.0 + mant / 1024.0) * (2.0f32).powi(e - 15),
    }
}

/// Mirror of the blit: the texels a target of `format` holds for presented (`present`) pixels.
pub fn encode(format: TargetFormat, pixels: &[[f32; 4]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(pixels.len() * format.texel_bytes());
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    for p in pixels {
        if format == TargetFormat::Rgba16Float {
            for v in p {
                out.extend_from_slice(&f16_bits(*v).to_le_bytes());
            }
            continue;
        }
        let rgb = if format.srgb() { [0, 1, 2].map(|c| to_srgb(p[c])) } else { [p[0], p[1], p[2]] };
        let [r, g, b] = rgb.map(q);
        out.extend_from_slice(&if format.bgra() { [b, g, r, q(p[3])] } else { [r, g, b, q(p[3])] });
    }
    out
}

/// Texels of `format` back to RGBA values (sRGB decoded to what `present` wrote), for comparisons.
pub fn decode(format: TargetFormat, bytes: &[u8]) -> Result<Vec<[f32; 4]>> {
    let n = format.texel_bytes();
    if !bytes.len().is_multiple_of(n) {
        return Err(Error::InvalidArgument(format!("{} bytes are not whole {format:?} texels", bytes.len())));
    }
    Ok(bytes
        .chunks_exact(n)
        .map(|t| {
            if format == TargetFormat::Rgba16Float {
                return [0, 1, 2, 3].map(|c| f16_value(u16::from_le_bytes([t[2 * c], t[2 * c + 1]])));
            }
            let v = |b: u8| b as f32 / 255.0;
            let (r, g, b) = if format.bgra() { (t[2], t[1], t[0]) } else { (t[0], t[1], t[2]) };
            let rgb = [r, g, b].map(|c| if format.srgb() { to_linear(v(c)) } else { v(c) });
            [rgb[0], rgb[1], rgb[2], v(t[3])]
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{over_bits, present_push};

    #[test]
    fn halves_round_trip_and_round_to_nearest() {
        for x in [0.0f32, 1.0, 0.5, 0.25, 1.0 / 3.0, 0.0001, 0.999] {
            let h = f16_value(f16_bits(x));
            assert!((h - x).abs() <= x.abs() / 2048.0 + 1e-7, "{x} -> {h}");
        }
        assert_eq!(f16_bits(1.0), 0x3c00);
        assert_eq!(f16_bits(0.5), 0x3800);
    }

    #[test]
    fn srgb_curves_invert_each_other_and_keep_bytes() {
        for b in 0..=255u8 {
            let v = b as f32 / 255.0;
            let back = to_srgb(to_linear(v));
            assert!((back - v).abs() < 1e-5, "{b}: {back}");
        }
        // Display value 0.5 over an opaque pixel: linear 0.214, encoded by an sRGB target to 128.
        let push = present_push(None, 1, true, 1, 1);
        let p = present_pixel(&push, [0.5, 0.5, 0.5, 1.0], [0.0; 4], [0.0; 4]);
        assert!((p[0] - 0.21404).abs() < 1e-4);
        assert_eq!(encode(TargetFormat::Bgra8Srgb, &[p])[..3], [128, 128, 128]);
        assert_eq!(encode(TargetFormat::Rgba8Unorm, &[[0.5, 0.25, 1.0, 1.0]]), [128, 64, 255, 255]);
    }

    #[test]
    fn background_goes_under_and_sources_average() {
        let push = present_push(Some([0.0, 0.0, 1.0, 1.0]), 3, false, 1, 1);
        let p = present_pixel(&push, [0.5, 0.0, 0.0, 0.5], [0.3, 0.0, 0.0, 0.3], [0.0; 4]);
        // Mean (0.4, 0, 0, 0.4), then 0.6 of the blue background under it.
        let want = [0.4, 0.0, 0.6, 1.0];
        assert!(p.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6), "{p:?}");
    }

    #[test]
    fn over_the_host_image_in_the_targets_values() {
        // Half-covered grey over the host's red texel, in each layout the host's image may have.
        for format in TargetFormat::ALL {
            let red = encode(format, &[[1.0, 0.0, 0.0, 1.0]]);
            let words: Vec<u32> = red.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
            let mut push = present_push(None, 1, format.linear(), 1, 1);
            push.sources |= over_bits(format);
            let red = host_texel(&push, &words, 0);
            assert!(red.iter().zip([1.0, 0.0, 0.0, 1.0]).all(|(a, b)| (a - b).abs() < 1e-6), "{format:?}: {red:?}");
            let p = present_pixel(&push, [0.25, 0.25, 0.25, 0.5], [0.0; 4], red);
            // The frame's 0.5 display grey at alpha 0.5 over the red, as over a red background;
            // decoded for the targets that store linear values.
            let want = [0.75, 0.25, 0.25, 1.0].map(|v: f32| if format.linear() && v < 1.0 { to_linear(v) } else { v });
            let over_bg = present_pixel(
                &present_push(Some([1.0, 0.0, 0.0, 1.0]), 1, format.linear(), 1, 1),
                [0.25, 0.25, 0.25, 0.5],
                [0.0; 4],
                [0.0; 4],
            );
            assert_eq!(p, over_bg, "{format:?}: the host's image acts as a background");
            assert!(p.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6), "{format:?}: {p:?}");
        }
        // Without the bit the host's image is not read.
        let push = present_push(None, 1, false, 1, 1);
        assert_eq!(present_pixel(&push, [0.0; 4], [0.0; 4], [1.0; 4]), [0.0; 4]);
    }
}
