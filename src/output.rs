//! Writing frames: RGBA8 PNG with straight (un-premultiplied) alpha, and RGBA32F EXR with
//! premultiplied alpha (EXR's own convention). Values are written as computed: no sRGB curve.
use crate::cpu::ImageF32;
use crate::error::{Error, Result};
use std::path::Path;

/// Straight-alpha RGBA8 pixels of a premultiplied float image.
pub fn to_rgba8(img: &ImageF32) -> Vec<u8> {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    let mut out = Vec::with_capacity(img.pixels.len() * 4);
    for p in &img.pixels {
        let a = p[3].clamp(0.0, 1.0);
        let s = if a > 0.0 { 1.0 / a } else { 0.0 };
        out.extend_from_slice(&[q(p[0] * s), q(p[1] * s), q(p[2] * s), q(a)]);
    }
    out
}

/// Write `img` as PNG or EXR, chosen by the extension.
pub fn write_image(img: &ImageF32, path: &Path) -> Result<()> {
    let name = path.display().to_string();
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("png") => image::save_buffer(path, &to_rgba8(img), img.width, img.height, image::ExtendedColorType::Rgba8)
            .map_err(|e| Error::Image { path: name, message: e.to_string() }),
        Some("exr") => {
            let w = img.width as usize;
            exr::prelude::write_rgba_file(path, w, img.height as usize, |x, y| {
                let p = img.pixels[y * w + x];
                (p[0], p[1], p[2], p[3])
            })
            .map_err(|e| Error::Image { path: name, message: e.to_string() })
        }
        _ => Err(Error::InvalidArgument(format!("output '{name}' must end in .png or .exr"))),
    }
}

/// Premultiplied RGBA8 pixels (what a compositor would blend).
pub fn to_premultiplied_rgba8(img: &ImageF32) -> Vec<u8> {
    img.pixels.iter().flat_map(|p| p.map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)).collect()
}

/// Mean and max absolute difference per channel between two images' 8-bit premultiplied
/// encodings, in units of 1/255. (Straight alpha would amplify noise in nearly transparent pixels.)
pub fn diff_rgba8(a: &ImageF32, b: &ImageF32) -> Result<(f64, u8)> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(Error::InvalidArgument("images differ in size".into()));
    }
    let (x, y) = (to_premultiplied_rgba8(a), to_premultiplied_rgba8(b));
    let mut sum = 0u64;
    let mut max = 0u8;
    for (p, q) in x.iter().zip(&y) {
        let d = p.abs_diff(*q);
        sum += d as u64;
        max = max.max(d);
    }
    Ok((sum as f64 / x.len().max(1) as f64, max))
}
