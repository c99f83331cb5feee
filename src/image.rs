//! The output image, and the formats of a host's image it can be drawn into.
//!
//! ```
//! use voxsplat::image::{downsample, Downsample, ImageF32};
//! // Frames are linear, premultiplied RGBA in f32; a 2 x 2 box filter halves one.
//! let mut img = ImageF32::new(4, 4);
//! img.pixels[0] = [1.0, 0.0, 0.0, 1.0];
//! let half = downsample(&img, 2, Downsample::Box);
//! assert_eq!((half.width, half.pixels[0][3]), (2, 0.25));
//!
//! ```

/// An RGBA32F image, row 0 at the top. Colour is premultiplied by alpha.
///
/// ```
/// use voxsplat::image::ImageF32;
/// // Premultiplied RGBA per pixel, row by row.
/// let mut image = ImageF32::new(4, 2);
/// image.pixels[0] = [0.5, 0.0, 0.0, 0.5];
/// assert_eq!(image.pixels.len(), 8);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ImageF32 {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// Row-major premultiplied RGBA.
    pub pixels: Vec<[f32; 4]>,
}

impl ImageF32 {
    /// A transparent image.
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![[0.0; 4]; width as usize * height as usize] }
    }
}

/// The formats `Renderer::render_to` writes: the usual swapchain ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TargetFormat {
    /// `B8G8R8A8_SRGB`: the device encodes; voxsplat writes linear values.
    Bgra8Srgb,
    /// `B8G8R8A8_UNORM`: the frame's values as a PNG of it holds them.
    Bgra8Unorm,
    /// `R8G8B8A8_SRGB`.
    Rgba8Srgb,
    /// `R8G8B8A8_UNORM`.
    Rgba8Unorm,
    /// `R16G16B16A16_SFLOAT`: linear values (an extended-sRGB-linear swapchain, or a host texture).
    Rgba16Float,
}

impl TargetFormat {
    /// Every format, for tests and listings.
    pub const ALL: [TargetFormat; 5] = [
        TargetFormat::Bgra8Srgb,
        TargetFormat::Bgra8Unorm,
        TargetFormat::Rgba8Srgb,
        TargetFormat::Rgba8Unorm,
        TargetFormat::Rgba16Float,
    ];

    /// Whether the target wants linear values: it encodes them itself (sRGB) or stores them (float).
    pub fn linear(self) -> bool {
        !matches!(self, TargetFormat::Bgra8Unorm | TargetFormat::Rgba8Unorm)
    }

    /// Bytes per texel.
    pub fn texel_bytes(self) -> usize {
        if self == TargetFormat::Rgba16Float {
            8
        } else {
            4
        }
    }

    pub(crate) fn bgra(self) -> bool {
        matches!(self, TargetFormat::Bgra8Srgb | TargetFormat::Bgra8Unorm)
    }

    pub(crate) fn srgb(self) -> bool {
        matches!(self, TargetFormat::Bgra8Srgb | TargetFormat::Rgba8Srgb)
    }
}

/// How a supersampled reference is brought down to the camera's pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Downsample {
    /// The mean of each pixel's samples: lets through much of what lies above the pixels' Nyquist
    /// frequency.
    #[default]
    Box,
    /// A Lanczos-3 low-pass at the pixels' Nyquist frequency (windowed sinc, three pixels each
    /// side, weights normalised where the image ends): the reconstruction filter anti-aliasing is
    /// measured against.
    Lanczos3,
}

/// `img` brought down `f`× along each axis by `filter`, separably (rows, then columns).
pub fn downsample(img: &ImageF32, f: usize, filter: Downsample) -> ImageF32 {
    let (w, h) = (img.width as usize / f, img.height as usize / f);
    let big_w = img.width as usize;
    // Per output index, its (sample index, weight) taps along one axis of n samples.
    let taps = |n: usize, out: usize| -> Vec<Vec<(usize, f32)>> {
        (0..out)
            .map(|x| match filter {
                Downsample::Box => (x * f..x * f + f).map(|i| (i, 1.0 / f as f32)).collect(),
                Downsample::Lanczos3 => {
                    let c = (x as f64 + 0.5) * f as f64;
                    let lo = (c - 3.0 * f as f64).floor().max(0.0) as usize;
                    let hi = ((c + 3.0 * f as f64).ceil() as usize).min(n);
                    let t: Vec<(usize, f64)> =
                        (lo..hi).map(|i| (i, lanczos3((i as f64 + 0.5 - c) / f as f64))).collect();
                    let sum: f64 = t.iter().map(|p| p.1).sum();
                    t.into_iter().map(|(i, wt)| (i, (wt / sum) as f32)).collect()
                }
            })
            .collect()
    };
    let (tx, ty) = (taps(big_w, w), taps(img.height as usize, h));
    let mut rows = vec![[0.0f32; 4]; w * img.height as usize];
    for y in 0..img.height as usize {
        for (x, t) in tx.iter().enumerate() {
            let mut acc = [0.0f32; 4];
            for &(i, wt) in t {
                let p = img.pixels[y * big_w + i];
                (0..4).for_each(|c| acc[c] += wt * p[c]);
            }
            rows[y * w + x] = acc;
        }
    }
    let mut out = ImageF32::new(w as u32, h as u32);
    for (y, t) in ty.iter().enumerate() {
        for x in 0..w {
            let mut acc = [0.0f32; 4];
            for &(j, wt) in t {
                let p = rows[j * w + x];
                (0..4).for_each(|c| acc[c] += wt * p[c]);
            }
            out.pixels[y * w + x] = acc;
        }
    }
    out
}

/// The Lanczos-3 kernel: sinc(x) sinc(x / 3) for |x| < 3.
fn lanczos3(x: f64) -> f64 {
    if x.abs() >= 3.0 {
        return 0.0;
    }
    if x.abs() < 1e-9 {
        return 1.0;
    }
    let px = std::f64::consts::PI * x;
    3.0 * px.sin() * (px / 3.0).sin() / (px * px)
}
