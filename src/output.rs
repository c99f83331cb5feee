//! Writing frames: RGBA8 PNG with straight (un-premultiplied) alpha, and RGBA32F EXR with
//! premultiplied alpha (EXR's own convention). Values are written as computed: no sRGB curve.
//!
//! ```,no_run
//! use voxsplat::{image::ImageF32, output::write_image};
//! // PNG (8-bit sRGB), EXR (linear float) or GIF, by the file's extension.
//! let frame = ImageF32::new(64, 64);
//! write_image(&frame, "frame.png".as_ref())?;
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::error::{Error, Result};
use crate::image::ImageF32;
use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::path::Path;

/// Straight-alpha RGBA8 pixels of a premultiplied float image.
pub fn to_rgba8(img: &ImageF32) -> Vec<u8> {
    let mut out = Vec::with_capacity(img.pixels.len() * 4);
    rgba8_into(&img.pixels, &mut out);
    out
}

/// `pixels` (premultiplied float) appended to `out` as straight-alpha RGBA8.
fn rgba8_into(pixels: &[[f32; 4]], out: &mut Vec<u8>) {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    for p in pixels {
        let a = p[3].clamp(0.0, 1.0);
        let s = if a > 0.0 { 1.0 / a } else { 0.0 };
        out.extend_from_slice(&[q(p[0] * s), q(p[1] * s), q(p[2] * s), q(a)]);
    }
}

/// A PNG (RGBA8, straight alpha) written in bands of rows as they come, so a large frame is never
/// held whole: `Renderer::render_bands` hands its bands to `push`; `finish` checks that every row
/// came and that the last flush succeeded.
pub struct PngRows {
    path: std::path::PathBuf,
    writer: png::StreamWriter<'static, SharedWriter>,
    file: std::sync::Arc<std::sync::Mutex<BufWriter<File>>>,
    rows_left: u32,
    width: u32,
    row: Vec<u8>,
}

impl PngRows {
    /// Create `path` for a `width` x `height` PNG.
    pub fn create(path: &Path, width: u32, height: u32) -> Result<Self> {
        let name = path.display().to_string();
        let file = File::create(path).map_err(|source| Error::Io { path: name.clone(), source })?;
        let file = std::sync::Arc::new(std::sync::Mutex::new(BufWriter::new(file)));
        let mut encoder = png::Encoder::new(SharedWriter(file.clone()), width, height);
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        let encoding = |e: png::EncodingError| Error::Image { path: name.clone(), message: e.to_string() };
        let writer = encoder.write_header().map_err(encoding)?.into_stream_writer().map_err(encoding)?;
        let row = Vec::with_capacity(width as usize * 4);
        Ok(Self { path: path.to_path_buf(), writer, file, rows_left: height, width, row })
    }

    /// Append `band`'s rows (as wide as the image).
    pub fn push(&mut self, band: &ImageF32) -> Result<()> {
        if band.width != self.width || band.height > self.rows_left {
            return Err(Error::InvalidArgument(format!(
                "a {}x{} band does not fit the {} rows left of a PNG {} wide",
                band.width, band.height, self.rows_left, self.width
            )));
        }
        let name = self.path.display().to_string();
        for line in band.pixels.chunks_exact(self.width as usize) {
            self.row.clear();
            rgba8_into(line, &mut self.row);
            std::io::Write::write_all(&mut self.writer, &self.row)
                .map_err(|source| Error::Io { path: name.clone(), source })?;
        }
        self.rows_left -= band.height;
        Ok(())
    }

    /// Write the trailer and flush the file.
    pub fn finish(self) -> Result<()> {
        let name = self.path.display().to_string();
        if self.rows_left > 0 {
            return Err(Error::InvalidArgument(format!("{name}: {} rows were never written", self.rows_left)));
        }
        let encoding = |e: png::EncodingError| Error::Image { path: name.clone(), message: e.to_string() };
        self.writer.finish().map_err(encoding)?;
        let io = |source| Error::Io { path: name.clone(), source };
        self.file.lock().map_err(|_| io(std::io::Error::other("PNG writer poisoned")))?.flush().map_err(io)
    }
}

/// The formats `write_image` writes, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// RGBA8, straight alpha.
    Png,
    /// RGBA32F, premultiplied alpha.
    Exr,
}

impl ImageFormat {
    /// The format `path`'s extension names, or a typed error: callers check `--out` before
    /// rendering, not after.
    pub fn of(path: &Path) -> Result<Self> {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("png") => Ok(ImageFormat::Png),
            Some("exr") => Ok(ImageFormat::Exr),
            _ => Err(Error::InvalidArgument(format!("output '{}' must end in .png or .exr", path.display()))),
        }
    }
}

/// Create `path` and write it through a buffer whose last flush is checked: a full disk or a
/// closed pipe is an error, not a short file and a success.
fn write_file(path: &Path, write: impl FnOnce(&mut BufWriter<File>) -> Result<()>) -> Result<()> {
    let name = path.display().to_string();
    let io = |source| Error::Io { path: name.clone(), source };
    let mut w = BufWriter::new(File::create(path).map_err(io)?);
    write(&mut w)?;
    w.flush().map_err(io)
}

/// Write `img` as PNG or EXR, chosen by the extension.
///
/// ```no_run
/// use voxsplat::{output::write_image, image::ImageF32};
/// let frame = ImageF32::new(64, 64);
/// write_image(&frame, "frame.png".as_ref())?; // 8-bit sRGB
/// write_image(&frame, "frame.exr".as_ref())?; // linear float
/// # Ok::<(), voxsplat::Error>(())
/// ```
pub fn write_image(img: &ImageF32, path: &Path) -> Result<()> {
    let format = ImageFormat::of(path)?;
    let encoding = |message: String| Error::Image { path: path.display().to_string(), message };
    match format {
        ImageFormat::Png => {
            // Row by row: an 8-bit copy of a large frame would add a quarter of its size.
            let mut png = PngRows::create(path, img.width, img.height)?;
            png.push(img)?;
            png.finish()
        }
        ImageFormat::Exr => write_file(path, |w| {
            use exr::prelude::WritableImage as _;
            let width = img.width as usize;
            let channels =
                exr::prelude::SpecificChannels::rgba(|exr::prelude::Vec2(x, y): exr::prelude::Vec2<usize>| {
                    let p = img.pixels[y * width + x];
                    (p[0], p[1], p[2], p[3])
                });
            exr::prelude::Image::from_channels((width, img.height as usize), channels)
                .write()
                .to_buffered(w)
                .map_err(|e| encoding(e.to_string()))
        }),
    }
}

/// An animated GIF written frame by frame over a dark background (`delay_ms` per frame), so a
/// long animation holds one frame at a time; `finish` writes the trailer and checks the flush.
pub struct GifWriter {
    path: std::path::PathBuf,
    encoder: image::codecs::gif::GifEncoder<SharedWriter>,
    file: std::sync::Arc<std::sync::Mutex<BufWriter<File>>>,
    delay_ms: u32,
}

/// An encoder's handle on the file (GIF's, PNG's): the encoder writes its trailer when finished or
/// dropped, and the file is flushed after that, through the other handle, its error checked.
struct SharedWriter(std::sync::Arc<std::sync::Mutex<BufWriter<File>>>);

impl std::io::Write for SharedWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.lock().map_err(|_| std::io::Error::other("image writer poisoned"))?.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.lock().map_err(|_| std::io::Error::other("image writer poisoned"))?.flush()
    }
}

impl GifWriter {
    /// Create `path`.
    pub fn create(path: &Path, delay_ms: u32) -> Result<Self> {
        let name = path.display().to_string();
        let file = File::create(path).map_err(|source| Error::Io { path: name.clone(), source })?;
        let file = std::sync::Arc::new(std::sync::Mutex::new(BufWriter::new(file)));
        let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(SharedWriter(file.clone()), 10);
        encoder
            .set_repeat(image::codecs::gif::Repeat::Infinite)
            .map_err(|e| Error::Image { path: name, message: e.to_string() })?;
        Ok(Self { path: path.to_path_buf(), encoder, file, delay_ms })
    }

    /// Append a premultiplied frame.
    pub fn push(&mut self, f: &ImageF32) -> Result<()> {
        let bg = [0.12f32, 0.12, 0.16];
        let mut rgba = image::RgbaImage::new(f.width, f.height);
        for (px, p) in rgba.pixels_mut().zip(&f.pixels) {
            let a = p[3].clamp(0.0, 1.0);
            let c = |i: usize| ((p[i] + bg[i] * (1.0 - a)).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            *px = image::Rgba([c(0), c(1), c(2), 255]);
        }
        let frame = image::Frame::from_parts(rgba, 0, 0, image::Delay::from_numer_denom_ms(self.delay_ms, 1));
        self.encoder
            .encode_frame(frame)
            .map_err(|e| Error::Image { path: self.path.display().to_string(), message: e.to_string() })
    }

    /// Write the trailer and flush, checked.
    pub fn finish(self) -> Result<()> {
        let name = self.path.display().to_string();
        let io = |source| Error::Io { path: name.clone(), source };
        // The trailer is written when the encoder is dropped.
        drop(self.encoder);
        let mut w = self.file.lock().map_err(|_| io(std::io::Error::other("GIF writer poisoned")))?;
        w.flush().map_err(io)
    }
}

/// An animated GIF of premultiplied frames over a dark background, `delay_ms` per frame.
pub fn write_gif(frames: &[ImageF32], path: &Path, delay_ms: u32) -> Result<()> {
    let mut gif = GifWriter::create(path, delay_ms)?;
    for f in frames {
        gif.push(f)?;
    }
    gif.finish()
}

/// A PNG (or any format `image` guesses) as straight RGBA8, within `MAX_PIXELS` (a terrain's
/// colour image).
pub fn read_rgba8(path: &Path) -> Result<image::RgbaImage> {
    Ok(decode(path)?.to_rgba8())
}

/// An input image decoded by `image` (format guessed from its bytes) within `MAX_IMAGE_SIDE` a
/// side and `MAX_PIXELS` RGBA32F of memory.
fn decode(path: &Path) -> Result<image::DynamicImage> {
    let name = path.display().to_string();
    let mut reader = image::ImageReader::open(path)
        .map_err(|e| Error::Io { path: name.clone(), source: e })?
        .with_guessed_format()
        .map_err(|e| Error::Io { path: name.clone(), source: e })?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(crate::camera::MAX_IMAGE_SIDE);
    limits.max_image_height = Some(crate::camera::MAX_IMAGE_SIDE);
    limits.max_alloc = Some(crate::camera::MAX_PIXELS * 16);
    reader.limits(limits);
    reader.decode().map_err(|e| Error::ImageRead { path: name, message: crate::error::clip_message(e) })
}

/// Read a PNG (straight alpha, 8 or 16 bit) or an EXR (premultiplied) as a premultiplied float
/// image. Sizes are checked against `MAX_PIXELS` from the header before any pixel is decoded.
pub fn read_image(path: &Path) -> Result<ImageF32> {
    use crate::camera::MAX_PIXELS;
    let name = path.display().to_string();
    let bad = |message: String| Error::ImageRead { path: name.clone(), message: crate::error::clip_message(message) };
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("png") => {
            // The decoded image (up to 8 bytes a pixel) and its floats, within the host budget.
            let (w, h) = image::image_dimensions(path).map_err(|e| bad(e.to_string()))?;
            crate::error::check_host_memory(w as u64 * h as u64 * 24, &format!("reading {name} ({w}x{h})"))?;
            let img = decode(path)?;
            let (width, height) = (img.width(), img.height());
            let premultiplied = |p: [f32; 4]| [p[0] * p[3], p[1] * p[3], p[2] * p[3], p[3]];
            // Straight to premultiplied floats, without a whole RGBA32F copy in between.
            let pixels = match &img {
                image::DynamicImage::ImageRgba8(b) => {
                    b.pixels().map(|p| premultiplied(p.0.map(|v| v as f32 / 255.0))).collect()
                }
                image::DynamicImage::ImageRgba16(b) => {
                    b.pixels().map(|p| premultiplied(p.0.map(|v| v as f32 / 65535.0))).collect()
                }
                other => other.to_rgba32f().pixels().map(|p| premultiplied(p.0)).collect(),
            };
            Ok(ImageF32 { width, height, pixels })
        }
        Some("exr") => {
            let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| bad(e.to_string()))?;
            let header = meta.headers.first().ok_or_else(|| bad("no layer".into()))?;
            let size = header.layer_size;
            if size.0 as u64 * size.1 as u64 > MAX_PIXELS {
                return Err(bad(format!("{}x{} exceeds the pixel limit", size.0, size.1)));
            }
            crate::error::check_host_memory(
                size.0 as u64 * size.1 as u64 * 16,
                &format!("reading {name} ({}x{})", size.0, size.1),
            )?;
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
