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

pub mod aa;
pub mod animate;
pub mod bench;
pub mod camera;
pub mod classify;
pub mod constants;
pub mod cpu;
mod error;
mod gpu;
pub mod gpu_types;
pub mod kernel;
pub mod loaders;
pub mod metrics;
pub mod order;
pub mod output;
pub mod peer;
pub mod pipeline;
pub mod raster;
pub mod rates;
pub mod resample;
pub mod scene;
pub mod slab;
pub mod soak;
pub mod stability;
pub mod terrain;
pub mod truth;
#[allow(unsafe_code)]
pub mod vk;
pub mod volume;

pub use camera::{Camera, Projection};
pub use error::{Error, Result};
pub use kernel::Kernel;
pub use order::{Direction, OrderKind};
pub use pipeline::{Antialias, Composite, RenderOptions, Rendered, StageTime};
pub use raster::{Raster, RasterChoice};
pub use volume::{Grid, SplatSet, Volume};

use pipeline::Prepared;
use std::sync::Arc;

/// Where the frame is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Backend {
    #[default]
    Gpu,
    /// The CPU mirrors, stage by stage.
    Cpu,
}

/// How to create a [`Renderer`].
#[derive(Clone, Debug, Default)]
#[non_exhaustive]
pub struct RendererOptions {
    pub backend: Backend,
    /// Khronos validation with synchronization validation; messages are counted, see
    /// [`Renderer::validation_messages`].
    pub validation: bool,
    /// Pick the Vulkan device whose name contains this text.
    pub device_name: Option<String>,
}

/// A scene on a backend. `Send`: one renderer per thread.
pub struct Renderer {
    gpu: Option<gpu::GpuPipeline>,
    scene: Option<Prepared>,
}

impl Renderer {
    pub fn new(options: &RendererOptions) -> Result<Self> {
        let gpu = match options.backend {
            Backend::Gpu => {
                let ctx = vk::Context::new(&vk::ContextOptions {
                    validation: options.validation,
                    device_name: options.device_name.clone(),
                })?;
                Some(gpu::GpuPipeline::new(ctx)?)
            }
            Backend::Cpu => None,
        };
        Ok(Self { gpu, scene: None })
    }

    /// A renderer on a host program's Vulkan device (see [`vk::Context::from_host`]).
    pub fn with_context(ctx: Arc<vk::Context>) -> Result<Self> {
        Ok(Self { gpu: Some(gpu::GpuPipeline::new(ctx)?), scene: None })
    }

    /// The Vulkan device's name, or "cpu".
    pub fn device_name(&self) -> String {
        self.gpu.as_ref().map(|g| g.context().device_name().to_string()).unwrap_or_else(|| "cpu".into())
    }

    pub fn backend(&self) -> Backend {
        if self.gpu.is_some() {
            Backend::Gpu
        } else {
            Backend::Cpu
        }
    }

    pub fn set_scene(&mut self, set: SplatSet) -> Result<()> {
        let prep = Prepared::new(set);
        if let Some(g) = &mut self.gpu {
            g.set_scene(&prep)?;
        }
        self.scene = Some(prep);
        Ok(())
    }

    pub fn scene(&self) -> Option<&SplatSet> {
        self.scene.as_ref().map(|p| &p.set)
    }

    pub fn render(&mut self, camera: &Camera, options: &RenderOptions) -> Result<Rendered> {
        self.render_keeping(camera, options, None)
    }

    /// `render`, also leaving the sheet modes' per-tile sheet ranges in `sheet_tiles` when given
    /// (of the grid actually drawn: the coarse one under a render scale).
    fn render_keeping(
        &mut self,
        camera: &Camera,
        options: &RenderOptions,
        sheet_tiles: Option<&mut Vec<u32>>,
    ) -> Result<Rendered> {
        options.validate()?;
        camera.validate()?;
        if options.render_scale != 1.0 {
            let full = RenderOptions { render_scale: 1.0, ..options.clone() };
            return resample::render_scaled(camera, options.render_scale, |low| {
                self.render_keeping(low, &full, sheet_tiles)
            });
        }
        let prep =
            self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))?;
        let device = match &self.gpu {
            Some(g) => {
                raster::Device { cpu: g.context().is_cpu_device(), point_size_max: g.context().point_size_max() }
            }
            None => raster::Device { cpu: true, point_size_max: f32::INFINITY },
        };
        let choice = raster::choose(&prep.set, camera, options, device)?;
        let mut opts = options.clone();
        opts.raster = choice.raster;
        let mut out = match (&mut self.gpu, sheet_tiles) {
            (Some(g), tiles) => {
                let out = g.render(prep, camera, &opts)?;
                if let Some(tiles) = tiles {
                    *tiles = g.last_sheet_tiles()?;
                }
                out
            }
            (None, Some(tiles)) => pipeline::render_cpu_with(prep, camera, &opts, tiles)?,
            (None, None) => pipeline::render_cpu(prep, camera, &opts)?,
        };
        out.raster = Some(choice);
        Ok(out)
    }

    /// The compute tile compositor's binning for this frame (GPU stages or their CPU mirrors):
    /// each screen tile's first entry plus the total, and the entries (splat indices, each tile's
    /// run in draw-list order).
    pub fn tile_lists(&mut self, camera: &Camera, options: &RenderOptions) -> Result<(Vec<u32>, Vec<u32>)> {
        camera.validate()?;
        options.validate()?;
        let prep =
            self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))?;
        let mut opts = options.clone();
        opts.raster = Raster::Compute;
        opts.composite = Composite::Splat;
        if let Some(g) = &mut self.gpu {
            return g.tile_lists(prep, camera, &opts);
        }
        let frame = pipeline::frame_for(&prep.set, camera, &opts);
        let draw = match opts.order {
            OrderKind::Pbtf => cpu_pbtf_order(prep, camera, opts.direction()),
            kind => order::visibility_order(&prep.set, camera, kind, opts.direction()),
        };
        let mut params = vec![Default::default(); prep.set.len()];
        cpu::splat_params(&frame, prep.set.splats(), &mut params);
        let inputs = cpu::footprint::FootprintInputs {
            frame: &frame,
            params: &params,
            draw_list: &draw,
            splats: prep.set.splats(),
            sheet_rank: &prep.ranks,
            table: &[],
            slice_table: &[],
            occlusion: &[],
        };
        let bins = cpu::tile::tile_bins_cpu(
            &inputs,
            &pipeline::tile_push(&opts, prep.set.len() as u32, camera.width, camera.height),
        )?;
        Ok((bins.start, bins.entries))
    }

    /// The sheet modes' per-tile sheet ranges of this frame, as the backend computes them (the GPU
    /// `sheet_tiles` stage, or its CPU mirror): for each composite tile, the lowest sheet (global
    /// rank; slab mode: slab) whose footprints reach it (`u32::MAX`: none), then for each tile the
    /// highest + 1; every tile `pipeline::ALL_SHEETS` where the pass would not pay
    /// (`pipeline::sheet_tiles_pay`). Renders the frame to get them.
    pub fn sheet_tiles(&mut self, camera: &Camera, options: &RenderOptions) -> Result<Vec<u32>> {
        if options.composite == Composite::Splat {
            return Err(Error::InvalidArgument("sheet ranges exist only in the sheet and slab modes".into()));
        }
        let mut tiles = Vec::new();
        self.render_keeping(camera, options, Some(&mut tiles))?;
        Ok(tiles)
    }

    /// The PBTF draw sequence as the backend computes it (the GPU order stage, or its CPU mirror).
    pub fn pbtf_order(&mut self, camera: &Camera, direction: Direction) -> Result<Vec<u32>> {
        camera.validate()?;
        let prep =
            self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))?;
        match &mut self.gpu {
            Some(g) => g.order(prep, camera, direction),
            None => Ok(cpu_pbtf_order(prep, camera, direction)),
        }
    }

    /// The image-aligned sheets' binning for this camera: the (splat, slab) pairs, interleaved, in
    /// visiting order (GPU stages `splat_params`, `slab_count`, `slab_scan`, `slab_scatter`, or
    /// their CPU mirrors), for comparison and inspection.
    pub fn slab_pairs(&mut self, camera: &Camera, options: &RenderOptions) -> Result<Vec<u32>> {
        camera.validate()?;
        options.validate()?;
        let prep =
            self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))?;
        let direction = options.direction();
        let set = &prep.set;
        let frame = pipeline::frame_for(set, camera, options);
        let pc = slab::slab_geometry(&frame, set.grid(), set.len(), options.slab_thickness, direction)?;
        match &mut self.gpu {
            Some(g) => g.slab_pairs(&frame, &pc),
            None => {
                let mut params = vec![gpu_types::SplatParams::default(); set.len()];
                cpu::splat_params(&frame, set.splats(), &mut params);
                Ok(slab::slab_bins_cpu(&pc, &params, u32::MAX)?.0)
            }
        }
    }

    /// The ray caster: `raycast.comp` on the GPU, or its CPU mirror.
    pub fn raycast(&mut self, camera: &Camera, options: &cpu::raycast::RaycastOptions) -> Result<Rendered> {
        camera.validate()?;
        if !(options.step.is_finite() && options.step > 0.0) {
            return Err(Error::InvalidArgument("ray caster step must be positive".into()));
        }
        if options.render_scale != 1.0 {
            let full = cpu::raycast::RaycastOptions { render_scale: 1.0, ..*options };
            return resample::render_scaled(camera, options.render_scale, |low| self.raycast(low, &full));
        }
        let prep =
            self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))?;
        match &mut self.gpu {
            Some(g) => g.raycast(prep, camera, options),
            None => {
                let t = std::time::Instant::now();
                let field = prep.dense_field()?;
                let rc = cpu::raycast::raycast_params(&prep.set, camera, options);
                let (_, bricks) = cpu::raycast::brick_occupancy(field, options.brick.max(1));
                let image = cpu::raycast(&rc, field, &bricks, None);
                Ok(Rendered {
                    image,
                    timings: vec![StageTime { stage: "raycast", ms: t.elapsed().as_secs_f64() * 1e3 }],
                    raster: None,
                })
            }
        }
    }

    /// The splat_params stage's output for this camera (GPU stage, or its CPU mirror).
    pub fn splat_params(
        &mut self,
        camera: &Camera,
        kernel: Kernel,
        antialias: Antialias,
    ) -> Result<Vec<gpu_types::SplatParams>> {
        camera.validate()?;
        let prep =
            self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene: call set_scene first".into()))?;
        match &mut self.gpu {
            Some(g) => g.splat_params(prep, camera, kernel, antialias),
            None => {
                let set = &prep.set;
                let frame =
                    pipeline::make_frame(set, camera, kernel, antialias, None, order::pbtf_split(set, camera), true);
                let mut out = vec![gpu_types::SplatParams::default(); set.len()];
                cpu::splat_params(&frame, set.splats(), &mut out);
                Ok(out)
            }
        }
    }

    /// Validation messages counted so far (always 0 without validation or on the CPU).
    pub fn validation_count(&self) -> u64 {
        self.gpu.as_ref().map(|g| g.context().validation_count()).unwrap_or(0)
    }

    pub fn validation_messages(&self) -> Vec<String> {
        self.gpu.as_ref().map(|g| g.context().validation_messages()).unwrap_or_default()
    }

    /// GPU roofline of the raster pass: milliseconds for `instances` additive `size`-pixel quads.
    pub fn roofline_quads(&mut self, width: u32, height: u32, size: u32, instances: u32) -> Result<f64> {
        match &mut self.gpu {
            Some(g) => g.roofline_quads(width, height, size.max(1), instances),
            None => Err(Error::Unsupported("the roofline needs a GPU backend".into())),
        }
    }

    /// GPU roofline of the compositing pass: (roofline ms, composite.comp ms) over `layers` layers.
    pub fn roofline_composite(&mut self, width: u32, height: u32, layers: u32) -> Result<(f64, f64)> {
        match &mut self.gpu {
            Some(g) => g.roofline_composite(width, height, layers.max(1)),
            None => Err(Error::Unsupported("the roofline needs a GPU backend".into())),
        }
    }

    /// The Vulkan context, for hosts that share it or tests that probe it.
    pub fn context(&self) -> Option<&Arc<vk::Context>> {
        self.gpu.as_ref().map(|g| g.context())
    }
}

/// GPU memory a scene costs per splat: the splat (32 B), its parameters (80 B), its order entry and
/// its three slice-list entries (16 B), plus the per-row tables spread over the splats.
pub fn gpu_bytes_per_splat(set: &SplatSet) -> f64 {
    let n = set.len().max(1) as f64;
    let rows = (set.row_start().len() - 1) as f64;
    let dims = set.grid().dims;
    let per_splat =
        (std::mem::size_of::<gpu_types::Splat>() + std::mem::size_of::<gpu_types::SplatParams>() + 16) as f64;
    per_splat + (rows * (4.0 + 4.0 + 8.0) + (dims[0] + dims[1] + dims[2]) as f64 * 4.0) / n
}

/// The three order stages' CPU mirrors run in sequence.
fn cpu_pbtf_order(prep: &Prepared, camera: &Camera, direction: Direction) -> Vec<u32> {
    let set = &prep.set;
    let frame = pipeline::order_frame(set, camera, direction);
    let rows = set.row_start().len() - 1;
    let mut row_split = vec![0u32; rows];
    let mut segments = vec![0u32; 2 * rows];
    let mut out = vec![0u32; set.len()];
    cpu::order_count(&frame, set.splats(), set.row_start(), &mut row_split, &mut segments);
    cpu::order_scan(&frame, &mut segments);
    cpu::order_scatter(&frame, set.splats(), set.row_start(), &row_split, &segments, &mut out);
    out
}
