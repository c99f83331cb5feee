//! The output image, and the formats of a host's image it can be drawn into.

/// An RGBA32F image, row 0 at the top. Colour is premultiplied by alpha.
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
