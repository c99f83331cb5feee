//! A rendered frame: its image, each stage's time, and what it drew (`Rendered::stats`).

use super::RasterChoice;
use crate::image::ImageF32;

/// A rendered frame: premultiplied RGBA32F, row 0 at the top.
///
/// ```
/// use voxsplat::{scene, Backend, Camera, RenderOptions, Renderer, RendererOptions};
/// let mut o = RendererOptions::default();
/// o.backend = Backend::Cpu;
/// let mut r = Renderer::new(&o)?;
/// let set = scene::build("cube40")?;
/// let camera = Camera::framing(set.grid(), 64, 48);
/// r.set_scene(set)?;
/// let frame = r.render(&camera, &RenderOptions::default())?;
/// assert_eq!((frame.image.width, frame.image.height), (64, 48));
/// let ms: f64 = frame.timings.iter().map(|t| t.ms).sum(); // each stage's time
/// # let _ = ms;
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The frame.
    pub image: ImageF32,
    /// Per-stage times, in the order the stages ran.
    pub timings: Vec<StageTime>,
    /// The footprint stage's raster variant and why (`None` for the ray caster and the truth).
    pub raster: Option<RasterChoice>,
    /// What the frame drew and culled (a bricked volume's; zero elsewhere).
    pub stats: FrameStats,
}

/// One named stage's time in milliseconds (GPU timestamps, or wall time on the CPU path).
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    /// The stage's name (`order`, `splat_params`, `footprint`, ...).
    pub stage: &'static str,
    /// Milliseconds.
    pub ms: f64,
}

/// Add `ms` to the stage named `stage` (first-seen order).
pub fn add_time(timings: &mut Vec<StageTime>, stage: &'static str, ms: f64) {
    match timings.iter_mut().find(|t| t.stage == stage) {
        Some(t) => t.ms += ms,
        None => timings.push(StageTime { stage, ms }),
    }
}

/// What a frame drew and what it left out, and why (`Rendered::stats`): a bricked volume's bricks and
/// splats, an isosurface's discs, a label volume's unlabelled voxels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameStats {
    /// Non-empty bricks in the store.
    pub bricks: u32,
    /// Bricks left after culling those outside the view or empty under the transfer function.
    pub bricks_visible: u32,
    /// Visible bricks the level-of-detail cut drew coarser than their voxels.
    pub bricks_coarse: u32,
    /// Of those, nodes above the brick: one cell drawn for 2^k bricks a side, listed at the first
    /// of its bricks that draws (the others are not counted as visible).
    pub nodes: u32,
    /// Visible bricks dropped because what earlier waves drew already hides them.
    pub bricks_hidden: u32,
    /// Splats drawn: voxels and coarse cells; in `Mode::Iso`, the surface's discs (0: the value
    /// crosses no cell, and the frame is empty).
    pub splats: u64,
    /// MIP and MinIP: voxels not drawn because a brighter one's centre falls in the same texel (a
    /// third of a pixel a side), so that it adds next to nothing.
    pub splats_outshone: u64,
    /// Batches (waves) the visible bricks were drawn in, front to back.
    pub waves: u32,
    /// Bytes of brick records uploaded: a streamed store's bricks its record cache lacked.
    pub bytes_uploaded: u64,
    /// Bytes of brick records its record cache holds after the frame (whole-brick slots).
    pub records_resident: u64,
    /// A label volume's voxels drawn hidden because the label table lacks their label
    /// (`labels::classify_labels`).
    pub unlabelled: u64,
}

impl FrameStats {
    /// Field by field, the larger of the two: a frame drawn in bands (`frame_bands`) reports its
    /// busiest band's counts, since a brick or splat two bands draw would be counted twice.
    pub fn busiest(&self, o: &Self) -> Self {
        Self {
            bricks: self.bricks.max(o.bricks),
            bricks_visible: self.bricks_visible.max(o.bricks_visible),
            bricks_coarse: self.bricks_coarse.max(o.bricks_coarse),
            nodes: self.nodes.max(o.nodes),
            bricks_hidden: self.bricks_hidden.max(o.bricks_hidden),
            splats: self.splats.max(o.splats),
            splats_outshone: self.splats_outshone.max(o.splats_outshone),
            waves: self.waves.max(o.waves),
            bytes_uploaded: self.bytes_uploaded.max(o.bytes_uploaded),
            records_resident: self.records_resident.max(o.records_resident),
            unlabelled: self.unlabelled.max(o.unlabelled),
        }
    }
}
