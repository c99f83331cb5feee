//! The output image.

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
