//! Writing frames: RGBA8 PNG with straight (un-premultiplied) alpha, and RGBA32F EXR with
//! premultiplied alpha (EXR's own convention). Values are written as computed: no sRGB curve.
use crate::error::{Error, Result};
use crate::image::ImageF32;
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

/// An animated GIF of premultiplied frames over a dark background, `delay_ms` per frame.
pub fn write_gif(frames: &[ImageF32], path: &Path, delay_ms: u32) -> Result<()> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let name = path.display().to_string();
    let file = std::fs::File::create(path).map_err(|e| Error::Io { path: name.clone(), source: e })?;
    let mut enc = GifEncoder::new_with_speed(std::io::BufWriter::new(file), 10);
    enc.set_repeat(Repeat::Infinite).map_err(|e| Error::Image { path: name.clone(), message: e.to_string() })?;
    let bg = [0.12f32, 0.12, 0.16];
    for f in frames {
        let mut rgba = image::RgbaImage::new(f.width, f.height);
        for (px, p) in rgba.pixels_mut().zip(&f.pixels) {
            let a = p[3].clamp(0.0, 1.0);
            let c = |i: usize| ((p[i] + bg[i] * (1.0 - a)).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            *px = image::Rgba([c(0), c(1), c(2), 255]);
        }
        let frame = image::Frame::from_parts(rgba, 0, 0, image::Delay::from_numer_denom_ms(delay_ms, 1));
        enc.encode_frame(frame).map_err(|e| Error::Image { path: name.clone(), message: e.to_string() })?;
    }
    Ok(())
}

/// Read a PNG (straight alpha, 8 or 16 bit) or an EXR (premultiplied) as a premultiplied float
/// image. Sizes are checked against `MAX_PIXELS` from the header before any pixel is decoded.
pub fn read_image(path: &Path) -> Result<ImageF32> {
    use crate::camera::MAX_PIXELS;
    let name = path.display().to_string();
    let bad = |message: String| Error::Image { path: name.clone(), message };
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("png") => {
            let mut reader = image::ImageReader::open(path)
                .map_err(|e| Error::Io { path: name.clone(), source: e })?
                .with_guessed_format()
                .map_err(|e| Error::Io { path: name.clone(), source: e })?;
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(crate::camera::MAX_IMAGE_SIDE);
            limits.max_image_height = Some(crate::camera::MAX_IMAGE_SIDE);
            limits.max_alloc = Some(MAX_PIXELS * 16);
            reader.limits(limits);
            let img = reader.decode().map_err(|e| bad(e.to_string()))?.to_rgba32f();
            let (width, height) = img.dimensions();
            let pixels = img.pixels().map(|p| [p[0] * p[3], p[1] * p[3], p[2] * p[3], p[3]]).collect();
            Ok(ImageF32 { width, height, pixels })
        }
        Some("exr") => {
            let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| bad(e.to_string()))?;
            let header = meta.headers.first().ok_or_else(|| bad("no layer".into()))?;
            let size = header.layer_size;
            if size.0 as u64 * size.1 as u64 > MAX_PIXELS {
                return Err(bad(format!("{}x{} exceeds the pixel limit", size.0, size.1)));
            }
            let image = exr::prelude::read_first_rgba_layer_from_file(
                path,
                |res, _| ImageF32::new(res.width() as u32, res.height() as u32),
                |img: &mut ImageF32, pos, (r, g, b, a): (f32, f32, f32, f32)| {
                    let w = img.width as usize;
                    img.pixels[pos.y() * w + pos.x()] = [r, g, b, a];
                },
            )
            .map_err(|e| bad(e.to_string()))?;
            Ok(image.layer_data.channel_data.pixels)
        }
        _ => Err(Error::InvalidArgument(format!("'{name}' must end in .png or .exr"))),
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
