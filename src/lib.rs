//! voxsplat renders discrete objects (volume rasters) by splatting on Vulkan, following J. E. Swan's
//! 1997 dissertation: PBTF visibility order computed on the GPU without a sort, eye-facing
//! footprints drawn instanced, per-splat compositing or Westover's sheet summation buffer — and a
//! CPU mirror of every GPU stage that computes the same frame.
//!
//! ```no_run
//! use voxsplat::{scene, Camera, Renderer, RendererOptions, RenderOptions};
//! let set = scene::build("cube60")?;
//! let camera = Camera::framing(set.grid(), 512, 512);
//! let mut renderer = Renderer::new(&RendererOptions::default())?;
//! renderer.set_scene(set)?;
//! let frame = renderer.render(&camera, &RenderOptions::default())?;
//! voxsplat::output::write_image(&frame.image, "cube.png".as_ref())?;
//! # Ok::<(), voxsplat::Error>(())
//! ```
#![deny(unsafe_code)]
#![warn(missing_docs)]
// Some internals only the tests use (a mirror's helpers, the stage tables' lists): dead in the
// library's own build. The test build (`mod tests`), which clippy and CI check, still reports
// anything that nothing uses.
#![cfg_attr(not(test), allow(dead_code, unused_imports))]

#[cfg(feature = "lab")]
pub mod aa;
pub mod animate;
mod bands;
mod bisect;
pub mod bricks;
mod builds;
pub mod camera;
pub mod classify;
mod constants;
mod cpu;
mod cpu_engine;
pub mod device;
mod dispatch;
pub mod distributed;
#[doc = include_str!("../docs/guide/embedding.md")]
pub mod embedding {}
mod error;
mod gpu;
mod gpu_types;
pub mod image;
mod iso;
// The README's Rust example compiles (a doc test; cli/tests/readme.rs runs its commands).
#[cfg(all(doctest, feature = "io"))]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
mod kdtree;
pub mod kernel;
pub mod labels;
#[cfg(feature = "io")]
pub mod loaders;
pub mod low_level;
#[cfg(feature = "lab")]
pub mod metrics;
pub mod options;
pub mod order;
pub mod orient;
#[cfg(feature = "io")]
pub mod output;
mod pick;
mod plan;
mod raster;
mod recording;
mod resample;
mod residency;
pub mod scene;
mod series;
mod shaders;
mod stages;
#[cfg(feature = "io")]
pub mod terrain;
// The engine's tests (tests/main.rs, each file a module) are compiled into the library's test
// build, so that they use its internals from inside the crate rather than through a public door.
#[cfg(test)]
#[allow(unsafe_code)]
#[path = "../tests/main.rs"]
mod tests;
#[cfg(feature = "lab")]
pub mod truth;
#[allow(unsafe_code)]
pub mod vk;
pub mod volume;

// The facade: what an embedder names at the top. Everything else has one path, in its module
// (`options::Mode`, `order::Direction`, ...); tests/layout.rs counts these names (at most 40).
pub use camera::Camera;
pub use error::{Error, Result};
/// The vector and matrix types of the API (`Camera`'s eye, a clip plane, an affine).
///
/// ```
/// use voxsplat::glam::Vec3;
/// let mut camera = voxsplat::Camera::framing(&voxsplat::Grid::centered([8; 3], [1.0; 3])?, 64, 64);
/// camera.up = Vec3::Z;
/// # Ok::<(), voxsplat::Error>(())
/// ```
pub use glam;
pub use options::{RenderOptions, Rendered};
pub use pick::Pick;
pub use series::VolumeUpdate;
pub use volume::{Grid, SplatSet, Volume};

// Short paths inside the crate (and for its tests), not public.
use bisect::Bisect;
use camera::Projection;
use image::{ImageF32, TargetFormat};
use kernel::Kernel;
use options::{
    Antialias, BlurProfile, Clip, Composite, Delivered, DepthBuffer, DepthFormat, FrameStats, Lod, Mode, Motion,
    Raster, RasterChoice, RaycastOptions, StageTime,
};
use order::{Direction, OrderKind};

use cpu_engine::CpuEngine;
use plan::Prepared;
use recording::record_frame;
use stages::{Engine, Res, StageId};
use std::sync::Arc;

/// Where the frame is computed.
///
/// ```
/// use voxsplat::{Backend, Renderer, RendererOptions};
/// // The CPU mirrors: the same frame without a Vulkan device.
/// let mut o = RendererOptions::default();
/// o.backend = Backend::Cpu;
/// let r = Renderer::new(&o)?;
/// assert_eq!(r.backend(), Backend::Cpu);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Backend {
    /// Vulkan.
    #[default]
    Gpu,
    /// The CPU mirrors, stage by stage.
    Cpu,
}

/// How to create a [`Renderer`].
///
/// ```no_run
/// use voxsplat::{Renderer, RendererOptions};
/// // Validation on (its messages are counted, never printed), a device by name, 4 GiB for frames.
/// let mut options = RendererOptions::default();
/// options.validation = true;
/// options.device_name = Some("NVIDIA".into());
/// options.gpu_budget_bytes = Some(4 << 30);
/// let renderer = Renderer::new(&options)?;
/// assert_eq!(renderer.validation_count(), 0);
/// # Ok::<(), voxsplat::Error>(())
/// ```
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct RendererOptions {
    /// Vulkan or the CPU mirrors.
    pub backend: Backend,
    /// Khronos validation with synchronization validation; messages are counted, see
    /// [`Renderer::validation_messages`].
    pub validation: bool,
    /// Pick the Vulkan device whose name contains this text.
    pub device_name: Option<String>,
    /// Device memory a frame may hold, in bytes: a bricked volume's splats stream through it in
    /// batches ([`Renderer::set_volume`]). `None`: the device's default
    /// ([`device::DeviceChoices::default_budget`]: 1 GiB on a CPU device, half the largest
    /// device-local heap on a GPU).
    pub gpu_budget_bytes: Option<u64>,
}

impl Default for RendererOptions {
    fn default() -> Self {
        Self { backend: Backend::Gpu, validation: false, device_name: None, gpu_budget_bytes: None }
    }
}

/// A scene on a backend. `Send`: one renderer per thread.
///
/// ```
/// use voxsplat::{Backend, Camera, Grid, RenderOptions, Renderer, RendererOptions, SplatSet};
/// // A ball of orange voxels, drawn by the CPU mirrors (`Backend::Gpu`, the default, for Vulkan).
/// let grid = Grid::centered([16; 3], [1.0; 3])?;
/// let set = SplatSet::from_fn(grid, |i, j, k| {
///     let d = voxsplat::glam::Vec3::new(i as f32, j as f32, k as f32) - 7.5;
///     (d.length() < 6.0).then_some([1.0, 0.5, 0.1, 0.3])
/// })?;
/// let mut options = RendererOptions::default();
/// options.backend = Backend::Cpu;
/// let mut renderer = Renderer::new(&options)?;
/// let camera = Camera::framing(set.grid(), 64, 64);
/// renderer.set_scene(set)?;
/// let frame = renderer.render(&camera, &RenderOptions::default())?;
/// assert!(frame.image.pixels.iter().any(|p| p[3] > 0.0));
/// # Ok::<(), voxsplat::Error>(())
/// ```
pub struct Renderer {
    gpu: Option<gpu::Gpu>,
    scene: Option<Prepared>,
    bisect: Option<Bisect>,
    budget_bytes: u64,
}

impl Renderer {
    /// A renderer on its own Vulkan device (or the CPU mirrors).
    pub fn new(options: &RendererOptions) -> Result<Self> {
        let gpu = match options.backend {
            Backend::Gpu => {
                let ctx = vk::Context::new(&vk::ContextOptions {
                    validation: options.validation,
                    device_name: options.device_name.clone(),
                })?;
                Some(gpu::Gpu::new(ctx)?)
            }
            Backend::Cpu => None,
        };
        let mut renderer = Self { gpu, scene: None, bisect: None, budget_bytes: 0 };
        let device_default =
            renderer.gpu.as_ref().map_or(constants::DEFAULT_GPU_BUDGET, |g| g.context().choices().default_budget);
        renderer.set_gpu_budget(options.gpu_budget_bytes.unwrap_or(device_default))?;
        Ok(renderer)
    }

    /// Device memory a frame may hold, in bytes (see [`RendererOptions::gpu_budget_bytes`]); the
    /// CPU backend cuts the same batches.
    pub fn set_gpu_budget(&mut self, bytes: u64) -> Result<()> {
        if bytes == 0 {
            return Err(Error::InvalidArgument("a GPU budget of 0 bytes".into()));
        }
        if let Some(g) = &self.gpu {
            let most = g.context().choices().max_budget;
            if bytes > most {
                return Err(Error::InvalidArgument(format!(
                    "a GPU budget of {} MiB exceeds the device's {} MiB of device-local memory",
                    bytes >> 20,
                    most >> 20
                )));
            }
        }
        self.budget_bytes = bytes;
        if let Some(g) = &mut self.gpu {
            g.budget_bytes = bytes;
            // Whether a bricked store's records stay on the host follows the budget.
            if let Some(prep) = self.scene.as_ref().filter(|p| p.bricks.is_some()) {
                g.set_scene(prep)?;
            }
        }
        Ok(())
    }

    /// A renderer on a host program's Vulkan device (see [`vk::Context::from_host`]).
    pub fn with_context(ctx: Arc<vk::Context>) -> Result<Self> {
        let budget_bytes = ctx.choices().default_budget;
        Ok(Self { gpu: Some(gpu::Gpu::new(ctx)?), scene: None, bisect: None, budget_bytes })
    }

    /// The Vulkan device's name, or "cpu".
    pub fn device_name(&self) -> String {
        self.gpu.as_ref().map(|g| g.context().device_name().to_string()).unwrap_or_else(|| "cpu".into())
    }

    /// Where frames are computed.
    pub fn backend(&self) -> Backend {
        if self.gpu.is_some() {
            Backend::Gpu
        } else {
            Backend::Cpu
        }
    }

    /// Make `set` the scene (uploaded to the device on the GPU backend).
    pub fn set_scene(&mut self, set: SplatSet) -> Result<()> {
        self.install(Prepared::new(set))
    }

    /// Upload `prep` (GPU backend) and make it the scene.
    fn install(&mut self, prep: Prepared) -> Result<()> {
        if let Some(g) = &mut self.gpu {
            g.set_scene(&prep)?;
        }
        self.scene = Some(prep);
        Ok(())
    }

    /// Make a scalar volume the scene as a bricked store (`bricks`), classified with `tf` and
    /// `shading` on every frame: on the GPU backend the store is resident (or its records stream
    /// through the budget, `bricks::BrickScene::streams`) and culling,
    /// classification and the two-level PBTF order run on the device, so a volume of any size that
    /// fits host memory draws, streaming through the device budget when it must: per splat (PBTF),
    /// and in the sheet and slab modes. The other orders and the ray caster need
    /// [`Renderer::set_scene`] with a classified set. The host keeps no copy of `volume`. The grid
    /// is axis-aligned: a sheared file's store goes in through [`Renderer::set_bricks`] after
    /// `bricks::BrickStore::place`.
    pub fn set_volume(
        &mut self,
        volume: &volume::ScalarVolume,
        tf: &classify::TransferFunction,
        shading: Option<classify::Shading>,
    ) -> Result<()> {
        let store = bricks::BrickStore::build(volume)?;
        self.set_bricks(bricks::BrickScene::new(store, tf.clone(), shading)?)
    }

    /// Make a bricked volume the scene (see [`Renderer::set_volume`]).
    pub fn set_bricks(&mut self, scene: bricks::BrickScene) -> Result<()> {
        // The old scene goes first: a large store should not sit beside the new one.
        self.scene = None;
        self.install(Prepared::bricked(scene)?)
    }

    /// Classify the bricked volume with another transfer function and shading from the next
    /// frame on: a buffer write and the next frame's culling, no re-extraction or upload.
    pub fn set_transfer_function(
        &mut self,
        tf: &classify::TransferFunction,
        shading: Option<classify::Shading>,
    ) -> Result<()> {
        let scene = self.scene.as_mut().and_then(|p| p.bricks.as_mut()).ok_or_else(|| {
            Error::InvalidArgument("set_transfer_function needs a bricked volume (Renderer::set_volume)".into())
        })?;
        scene.set_transfer_function(tf.clone(), shading)
    }

    /// The bricked volume, if the scene is one.
    pub fn volume(&self) -> Option<&bricks::BrickScene> {
        self.scene.as_ref().and_then(|p| p.bricks.as_ref())
    }

    /// The scene, if one is set (a bricked volume's holds its grid and no splats).
    pub fn scene(&self) -> Option<&SplatSet> {
        self.scene.as_ref().map(|p| &p.set)
    }

    /// Split every frame between the device and the CPU mirrors at a stage (`None`: the backend
    /// runs it all), to find which stage departs from its mirror. Needs the GPU backend.
    pub fn set_bisect(&mut self, bisect: Option<Bisect>) -> Result<()> {
        if bisect.is_some() && self.gpu.is_none() {
            return Err(Error::InvalidArgument("bisecting needs the GPU backend".into()));
        }
        self.bisect = bisect;
        Ok(())
    }

    fn prepared(&self) -> Result<&Prepared> {
        Self::prepared_in(&self.scene)
    }

    /// The scene, from its field alone (so the GPU can be borrowed beside it).
    fn prepared_in(scene: &Option<Prepared>) -> Result<&Prepared> {
        scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))
    }

    /// Draw a frame (in bands past [`BAND_BYTES`](low_level::BAND_BYTES), put together: see `render_bands`).
    pub fn render(&mut self, camera: &Camera, options: &RenderOptions) -> Result<Rendered> {
        options.validate()?;
        camera.validate()?;
        bands::check_memory(camera, true)?;
        if options.render_scale != 1.0 {
            let full = RenderOptions { render_scale: 1.0, ..options.clone() };
            return resample::render_scaled(camera, options.render_scale, |low| self.render(low, &full));
        }
        let (opts, choice) = self.choose(camera, options)?;
        if bands::frame_bands(camera).len() > 1 {
            return bands::assemble(camera, |band| Ok(self.record(band, &opts)?.rendered(Some(choice.clone()))));
        }
        Ok(self.record(camera, &opts)?.rendered(Some(choice)))
    }

    /// Draw a frame in full-width bands of at most [`BAND_BYTES`](low_level::BAND_BYTES), top to bottom, handing
    /// each to `sink` with its first row: a frame of any size in the memory of one band. Each band
    /// is a window of the camera (`Camera::windowed`) drawn with the whole frame's projection and
    /// raster, so bands meet without seams; stats are the busiest band's. Under a render scale the
    /// coarse frame is drawn whole and resampled band by band.
    pub fn render_bands(
        &mut self,
        camera: &Camera,
        options: &RenderOptions,
        sink: &mut dyn FnMut(u32, &ImageF32) -> Result<()>,
    ) -> Result<Delivered> {
        options.validate()?;
        camera.validate()?;
        bands::check_memory(camera, false)?;
        if options.render_scale != 1.0 {
            // The coarse frame whole (a fraction of this one), resampled band by band.
            let full = RenderOptions { render_scale: 1.0, ..options.clone() };
            let low = resample::scaled_camera(camera, options.render_scale)?;
            let (_, raster) = self.choose(&low, &full)?;
            return bands::upsampled(camera, self.render(&low, &full)?, raster, sink);
        }
        let (opts, raster) = self.choose(camera, options)?;
        let (timings, stats) = bands::each(
            camera,
            |band| {
                let r = self.record(band, &opts)?;
                Ok((r.image, r.timings, r.stats))
            },
            sink,
        )?;
        Ok(Delivered { timings, raster, stats })
    }

    /// One frame (or band) recorded on the backend, or on a bisect split of it.
    fn record(&mut self, camera: &Camera, opts: &RenderOptions) -> Result<recording::Recorded> {
        let bisect = self.bisect;
        let prep = Self::prepared_in(&self.scene)?;
        let mut cpu = CpuEngine::new(prep).with_budget(self.budget_bytes);
        let mut recorded = match (&mut self.gpu, bisect) {
            (Some(g), None) => record_frame(&mut g.engine(prep), prep, camera, opts)?,
            (Some(g), Some(b)) => {
                let mut gpu = g.engine(prep);
                let mut split = match b {
                    Bisect::GpuUntil(at) => bisect::Split::new(&mut gpu, &mut cpu, at),
                    Bisect::CpuUntil(at) => bisect::Split::new(&mut cpu, &mut gpu, at),
                };
                record_frame(&mut split, prep, camera, opts)?
            }
            (None, _) => record_frame(&mut cpu, prep, camera, opts)?,
        };
        recorded.stats.unlabelled = prep.set.unlabelled();
        Ok(recorded)
    }

    /// The frame's plan: every decision `render` would make for this frame before it touches the
    /// device (the raster path, the order, the sheet batches, a bricked volume's budget split and
    /// levels of detail), for printing and testing. Under a render scale, the coarse frame's.
    pub fn plan(&mut self, camera: &Camera, options: &RenderOptions) -> Result<plan::FramePlan> {
        options.validate()?;
        camera.validate()?;
        let camera =
            if options.render_scale != 1.0 { resample::scaled_camera(camera, options.render_scale)? } else { *camera };
        let options = RenderOptions { render_scale: 1.0, ..options.clone() };
        let (opts, _) = self.choose(&camera, &options)?;
        let prep = Self::prepared_in(&self.scene)?;
        let limits = match &mut self.gpu {
            Some(g) => g.engine(prep).limits(),
            None => CpuEngine::new(prep).with_budget(self.budget_bytes).limits(),
        };
        plan::frame(prep, &camera, &opts, &limits)
    }

    /// Draw a frame into the host's image `target` on the device, with no readback: the frame
    /// waits on the target's wait semaphores before it writes the image, converts it to the image's
    /// format (over `options.background`, sRGB encoded where the format says so: the bytes a PNG
    /// of `render` holds), leaves it in the target's new layout and signals the target's signal
    /// semaphores. It returns when the frame is complete (docs/guide/embedding.md). A `render_scale`
    /// below 1 draws the coarser grid and stretches it in the blit (linear filter). A target with
    /// the host's depth image (`vk::HostTarget::with_depth`) hides the splats behind the host's
    /// geometry, per pixel.
    pub fn render_to(
        &mut self,
        camera: &Camera,
        options: &RenderOptions,
        target: &vk::HostTarget,
    ) -> Result<Delivered> {
        self.render_to_with(camera, options, target, None)
    }

    /// `render_to`, telling `progress` how far a long one-off build has got: a bricked volume's
    /// levels of detail, built on the first frame and after each change of its transfer function
    /// (`progress(done, of)` in bricks, each time after that much has run on the device; seconds
    /// on a CPU device for a large volume). A host with a window can present a frame with a
    /// progress bar from it; an error it returns stops the frame.
    pub fn render_to_with_progress(
        &mut self,
        camera: &Camera,
        options: &RenderOptions,
        target: &vk::HostTarget,
        progress: &mut dyn FnMut(u64, u64) -> Result<()>,
    ) -> Result<Delivered> {
        self.render_to_with(camera, options, target, Some(progress))
    }

    fn render_to_with(
        &mut self,
        camera: &Camera,
        options: &RenderOptions,
        target: &vk::HostTarget,
        progress: Option<&mut dyn FnMut(u64, u64) -> Result<()>>,
    ) -> Result<Delivered> {
        options.validate()?;
        camera.validate()?;
        plan::check_host_frame(target, camera, options)?;
        if self.bisect.is_some() {
            return Err(Error::Unsupported("render_to with a bisect split: use render()".into()));
        }
        let scaled = options.render_scale != 1.0;
        let low = resample::scaled_camera(camera, options.render_scale)?;
        let mut full = options.clone();
        full.render_scale = 1.0;
        let (opts, choice) = self.choose(&low, &full)?;
        let prep = Self::prepared_in(&self.scene)?;
        let gpu = self.gpu.as_mut().ok_or_else(|| Error::Unsupported("render_to needs the GPU backend".into()))?;
        gpu.context().check_target(target.format(), scaled)?;
        let mut engine = gpu.engine_to(prep, target);
        if let Some(p) = progress {
            engine = engine.with_progress(p);
        }
        let recorded = record_frame(&mut engine, prep, &low, &opts)?;
        Ok(Delivered { timings: recorded.timings, raster: choice, stats: recorded.stats })
    }

    /// The texels of a target after `render_to`, in its format (it needs `TRANSFER_SRC` usage).
    pub fn read_target(&self, target: &vk::HostTarget) -> Result<Vec<u8>> {
        self.device_context("reading a target")?.read_target(target)
    }

    /// An image on this renderer's device that `render_to` can draw into and `read_target` read.
    pub fn target_image(&self, format: TargetFormat, width: u32, height: u32) -> Result<vk::TargetImage> {
        vk::TargetImage::new(self.device_context("a target image")?, format, width, height)
    }

    /// A depth image on this renderer's device, cleared to `depth` (a plane facing the camera),
    /// that a target can read as the host's (`vk::DepthImage::attach`).
    pub fn depth_image(&self, format: DepthFormat, width: u32, height: u32, depth: f32) -> Result<vk::DepthImage> {
        vk::DepthImage::new(self.device_context("a depth image")?, format, (width, height), depth)
    }

    fn device_context(&self, what: &str) -> Result<&Arc<vk::Context>> {
        self.context().ok_or_else(|| Error::Unsupported(format!("{what} needs the GPU backend")))
    }

    /// The options with the raster variant `Raster::Auto` resolved for this device and view.
    fn choose(&self, camera: &Camera, options: &RenderOptions) -> Result<(RenderOptions, RasterChoice)> {
        let prep = self.prepared()?;
        let device = match &self.gpu {
            Some(g) => {
                gpu::resources::Resources::check_splat_cap(prep)?;
                raster::Device::of(g.context().choices())
            }
            None => raster::Device { cpu: true, point_size_max: f32::INFINITY, graphics: true },
        };
        let choice = raster::choose(&prep.set, camera, options, device)?;
        let mut opts = options.clone();
        opts.raster = choice.raster;
        Ok((opts, choice))
    }

    /// Run this frame's recording through stage `after` (the backend's engine) and read `what`
    /// back, whole: a probe for tests and the single-stage probes of `low_level`.
    fn probe(
        &mut self,
        camera: &Camera,
        options: &RenderOptions,
        after: StageId,
        what: &[Res],
    ) -> Result<Vec<Vec<u32>>> {
        options.validate()?;
        camera.validate()?;
        let (opts, _) = self.choose(camera, options)?;
        let prep = Self::prepared_in(&self.scene)?;
        let run = |e: &mut dyn Engine| -> Result<Vec<Vec<u32>>> {
            record_frame(&mut bisect::Stop::new(e, after), prep, camera, &opts)?;
            let what: Vec<_> = what.iter().map(|&r| (r, e.words(r))).collect();
            e.read(&what)
        };
        match &mut self.gpu {
            Some(g) => run(&mut g.engine(prep)),
            None => run(&mut CpuEngine::new(prep).with_budget(self.budget_bytes)),
        }
    }

    /// What pixel position (`x`, `y`) of `camera` shows (pixels from the top left corner; a
    /// pixel's centre at + 0.5): the first point along its ray where the accumulated opacity
    /// passes one half, in MIP and MinIP the point of the extreme value, or in `Mode::Iso`
    /// the ray's first crossing of the iso value (the ray caster's surface), with the voxel
    /// nearest it, its value and depth; `None` where the ray meets nothing. Computed on the host
    /// over the ray caster's trilinear field with `options`' mode and clipping, so it needs no
    /// frame; a bricked store is read where the ray passes, without a dense copy.
    ///
    /// ```
    /// use voxsplat::{scene, Backend, Camera, RenderOptions, Renderer, RendererOptions};
    /// let mut o = RendererOptions::default();
    /// o.backend = Backend::Cpu;
    /// let mut r = Renderer::new(&o)?;
    /// let set = scene::build("cube40")?;
    /// let camera = Camera::framing(set.grid(), 64, 64);
    /// r.set_scene(set)?;
    /// let hit = r.pick(&camera, &RenderOptions::default(), 32.0, 32.0)?.expect("the cube fills the centre");
    /// assert!(hit.depth > 0.0);
    /// # Ok::<(), voxsplat::Error>(())
    /// ```
    pub fn pick(&mut self, camera: &Camera, options: &RenderOptions, x: f32, y: f32) -> Result<Option<Pick>> {
        options.validate()?;
        pick::pick(self.prepared()?, camera, options, x, y)
    }

    /// The ray caster: `raycast.comp` on the GPU, or its CPU mirror.
    pub fn raycast(&mut self, camera: &Camera, options: &RaycastOptions) -> Result<Rendered> {
        camera.validate()?;
        bands::check_memory(camera, true)?;
        if !(options.step.is_finite() && options.step > 0.0) {
            return Err(Error::InvalidArgument("ray caster step must be positive".into()));
        }
        if let Some(tf) = &options.colormap {
            tf.validate()?;
        }
        options::check_iso(options.mode, options.iso)?;
        if !(0.0..1.0).contains(&options.min_transmittance) {
            return Err(Error::InvalidArgument("the ray caster's stopping transmittance must be in [0, 1)".into()));
        }
        let k = options.supersample;
        if k == 0 || k > options::MAX_SUPERSAMPLE {
            return Err(Error::InvalidArgument(format!(
                "rays per pixel along each axis must be in 1..={}, not {k}",
                options::MAX_SUPERSAMPLE
            )));
        }
        if k > 1 && options.render_scale != 1.0 {
            return Err(Error::InvalidArgument(
                "a supersampled ray cast is the full-size reference: drop the render scale".into(),
            ));
        }
        if options.render_scale == 1.0 && bands::frame_bands(camera).len() > 1 {
            return bands::assemble(camera, |band| self.raycast(band, options));
        }
        if k > 1 {
            // k x k rays per pixel: the view cast on a grid k times finer, each pixel the mean of
            // its k x k rays (the finer grid's pixel centres sit on a regular grid inside it).
            let fine = camera.supersampled(k);
            fine.validate()?;
            let one = RaycastOptions { supersample: 1, ..options.clone() };
            let mut out = self.raycast(&fine, &one)?;
            let t = std::time::Instant::now();
            out.image = image::downsample(&out.image, k as usize, image::Downsample::Box);
            out.timings.push(StageTime { stage: "downsample", ms: t.elapsed().as_secs_f64() * 1e3 });
            return Ok(out);
        }
        if options.render_scale != 1.0 {
            let full = RaycastOptions { render_scale: 1.0, ..options.clone() };
            return resample::render_scaled(camera, options.render_scale, |low| self.raycast(low, &full));
        }
        let prep = Self::prepared_in(&self.scene)?;
        if prep.set.coordinates().is_some() {
            return Err(Error::Unsupported("the ray caster samples a uniform grid, not a rectilinear one".into()));
        }
        if prep.bricks.is_some() && options.mode != Mode::Iso {
            return Err(Error::Unsupported(
                "the ray caster draws classified splat sets, not bricked volumes (but their isosurfaces)".into(),
            ));
        }
        let recorded = match &mut self.gpu {
            Some(g) => recording::record_raycast(&mut g.engine(prep), prep, camera, options)?,
            None => recording::record_raycast(&mut CpuEngine::new(prep), prep, camera, options)?,
        };
        Ok(recorded.rendered(None))
    }

    /// Validation messages counted so far (always 0 without validation or on the CPU).
    pub fn validation_count(&self) -> u64 {
        self.gpu.as_ref().map(|g| g.context().validation_count()).unwrap_or(0)
    }

    /// The validation messages counted so far (empty without validation or on the CPU).
    pub fn validation_messages(&self) -> Vec<String> {
        self.gpu.as_ref().map(|g| g.context().validation_messages()).unwrap_or_default()
    }

    /// The Vulkan context, for hosts that share it or tests that probe it.
    pub fn context(&self) -> Option<&Arc<vk::Context>> {
        self.gpu.as_ref().map(|g| g.context())
    }
}
