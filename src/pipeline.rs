//! The named stage list and its execution, on the GPU or on the CPU mirrors:
//!
//! | stage          | GPU                          | CPU mirror              |
//! |----------------|------------------------------|-------------------------|
//! | order          | `order_{count,scan,scatter}.comp` | `cpu::order_*`     |
//! | splat_params   | `splat_params.comp`          | `cpu::splat_params`     |
//! | footprint      | `footprint.vert/.frag`       | `cpu::footprint`        |
//! | composite      | `composite.comp`             | `cpu::composite`        |
use crate::camera::Camera;
use crate::constants::{COMPOSITE_TILE, MAX_GROUPS_X, RASTER_TILE_H, RASTER_TILE_W, TILE_CHUNK, WORKGROUP_SIZE};
use crate::cpu::{self, footprint::Blend, ImageF32};
use crate::error::{Error, Result};
use crate::gpu_types::{CompositePush, FootprintPush, Frame, SHEET_MODE_AXIS};
use crate::kernel::Kernel;
use crate::order::{self, Direction, OrderKind};
use crate::raster::{Raster, RasterChoice};
use crate::volume::SplatSet;
use glam::Vec3;
use std::time::Instant;

/// How splats become pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Composite {
    /// Every footprint is composited (over / under) in visibility order.
    #[default]
    Splat,
    /// Westover's sheet summation buffer: splats summed per sheet, sheets composited in order.
    Sheet,
    /// Image-aligned sheet buffer (Mueller & Crawfis 1998): slabs parallel to the image plane, each
    /// splat's kernel sliced into the slabs it overlaps (`crate::slab`).
    Slab,
}

impl std::str::FromStr for Composite {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "splat" => Ok(Self::Splat),
            "sheet" => Ok(Self::Sheet),
            "slab" => Ok(Self::Slab),
            _ => Err(Error::InvalidArgument(format!("unknown compositing '{s}' (splat, sheet, slab)"))),
        }
    }
}

/// Anti-aliasing of distant splats (chapter 3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Antialias {
    /// Footprints keep their world size at every distance.
    #[default]
    None,
    /// Swan's method: beyond k = s·D/p a splat's radius grows by d/k and its energy by (k/d)².
    Swan,
    /// EWA-style screen-space low-pass (Zwicker et al. 2001): the footprint convolved with a
    /// Gaussian of `EWA_LOWPASS_PX` pixels standard deviation, energy preserved.
    Ewa,
}

/// Standard deviation, in pixels, of the EWA low-pass filter: variance ½ px² (full width at half
/// maximum 1.7 px), about one pixel wide; with less, a distant footprint is point-sampled too
/// coarsely to keep its energy (0.5 px loses 1.7 % at d = 4k).
pub const EWA_LOWPASS_PX: f32 = std::f32::consts::FRAC_1_SQRT_2;

impl Antialias {
    fn code(self) -> f32 {
        match self {
            Antialias::None => 0.0,
            Antialias::Swan => 1.0,
            Antialias::Ewa => 2.0,
        }
    }
}

impl std::str::FromStr for Antialias {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "none" => Ok(Self::None),
            "swan" => Ok(Self::Swan),
            "ewa" => Ok(Self::Ewa),
            _ => Err(Error::InvalidArgument(format!("unknown anti-aliasing '{s}' (none, swan, ewa)"))),
        }
    }
}

/// Motion blur of one frame (chapter 4): where every grid point was at the previous time step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Maps a grid point (the scene's own coordinates, as drawn this frame) to its position at
    /// t_{i-1} relative to the eye at t_i: `(V_i M_i)^-1 V_{i-1} M_{i-1}` for object transforms M and
    /// view transforms V.
    pub previous: glam::Mat4,
    /// Splats whose projected path is at most this many pixels are drawn unblurred (delta).
    pub delta_px: f32,
}

/// Per-frame choices. `Default` gives PBTF, per-splat back-to-front compositing, the Gaussian.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct RenderOptions {
    pub order: OrderKind,
    pub composite: Composite,
    pub kernel: Kernel,
    pub antialias: Antialias,
    /// Motion-blurred splats (chapter 4); `None` draws the frame still.
    pub motion: Option<Motion>,
    /// `None`: back to front for per-splat compositing, front to back for sheets.
    pub direction: Option<Direction>,
    /// Memory allowed for one batch of sheet summation layers (RGBA32F each).
    pub sheet_budget_bytes: u64,
    /// Image-aligned slab thickness in voxel spacings (`Composite::Slab`): thinner is closer to the
    /// volume integral and costs more primitives (about 2R/Δ + 1 per splat).
    pub slab_thickness: f32,
    /// Front-to-back early termination for the sheet modes (Mueller et al. 1999): after each batch,
    /// footprints lying wholly over composite tiles whose remaining transmittance is at most this
    /// are skipped. No pixel changes by more than this much. 0 (the default) turns it off; back to
    /// front ignores it. It pays on opaque data (1.2-1.8x on `solid40`) and costs on translucent data,
    /// where nothing is culled but batches are smaller (docs/RESULTS.md). The compute tile
    /// compositor (`Raster::Compute` with `Composite::Splat`) stops each pixel at this transmittance.
    pub early_termination: f32,
    /// How the footprint stage rasterises (`crate::raster`); `Auto` picks per device and footprint
    /// size, and `Rendered::raster` says what it picked.
    pub raster: Raster,
    /// Draw the frame on a grid this fraction of the camera's size and resample it bilinearly to
    /// full size (`crate::resample`; a ray caster's image sample distance is its inverse). Pays
    /// where voxels cover several pixels and the kernel already blurs finer than the grid; the
    /// error it adds is measured against the full-size truth. 1 (the default) draws full size.
    pub render_scale: f32,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            order: OrderKind::Pbtf,
            composite: Composite::Splat,
            kernel: Kernel::Gaussian,
            antialias: Antialias::None,
            motion: None,
            direction: None,
            sheet_budget_bytes: 256 << 20,
            slab_thickness: 1.0,
            early_termination: 0.0,
            raster: Raster::Auto,
            render_scale: 1.0,
        }
    }
}

/// Suggested transmittance threshold of front-to-back early termination: a quarter of an 8-bit step.
pub const DEFAULT_EARLY_TERMINATION: f32 = 1.0 / 1024.0;

/// Most summation layers in one batch when front-to-back early termination is on.
pub const EARLY_TERMINATION_BATCH: u32 = 8;

/// Most summation layers in one batch, whatever the budget.
pub const MAX_BATCH_LAYERS: u32 = 256;

impl RenderOptions {
    /// The visiting direction: as set, else back to front for per-splat compositing through the
    /// graphics pipeline (the over operator needs no destination alpha) and front to back
    /// otherwise (sheets, and the compute tile compositor, which can then stop early).
    pub fn direction(&self) -> Direction {
        self.direction.unwrap_or(match (self.composite, self.raster) {
            (Composite::Splat, Raster::Compute) => Direction::FrontToBack,
            (Composite::Splat, _) => Direction::BackToFront,
            (Composite::Sheet | Composite::Slab, _) => Direction::FrontToBack,
        })
    }

    /// Reject values no frame can use.
    pub fn validate(&self) -> Result<()> {
        if !(0.0..1.0).contains(&self.early_termination) {
            return Err(Error::InvalidArgument(format!(
                "early-termination transmittance {} must be in [0, 1)",
                self.early_termination
            )));
        }
        if self.sheet_budget_bytes == 0 {
            return Err(Error::InvalidArgument("the sheet budget must be positive".into()));
        }
        crate::resample::check_scale(self.render_scale)
    }

    /// Put the early-termination threshold in the batches' push constants (front to back only).
    pub fn set_early_termination(&self, batches: &mut [Batch]) {
        let on = self.direction() == Direction::FrontToBack && self.early_termination > 0.0;
        for b in batches {
            b.push.occluded = if on { self.early_termination } else { 0.0 };
        }
    }

    /// Layers per batch for an image of this size. With early termination on, batches hold at most
    /// `EARLY_TERMINATION_BATCH` layers: the occlusion map only changes between batches.
    pub fn batch_layers(&self, width: u32, height: u32) -> u32 {
        let layer = width as u64 * height as u64 * 16;
        let most = if self.direction() == Direction::FrontToBack && self.early_termination > 0.0 {
            EARLY_TERMINATION_BATCH
        } else {
            MAX_BATCH_LAYERS
        };
        (self.sheet_budget_bytes / layer.max(1)).clamp(1, most as u64) as u32
    }
}

/// One named stage's time in milliseconds (GPU timestamps, or wall time on the CPU path).
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    pub stage: &'static str,
    pub ms: f64,
}

/// A rendered frame: premultiplied RGBA32F, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub image: ImageF32,
    pub timings: Vec<StageTime>,
    /// The footprint stage's raster variant and why (`None` for the ray caster and the truth).
    pub raster: Option<RasterChoice>,
}

/// A scene ready to draw: the splat rows plus, per axis, the splats grouped by slice and each
/// slice's rank among non-empty slices (what the sheet batches index).
pub struct Prepared {
    pub set: SplatSet,
    pub slices: [(Vec<u32>, Vec<u32>); 3],
    pub ranks: Vec<u32>,
    pub rank_offsets: [u32; 3],
    /// The CPU ray caster's dense (colour * tau, tau) field, built on first use and kept with the
    /// scene (the GPU path uploads it to a 3D texture and drops the host copy).
    field: std::sync::OnceLock<crate::truth::DenseField>,
}

impl Prepared {
    pub fn new(set: SplatSet) -> Self {
        let slices = [0, 1, 2].map(|a| set.slices(a));
        let mut ranks = Vec::new();
        let mut rank_offsets = [0; 3];
        for a in 0..3 {
            rank_offsets[a] = ranks.len() as u32;
            ranks.extend(SplatSet::sheet_ranks(&slices[a].0));
        }
        Self { set, slices, ranks, rank_offsets, field: std::sync::OnceLock::new() }
    }

    /// The dense field for ray casting, built once per scene.
    pub fn dense_field(&self) -> Result<&crate::truth::DenseField> {
        if let Some(f) = self.field.get() {
            return Ok(f);
        }
        let f = crate::truth::DenseField::new(&self.set)?;
        Ok(self.field.get_or_init(|| f))
    }
}

/// The per-frame uniforms shared by every stage.
pub fn make_frame(
    set: &SplatSet,
    camera: &Camera,
    kernel: Kernel,
    antialias: Antialias,
    motion: Option<&Motion>,
    split: [u32; 3],
    back_to_front: bool,
) -> Frame {
    let g = set.grid();
    let radius_vox = kernel.radius();
    let f = camera.forward();
    let r = camera.right();
    let u = camera.true_up();
    let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
    Frame {
        view_proj: camera.view_proj().to_cols_array_2d(),
        eye: v4(camera.eye, if camera.is_perspective() { 1.0 } else { 0.0 }),
        forward: v4(f, camera.near),
        right: v4(r, camera.far),
        up: v4(u, camera.pixels_per_unit()),
        origin: [g.origin[0], g.origin[1], g.origin[2], radius_vox],
        spacing: [g.spacing[0], g.spacing[1], g.spacing[2], radius_vox * g.kernel_spacing()],
        dims: [g.dims[0], g.dims[1], g.dims[2], set.len() as u32],
        split: [split[0], split[1], split[2], back_to_front as u32],
        aa: [antialias.code(), kernel.footprint_sigma() as f32, EWA_LOWPASS_PX, 0.0],
        motion: motion.map(|m| m.previous).unwrap_or(glam::Mat4::IDENTITY).to_cols_array_2d(),
        blur: [
            motion.map(|m| m.delta_px.max(1e-6)).unwrap_or(0.0),
            kernel.motion_g() as f32,
            camera.width as f32,
            camera.height as f32,
        ],
    }
}

/// The per-frame constants for rendering `set` from `camera` with `opts`.
pub fn frame_for(set: &SplatSet, camera: &Camera, opts: &RenderOptions) -> Frame {
    let split = order::pbtf_split(set, camera);
    let btf = opts.direction() == Direction::BackToFront;
    make_frame(set, camera, opts.kernel, opts.antialias, opts.motion.as_ref(), split, btf)
}

/// The uniforms the order stage alone needs (no anti-aliasing or motion).
pub fn order_frame(set: &SplatSet, camera: &Camera, direction: Direction) -> Frame {
    let split = order::pbtf_split(set, camera);
    make_frame(set, camera, Kernel::Gaussian, Antialias::None, None, split, direction == Direction::BackToFront)
}

/// One batch of sheets drawn into summation layers and composited together.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    pub first_instance: u32,
    pub instances: u32,
    pub layers: u32,
    pub push: FootprintPush,
}

/// The grid axis most perpendicular to the view plane: the axis-aligned sheets' normal.
pub fn sheet_axis(camera: &Camera) -> usize {
    let f = camera.forward().abs();
    if f.x >= f.y && f.x >= f.z {
        0
    } else if f.y >= f.z {
        1
    } else {
        2
    }
}

/// The sheet axis (the grid axis most perpendicular to the view plane) and its batches in visiting
/// order. Empty sheets are skipped; a batch never straddles the eye's plane, so its splats are one
/// contiguous run of the slice-grouped draw list.
pub fn sheet_plan(prep: &Prepared, camera: &Camera, direction: Direction, max_layers: u32) -> (usize, Vec<Batch>) {
    let axis = sheet_axis(camera);
    let split = order::pbtf_split(&prep.set, camera)[axis];
    let n = prep.set.grid().dims[axis];
    let offsets = &prep.slices[axis].0;
    let nonempty = |s: &u32| offsets[*s as usize + 1] > offsets[*s as usize];
    let low: Vec<u32> = (0..split).rev().filter(nonempty).collect();
    let high: Vec<u32> = (split..n).filter(nonempty).collect();
    let mut sides = vec![low, high];
    if direction == Direction::BackToFront {
        sides.reverse();
        for s in &mut sides {
            s.reverse();
        }
    }
    let rank_of = |s: u32| prep.ranks[(prep.rank_offsets[axis] + s) as usize];
    let mut batches = Vec::new();
    for side in &sides {
        for chunk in side.chunks(max_layers.max(1) as usize) {
            let (first, last) = (chunk[0], chunk[chunk.len() - 1]);
            let (lo, hi) = (first.min(last), first.max(last));
            let start = offsets[lo as usize];
            let end = offsets[hi as usize + 1];
            batches.push(Batch {
                first_instance: start,
                instances: end - start,
                layers: chunk.len() as u32,
                push: FootprintPush {
                    sheet_mode: SHEET_MODE_AXIS,
                    axis: axis as u32,
                    rank_offset: prep.rank_offsets[axis],
                    rank_base: rank_of(first),
                    rank_dir: if last >= first { 1 } else { -1 },
                    ..Default::default()
                },
            });
        }
    }
    (axis, batches)
}

/// Push constants of the tile binning and compositing stages for a draw list of `n` entries on a
/// `width` x `height` image: chunks of `TILE_CHUNK` entries, fewer (and longer) where the count
/// matrix would pass `raster::MAX_TILE_CELLS`.
pub fn tile_push(opts: &RenderOptions, n: u32, width: u32, height: u32) -> FootprintPush {
    let btf = opts.direction() == Direction::BackToFront;
    let tiles = (width.div_ceil(RASTER_TILE_W) as u64 * height.div_ceil(RASTER_TILE_H) as u64).max(1);
    let most = (crate::raster::MAX_TILE_CELLS / tiles).max(1);
    FootprintPush {
        count: n,
        chunks: (n.div_ceil(TILE_CHUNK) as u64).clamp(1, most) as u32,
        back_to_front: btf as u32,
        occluded: if btf { 0.0 } else { opts.early_termination },
        ..Default::default()
    }
}

/// Push constants of `sheet_tiles.comp` for a frame's sheet batches: every entry of the sheet
/// list from 0, layers numbered by global sheet (rank base 0, direction +1), no occlusion culling.
pub fn sheet_tiles_push(batches: &[Batch], first: &Batch) -> FootprintPush {
    FootprintPush { rank_base: 0, rank_dir: 1, first: 0, count: sheet_entries(batches), occluded: 0.0, ..first.push }
}

/// Entries of the frame's sheet list that the batches draw (they cover it from 0).
fn sheet_entries(batches: &[Batch]) -> u32 {
    batches.iter().map(|b| b.first_instance + b.instances).max().unwrap_or(0)
}

/// Whether finding each tile's sheet range (`sheet_tiles`) can pay for itself: the composite must
/// read at least `SHEET_TILES_MIN_RATIO` layer pixels per entry of the sheet list (measured on
/// lavapipe: the pass costs 30–70 ns per entry, the composite ~8 ns per layer pixel). A single
/// sheet seen head-on (the raster sweep) falls below, the volume scenes far above.
pub fn sheet_tiles_pay(batches: &[Batch], width: u32, height: u32) -> bool {
    let entries = sheet_entries(batches) as u64;
    let layer_pixels: u64 = batches.iter().map(|b| b.layers as u64).sum::<u64>() * width as u64 * height as u64;
    entries > 0 && layer_pixels >= SHEET_TILES_MIN_RATIO * entries
}

/// See `sheet_tiles_pay`.
pub const SHEET_TILES_MIN_RATIO: u64 = 8;

/// Per-tile sheet ranges that let the composite read every layer (the `sheet_tiles` pass skipped):
/// lowest 0, highest + 1 `i32::MAX`.
pub const ALL_SHEETS: [u32; 2] = [0, i32::MAX as u32];

/// Push constants of `composite.comp` for batch `b`.
pub fn composite_push(b: &Batch, btf: bool, width: u32, height: u32) -> CompositePush {
    CompositePush {
        layers: b.layers,
        back_to_front: btf as u32,
        width,
        height,
        rank_base: b.push.rank_base,
        rank_dir: b.push.rank_dir,
        tiles: width.div_ceil(COMPOSITE_TILE) * height.div_ceil(COMPOSITE_TILE),
        pad: 0,
    }
}

/// Workgroup counts for `n` invocations of a 1D stage (spilling into y past `MAX_GROUPS_X`).
pub fn groups_1d(n: u32) -> [u32; 3] {
    let g = n.div_ceil(WORKGROUP_SIZE).max(1);
    [g.min(MAX_GROUPS_X), g.div_ceil(MAX_GROUPS_X), 1]
}

/// The whole frame on the CPU mirrors, stage by stage.
pub fn render_cpu(prep: &Prepared, camera: &Camera, opts: &RenderOptions) -> Result<Rendered> {
    render_cpu_with(prep, camera, opts, &mut Vec::new())
}

/// `render_cpu`, leaving the sheet modes' per-tile sheet ranges (`cpu::sheet_tiles`) in
/// `sheet_tiles`.
pub fn render_cpu_with(
    prep: &Prepared,
    camera: &Camera,
    opts: &RenderOptions,
    sheet_tiles: &mut Vec<u32>,
) -> Result<Rendered> {
    camera.validate()?;
    let set = &prep.set;
    let direction = opts.direction();
    let btf = direction == Direction::BackToFront;
    let frame = frame_for(set, camera, opts);
    let n = set.len();
    let mut timings = Vec::new();
    let mut t = Instant::now();
    let mut lap = |stage: &'static str, timings: &mut Vec<StageTime>| {
        timings.push(StageTime { stage, ms: t.elapsed().as_secs_f64() * 1e3 });
        t = Instant::now();
    };

    let mut draw = vec![0u32; n];
    if opts.composite == Composite::Splat {
        if opts.order == OrderKind::Pbtf {
            let rows = set.row_start().len() - 1;
            let mut row_split = vec![0u32; rows];
            let mut segments = vec![0u32; 2 * rows];
            cpu::order_count(&frame, set.splats(), set.row_start(), &mut row_split, &mut segments);
            cpu::order_scan(&frame, &mut segments);
            cpu::order_scatter(&frame, set.splats(), set.row_start(), &row_split, &segments, &mut draw);
        } else {
            draw = order::visibility_order(set, camera, opts.order, direction);
        }
        lap("order", &mut timings);
    }
    let mut params = vec![Default::default(); n];
    cpu::splat_params(&frame, set.splats(), &mut params);
    lap("splat_params", &mut timings);

    let table = opts.kernel.radial_table();
    let slice_table = opts.kernel.slice_table();
    let (w, h) = (camera.width, camera.height);
    let mut image = ImageF32::new(w, h);
    let points = opts.raster == Raster::Points;
    let compute = opts.raster == Raster::Compute;
    let inputs = cpu::footprint::FootprintInputs {
        frame: &frame,
        params: &params,
        draw_list: &draw,
        splats: set.splats(),
        sheet_rank: &prep.ranks,
        table: &table,
        slice_table: &slice_table,
        occlusion: &[],
    };
    match opts.composite {
        Composite::Splat => {
            if compute {
                let push = tile_push(opts, n as u32, w, h);
                let bins = cpu::tile::tile_bins_cpu(&inputs, &push)?;
                lap("tile_bins", &mut timings);
                cpu::tile_composite(&inputs, &push, &bins.quads, &bins.start, &bins.entries, &mut image);
            } else {
                let blend = if btf { Blend::Over } else { Blend::Under };
                let push = FootprintPush::default();
                cpu::footprint(&inputs, &push, blend, points, 0, n as u32, std::slice::from_mut(&mut image));
            }
            lap("footprint", &mut timings);
        }
        Composite::Sheet | Composite::Slab => {
            let (draw_list, batches) = if opts.composite == Composite::Sheet {
                let (axis, batches) = sheet_plan(prep, camera, direction, opts.batch_layers(w, h));
                (std::borrow::Cow::Borrowed(&prep.slices[axis].1[..]), batches)
            } else {
                let pc = crate::slab::slab_geometry(&frame, set.grid(), n, opts.slab_thickness, direction)?;
                let (pairs, batches) = crate::slab::slab_bins_cpu(&pc, &params, opts.batch_layers(w, h))?;
                lap("slab_bins", &mut timings);
                (std::borrow::Cow::Owned(pairs), batches)
            };
            let mut batches = batches;
            opts.set_early_termination(&mut batches);
            let tiles = w.div_ceil(COMPOSITE_TILE) as usize * h.div_ceil(COMPOSITE_TILE) as usize;
            let mut occlusion = vec![1.0f32; tiles];
            *sheet_tiles = vec![0u32; 2 * tiles];
            let sheet_inputs = cpu::footprint::FootprintInputs { draw_list: &draw_list, ..inputs };
            match batches.first() {
                Some(first) if sheet_tiles_pay(&batches, w, h) => {
                    let push = sheet_tiles_push(&batches, first);
                    cpu::sheet_tiles(&sheet_inputs, &push, points, sheet_tiles);
                    lap("sheet_tiles", &mut timings);
                }
                _ => {
                    sheet_tiles[..tiles].fill(ALL_SHEETS[0]);
                    sheet_tiles[tiles..].fill(ALL_SHEETS[1]);
                }
            }
            let (mut raster_ms, mut comp_ms) = (0.0, 0.0);
            for b in &batches {
                let inputs = cpu::footprint::FootprintInputs { occlusion: &occlusion, ..sheet_inputs };
                let t0 = Instant::now();
                let layers = if compute {
                    let mut sums = vec![0u32; b.layers as usize * w as usize * h as usize * 4];
                    let push = FootprintPush { first: b.first_instance, count: b.instances, ..b.push };
                    cpu::footprint_sum(&inputs, &push, &mut sums);
                    (0..b.layers as usize).map(|l| cpu::footprint::fixed_layer(&sums, l, w, h)).collect()
                } else {
                    let mut layers = vec![ImageF32::new(w, h); b.layers as usize];
                    cpu::footprint(&inputs, &b.push, Blend::Add, points, b.first_instance, b.instances, &mut layers);
                    layers
                };
                let t1 = Instant::now();
                let push = composite_push(b, btf, w, h);
                cpu::composite(&push, &layers, sheet_tiles, &mut image, &mut occlusion);
                raster_ms += (t1 - t0).as_secs_f64() * 1e3;
                comp_ms += t1.elapsed().as_secs_f64() * 1e3;
            }
            timings.push(StageTime { stage: "footprint", ms: raster_ms });
            timings.push(StageTime { stage: "composite", ms: comp_ms });
        }
    }
    Ok(Rendered { image, timings, raster: None })
}
