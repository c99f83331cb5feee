//! The host's depth buffer (`RenderOptions::depth`): what the host's opaque geometry hides.
use crate::error::{Error, Result};

/// How a depth buffer stores a pixel's depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthFormat {
    /// `D32_SFLOAT`: one f32 per pixel.
    D32,
    /// `D24_UNORM_S8_UINT`'s depth aspect as a copy gives it: the depth in the low 24 bits of a
    /// 32-bit word, unsigned normalised.
    D24S8,
}

impl DepthFormat {
    /// The code `host_depth.comp` reads (`DepthPush::format`).
    pub fn code(self) -> u32 {
        match self {
            DepthFormat::D32 => 0,
            DepthFormat::D24S8 => 1,
        }
    }
}

/// A host's depth buffer of the frame's size: its raw texels (row 0 at the top, as the frame's)
/// and the projection the host drew them with. The host's eye space must be the camera's view
/// (right-handed, looking down -z: `Camera::view`); its projection may differ from the camera's
/// (near and far planes, reversed depth). Splats whose centre lies behind the host's geometry at
/// a pixel add nothing there, so meshes and the volume intermix; per-splat compositing only (the
/// sheet and slab modes refuse it).
#[derive(Clone, Debug, PartialEq)]
pub struct DepthBuffer {
    /// Pixels across.
    pub width: u32,
    /// Pixels down.
    pub height: u32,
    /// How each texel stores its depth.
    pub format: DepthFormat,
    /// One word per pixel, row by row from the top.
    pub texels: Vec<u32>,
    /// The host's projection: its eye space to its clip space (Vulkan's: y down, depth 0 to 1,
    /// or 1 to 0 reversed).
    pub projection: glam::Mat4,
}

impl DepthBuffer {
    /// Refuse a buffer no frame of `width` x `height` can use: another size, a texel count that
    /// is not width x height, a projection that is not finite or not invertible.
    pub fn check(&self, width: u32, height: u32) -> Result<()> {
        if (self.width, self.height) != (width, height) {
            return Err(Error::InvalidArgument(format!(
                "a {} x {} depth buffer for a {width} x {height} frame: they must match",
                self.width, self.height
            )));
        }
        if self.texels.len() as u64 != width as u64 * height as u64 {
            return Err(Error::InvalidArgument(format!(
                "a {width} x {height} depth buffer of {} texels",
                self.texels.len()
            )));
        }
        let det = self.projection.determinant();
        if !(self.projection.is_finite() && det.is_finite() && det != 0.0) {
            return Err(Error::InvalidArgument("the depth buffer's projection must be finite and invertible".into()));
        }
        Ok(())
    }
}
