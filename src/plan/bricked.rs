//! A bricked volume's frame plan: the budget split between the resident store, levels of detail
//! and batches; whether records stream; the brick stages' builds; the brick uniforms; early
//! termination and hidden-brick culling; and for the sheet modes their layers and sheets. What
//! is visible comes back from the device (`brick_cull`); the recording cuts its batches by this plan.
use super::pass::{sheet_pass, SheetPass, TileRule};
use super::{
    node_and_cut_words, node_levels, pyramid_bytes, Prepared, LOD_BUFFERS, PYRAMID_BYTES, SLOTTED_LOD_BUFFERS,
    STREAMED_LOD_BUFFERS,
};
use crate::bricks::{BrickScene, BRICK};
use crate::builds::{Footprint, Records};
use crate::camera::Camera;
use crate::constants::{PYRAMID_PAGE, PYRAMID_PAGES};
use crate::dispatch::{Blend, Limits, List, Res};
use crate::error::{Error, Result};
use crate::gpu_types::{BrickFrame, Frame};
use crate::options::Raster;
use crate::options::{Composite, Lod, Mode, RenderOptions};
use crate::order::{Direction, OrderKind};
use crate::residency::SLOT_WORDS;
use std::fmt;

/// Device bytes a bricked frame holds per splat of a batch: its parameters (80), order entry and
/// voxel (8), and for the tile compositor its screen quad (80) and about four tile entries (the
/// sheet modes' (splat, slab) pairs fit in the last two).
pub const BATCH_BYTES_PER_SPLAT: u64 = 80 + 4 + 8 + 80 + 16;

/// What a bricked frame keeps resident besides its batches under `budget`: the store (without its
/// records when they stream, `BrickScene::streams`; then the per-brick counts), the brick index,
/// the draw-order slots and visible list, and the images.
pub fn bricked_resident_bytes(scene: &BrickScene, budget: u64, width: u32, height: u32) -> u64 {
    let s = &scene.store;
    let store = if scene.streams(budget) {
        s.bytes() - s.records.len() as u64 * 4 + s.headers.len() as u64 * 4
    } else {
        s.bytes()
    };
    store + s.index.len() as u64 * (4 + 4 + 16) + scene.tree().len() as u64 * 16 + width as u64 * height as u64 * 16 * 3
}

/// The least budget that draws `scene` at `width` x `height`: resident data and one brick's splats
/// (and records, when they stream).
pub fn bricked_min_budget(scene: &BrickScene, budget: u64, width: u32, height: u32) -> u64 {
    let brick = (BRICK as u64).pow(3) * (BATCH_BYTES_PER_SPLAT + 4 * scene.streams(budget) as u64);
    bricked_resident_bytes(scene, budget, width, height) + brick
}

/// The bytes the precomputed differences (`BrickStore::gradient_words`) take when this frame reads
/// them: it classifies with gradients, its store is resident in one page (`Records::OnePage`),
/// each fits a binding and both fit half of what the store leaves of the budget (`available`).
/// `None`: neighbours are read through the store.
fn gradients_fit(scene: &BrickScene, build: Records, range: u64, available: u64) -> Option<u64> {
    let bytes = scene.store.gradient_len() * 4;
    (build == Records::OnePage && scene.reads_gradients() && bytes <= range.min(available / 4)).then_some(2 * bytes)
}

/// A bricked frame's decisions.
#[derive(Clone, Debug)]
pub struct BrickedPlan {
    /// The store's records stay on the host and stream batch by batch.
    pub streamed: bool,
    /// Levels of detail on.
    pub lod: bool,
    /// The levels of detail's buffers and their bytes per brick.
    pub lod_buffers: &'static [(Res, u64)],
    /// Each batch builds its coarse bricks' pyramids (a streamed store whose pyramid does not fit).
    pub per_batch: bool,
    /// A batch entry's pyramid bytes when each batch builds its own (else 0).
    pub batch_pyramid: u64,
    /// Levels of the node tree above the brick (0: none).
    pub node_levels: u32,
    /// Bytes of the node tree and its cut.
    pub node_bytes: u64,
    /// Bytes of the levels of detail in all.
    pub pyramid: u64,
    /// Bytes left for batches.
    pub available: u64,
    /// A streamed store's record cache slots.
    pub cache_slots: u32,
    /// The device's largest storage binding.
    pub range: u64,
    /// The brick stages' reading of the records.
    pub build: Records,
    /// Bytes of the precomputed differences, when the frame reads them.
    pub gradients: Option<u64>,
    /// `brick_params`' and a resident pyramid's build: `build`, or `Records::Gradients`.
    pub gradient_build: Records,
    /// The brick stages' uniforms.
    pub brick_frame: BrickFrame,
    /// The compute tile compositor (else the footprint draw).
    pub compute: bool,
    /// The per-splat footprint draw's build.
    pub footprint: Footprint,
    /// Front to back, terminating: the frame is cut into waves.
    pub terminating: bool,
    /// Later waves drop the bricks that the image so far hides.
    pub cull_hidden: bool,
    /// The early-termination threshold.
    pub early_termination: f32,
    /// Motion-blurred footprints.
    pub blur: bool,
    /// The sheet modes' decisions (`None`: per-splat compositing).
    pub sheets: Option<BrickedSheets>,
    /// A projection mode (no levels of detail, no early termination: every voxel is read).
    pub projection: Option<super::Projection>,
    /// The host's depth hides what lies behind it (the tile compositor's `depth` build).
    pub depth: bool,
}

impl BrickedPlan {
    /// Bricks across the grid (the brick uniforms' `grid`).
    pub fn grid(&self) -> [u32; 3] {
        let g = self.brick_frame.grid;
        [g[0], g[1], g[2]]
    }

    /// The brick grid's PBTF split (the brick uniforms' `split`).
    pub fn split(&self) -> [u32; 3] {
        let s = self.brick_frame.split;
        [s[0], s[1], s[2]]
    }

    /// The tile compositor's rule for a batch of `n` splats.
    pub fn tile_rule(&self, n: u32, width: u32, height: u32, direction: Direction) -> TileRule {
        let mut rule = self.tile_walk(n, width, height, direction);
        rule.composite.depth = self.depth;
        rule
    }

    fn tile_walk(&self, n: u32, width: u32, height: u32, direction: Direction) -> TileRule {
        match &self.projection {
            Some(p) => {
                let mut rule = TileRule::plan(n, width, height, Direction::FrontToBack, 0.0, false);
                rule.composite.order = p.builds(false).0;
                rule
            }
            None => TileRule::plan(n, width, height, direction, self.early_termination, self.blur),
        }
    }
}

/// A bricked frame's sheets or slabs.
#[derive(Clone, Debug)]
pub struct BrickedSheets {
    /// Axis-aligned sheets binned by voxel plane (else slabs along the view).
    pub axis_sheets: bool,
    /// The sheets' normal axis.
    pub axis: usize,
    /// The grid's PBTF split along it.
    pub split: u32,
    /// Slab thickness in voxel spacings.
    pub slab_thickness: f32,
    /// Bytes left for batches once the layers are held.
    pub available: u64,
    /// How batches are summed.
    pub pass: SheetPass,
}

/// A projection's texels a pixel side (`project_texels`): PROJECT_TEXEL_SIDE, more where the view
/// projects a voxel spacing to less than three texels (`voxel_px` pixels: a texel spans at most
/// PROJECT_TEXEL_VOXELS of it), fewer where the image is large; at most PROJECT_TEXELS_MAX of
/// them, and `None` where that cannot hold texels that fine. The winner of a texel stands for the
/// others only where their footprints nearly coincide: texels of a third of a pixel over voxels of
/// a tenth dropped two thirds of the bonsai's MIP coverage at 64x64.
pub fn texel_side(w: u32, h: u32, voxel_px: f32) -> Option<u32> {
    let pixels = w as u64 * h as u64;
    let need = (1.0 / (PROJECT_TEXEL_VOXELS * voxel_px)).ceil();
    if !(need.is_finite() && need < 65536.0) {
        return None;
    }
    let need = (need as u32).max(1);
    (need..=need.max(PROJECT_TEXEL_SIDE)).rev().find(|&s| pixels * (s as u64 * s as u64) <= PROJECT_TEXELS_MAX)
}

/// The fewest pixels a voxel spacing (the grid's smallest) spans anywhere in `camera`'s view of
/// `grid`: at the box's farthest corner in a perspective view.
pub fn least_voxel_pixels(grid: &crate::Grid, camera: &Camera) -> f32 {
    let spacing = grid.spacing.into_iter().fold(f32::INFINITY, f32::min);
    let per_unit = camera.pixels_per_unit();
    if !camera.is_perspective() {
        return spacing * per_unit;
    }
    let [lo, hi] = grid.world_box(glam::Vec3::ZERO, glam::Vec3::from(grid.dims.map(|d| d.max(1) as f32 - 1.0)));
    let forward = camera.forward();
    let far = (0..8)
        .map(|c| glam::Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo))
        .map(|p| (p - camera.eye).dot(forward))
        .fold(camera.near, f32::max);
    spacing * per_unit / far
}

/// Whether every value the TF table extracts draws (an optical depth above 0 in f32: a tiny
/// opacity rounds to none), so that no voxel that claims a texel is transparent (texels.glsl).
fn extracted_draw(table: &[u32]) -> bool {
    (0..crate::constants::TF_ENTRIES)
        .filter(|&q| crate::bricks::emits(table, q))
        .all(|q| crate::volume::optical_depth(f32::from_bits(table[4 * q as usize + 3])) > 0.0)
}

/// The texels' bytes at `side` texels a pixel side (0: none), with the word before them that
/// counts a batch's drawn voxels (texels.glsl's TEXELS_FIRST).
pub fn texel_bytes(w: u32, h: u32, side: u32) -> u64 {
    if side == 0 {
        return 0;
    }
    (1 + w as u64 * side as u64 * h as u64 * side as u64) * 4
}

/// MIP's and MinIP's texels a pixel side: a voxel within a third of a pixel of a brighter one adds
/// next to nothing (docs/results-notes.md, "Projection modes").
pub const PROJECT_TEXEL_SIDE: u32 = 3;
/// The widest a texel is, in the smallest voxel spacing the view projects (`texel_side`).
pub const PROJECT_TEXEL_VOXELS: f32 = 0.5;
/// The most texels a frame holds (64 MiB of claims).
const PROJECT_TEXELS_MAX: u64 = 1 << 24;

/// The plan of a bricked frame: its uniforms and decisions.
pub fn plan(
    prep: &Prepared,
    scene: &BrickScene,
    camera: &Camera,
    opts: &RenderOptions,
    limits: &Limits,
) -> Result<(Frame, BrickedPlan)> {
    let sheets = opts.composite != Composite::Splat;
    if !sheets && opts.order != OrderKind::Pbtf {
        return Err(Error::Unsupported(
            "a bricked volume is drawn per splat in PBTF order; the other orders need a classified splat set".into(),
        ));
    }
    let (w, h) = (camera.width, camera.height);
    let budget = limits.budget_bytes;
    let streamed = scene.streams(budget);
    // A projection does not shade (below): only gradient weighting needs the neighbours then.
    let shaded = scene.shading().is_some() && !opts.mode.is_projection();
    if streamed && (shaded || scene.transfer_function().gradient_weight > 0.0) {
        return Err(Error::Unsupported(format!(
            "this volume's store ({} MiB) streams through the {} MiB GPU budget, and gradients (shading, gradient \
             weighting) read neighbouring bricks that a batch does not hold: a budget of at least {} MiB keeps it \
             resident",
            scene.store.bytes() >> 20,
            budget >> 20,
            (scene.store.records.len() as u64 * 8).div_ceil(1 << 20) + 1
        )));
    }
    // Levels of detail, per splat: the pyramid is built from the records on the device when the
    // classification changes (a streamed store's batch by batch: its coarse bricks then need no
    // records). When a streamed store's pyramid would take more than half of what the budget
    // leaves, only the bricks' summaries stay, and each batch rebuilds its coarse bricks' pyramids.
    // A projection reads each voxel's value: coarse cells hold none (their colours are prefiltered).
    let projection = super::Projection::of(opts);
    let lod = opts.lod == Lod::Auto && !sheets && projection.is_none();
    let headers = scene.store.headers.len().max(1);
    let room = budget.saturating_sub(bricked_resident_bytes(scene, budget, w, h));
    let slotted = pyramid_bytes(SLOTTED_LOD_BUFFERS, headers);
    // The pyramid binds as up to PYRAMID_PAGES storage ranges.
    let most_cells = PYRAMID_PAGE as u64 * 4 * PYRAMID_PAGES as u64;
    let fits = headers as u64 * PYRAMID_BYTES <= most_cells;
    if lod && !streamed && !fits {
        // Streaming needs records to stream (a store of uniform bricks has few or none).
        let records = scene.store.records.len() as u64 * 4;
        let stream = if records > 0 {
            format!(
                "a GPU budget under {} MiB streams the store's records and builds the pyramid batch by batch, or ",
                (2 * records) >> 20
            )
        } else {
            String::new()
        };
        return Err(Error::TooLarge(format!(
            "levels of detail: the pyramid of {headers} bricks takes {} MiB, more than the {} MiB its {PYRAMID_PAGES} \
             storage bindings hold; {stream}levels of detail off (--lod off) draw every voxel instead",
            (headers as u64 * PYRAMID_BYTES) >> 20,
            most_cells >> 20
        )));
    }
    let lod_buffers = match (streamed, fits && slotted <= room / 2) {
        (false, _) => LOD_BUFFERS,
        (true, true) => SLOTTED_LOD_BUFFERS,
        (true, false) => STREAMED_LOD_BUFFERS,
    };
    let per_batch = lod && lod_buffers == STREAMED_LOD_BUFFERS;
    let batch_pyramid = if per_batch { PYRAMID_BYTES } else { 0 };
    // The nodes above the brick, after the summaries (resident with them).
    let grid = scene.store.dims.map(|d| d.div_ceil(BRICK));
    let node_levels = if lod && opts.lod_nodes { node_levels(grid, headers) } else { 0 };
    let node_bytes = node_and_cut_words(grid, node_levels) * 4;
    let pyramid = if lod { pyramid_bytes(lod_buffers, headers) + batch_pyramid + node_bytes } else { 0 };
    let least = bricked_min_budget(scene, budget, w, h) + pyramid;
    if budget < least {
        let levels = if lod {
            format!(
                ", its levels-of-detail pyramid ({} MiB; levels of detail off draw without it, from {} MiB)",
                pyramid.div_ceil(1 << 20),
                (least - pyramid).div_ceil(1 << 20)
            )
        } else {
            String::new()
        };
        // A store streamed at this budget keeps its records on the host: the minimum is what stays
        // resident, below the store's size (it said "cannot hold the store", then named less).
        let store = if streamed {
            format!(
                "stream this volume's bricked store ({} MiB, its records kept on the host at this budget): its \
                 headers and summaries",
                scene.store.bytes() >> 20
            )
        } else {
            format!("hold this volume's bricked store ({} MiB)", scene.store.bytes() >> 20)
        };
        return Err(Error::TooLarge(format!(
            "a GPU budget of {} MiB cannot {store}{levels} and one brick of splats at {w}x{h}: the minimum is {} MiB",
            budget >> 20,
            least.div_ceil(1 << 20)
        )));
    }
    let available = budget - bricked_resident_bytes(scene, budget, w, h) - pyramid;
    let range = limits.max_storage_range;
    // A streamed store's records live in a cache of whole-brick slots across frames (half of
    // what the batches leave, one binding at most): a batch uploads only the bricks it lacks.
    let (available, cache_slots) = if streamed {
        let slot = SLOT_WORDS * 4;
        let brick = (BRICK as u64).pow(3) * BATCH_BYTES_PER_SPLAT;
        let most = (range / slot).min(headers as u64).min(u32::MAX as u64).max(1);
        let slots = (available.saturating_sub(brick) / 2 / slot).clamp(1, most);
        (available - slots * slot, slots as u32)
    } else {
        (available, 0)
    };
    // The brick stages' build: one page of store records, the paged reader, or streamed records.
    let build = Records::of(streamed, scene.store.records.len());
    let gradients = gradients_fit(scene, build, range, available);
    let available = available - gradients.unwrap_or(0);
    let mut frame = super::frame_for(&prep.set, camera, opts);
    frame.rect[2] = opts.mode.code();
    let split = crate::order::brick_split(&prep.set, camera, BRICK);
    let mut bf = super::brick_frame(scene, split);
    if projection.is_some() {
        // A projection keeps a voxel's value and whether it shows, not its colour: no shading
        // (its gradients were most of the classification's cost: 60 against 30 ms, bonsai MIP).
        bf.light[3] = 0.0;
    }
    // MIP and MinIP draw each texel's brightest voxel only (project_texels).
    let depth = opts.depth.is_some() || limits.target_depth.is_some();
    let extreme = matches!(opts.mode, Mode::Mip | Mode::Minip);
    let weighted = scene.transfer_function().gradient_weight > 0.0;
    let drawn = extracted_draw(scene.tf_words());
    let side = if extreme
        && !opts.every_voxel
        && drawn
        && !streamed
        && !depth
        && !weighted
        && opts.motion.is_none()
        && !sheets
    {
        texel_side(w, h, least_voxel_pixels(prep.set.grid(), camera))
            .filter(|&s| texel_bytes(w, h, s) * 2 <= available)
            .unwrap_or(0)
    } else {
        0
    };
    bf.split[3] = side;
    let available = available - texel_bytes(w, h, side);
    if lod {
        // The largest bound is none, however many times a view counts an error (view_coherence).
        let error = if opts.lod_error >= crate::options::MAX_LOD_ERROR { f32::INFINITY } else { opts.lod_error };
        (bf.grad[1], bf.grad[2], bf.grad[3]) = (opts.lod_pixels, error, opts.lod_band);
        bf.hi[3] = node_levels;
    }
    let compute = opts.raster == Raster::Compute;
    let direction = opts.direction();
    // Front to back with early termination, later batches drop the bricks that what is drawn
    // already hides: cut the frame into a few batches even when it fits one.
    let terminating = compute
        && !sheets
        && direction == Direction::FrontToBack
        && opts.early_termination > 0.0
        && projection.is_none();
    let blend = if direction == Direction::BackToFront { Blend::Over } else { Blend::Under };
    let sheets = if sheets {
        let axis_sheets = opts.composite == Composite::Sheet;
        let axis = super::sheet_axis(prep.set.grid(), camera);
        let pass = sheet_pass(opts, limits, List::SlabPairs, w, h);
        let layers = pass.layers;
        // The layers (and the compute raster's fixed-point copy) come out of the budget too.
        let layer_bytes = w as u64 * h as u64 * 16 * layers as u64 * (1 + compute as u64);
        let brick_bytes = (BRICK as u64).pow(3) * BATCH_BYTES_PER_SPLAT;
        let Some(left) = available.checked_sub(layer_bytes).filter(|&a| a >= brick_bytes) else {
            return Err(Error::TooLarge(format!(
                "the {} MiB GPU budget cannot hold this volume's store, {layers} summation layers of {w}x{h} and one \
                 brick of splats: raise it (--gpu-budget-mib) by {} MiB, or lower the sheet budget \
                 (voxsplat-lab render --sheet-budget-mib)",
                limits.budget_bytes >> 20,
                (layer_bytes + brick_bytes).saturating_sub(available).div_ceil(1 << 20)
            )));
        };
        Some(BrickedSheets {
            axis_sheets,
            axis,
            split: crate::order::pbtf_split(&prep.set, camera)[axis],
            slab_thickness: opts.slab_thickness,
            available: left,
            pass,
        })
    } else {
        None
    };
    let plan = BrickedPlan {
        streamed,
        lod,
        lod_buffers,
        per_batch,
        batch_pyramid,
        node_levels,
        node_bytes,
        pyramid,
        available,
        cache_slots,
        range,
        build,
        gradients,
        gradient_build: if gradients.is_some() { Records::Gradients } else { build },
        brick_frame: bf,
        compute,
        footprint: match &projection {
            Some(p) => p.builds(opts.raster == Raster::Points).1,
            None => Footprint::Ordered { blend, points: opts.raster == Raster::Points },
        },
        terminating,
        cull_hidden: terminating && opts.cull_hidden_bricks,
        early_termination: opts.early_termination,
        blur: opts.motion.is_some(),
        sheets,
        projection,
        depth: false,
    };
    Ok((frame, plan))
}

impl fmt::Display for BrickedPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.grid();
        let mode = match (&self.sheets, &self.projection) {
            (None, Some(p)) => format!("{} projection (no levels of detail or early termination)", p.mode),
            (None, None) => "composited per splat".to_string(),
            (Some(s), _) if s.axis_sheets => format!("in axis-aligned sheets along axis {}", s.axis),
            (Some(_), _) => "in image-aligned slabs".to_string(),
        };
        writeln!(f, "draw       bricked volume, {x}x{y}x{z} bricks ({} stored), {mode}", self.brick_frame.grid[3])?;
        if self.brick_frame.split[3] > 0 {
            let side = self.brick_frame.split[3];
            writeln!(f, "texels     {side}x{side} a pixel, each drawing its brightest voxel")?;
        }
        let records = match self.build {
            Records::Streamed => "streamed from the host batch by batch",
            Records::Paged => "resident, in pages",
            _ => "resident, one page",
        };
        let differences = if self.gradient_build == Records::Gradients { "; differences precomputed" } else { "" };
        writeln!(f, "records    {records}{differences}")?;
        if self.lod {
            writeln!(
                f,
                "lod        on: {} node levels, {} MiB{}",
                self.node_levels,
                self.pyramid.div_ceil(1 << 20),
                if self.per_batch { ", pyramids built per batch" } else { "" }
            )?;
        } else {
            writeln!(f, "lod        off")?;
        }
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        write!(f, "budget     {:.1} MiB for batches", mib(self.available))?;
        if let Some(g) = self.gradients {
            write!(f, ", {:.1} MiB of precomputed differences", mib(g))?;
        }
        if self.streamed {
            write!(f, ", {} record cache slots", self.cache_slots)?;
        }
        writeln!(f)?;
        match &self.sheets {
            None if self.compute => writeln!(
                f,
                "raster     compute tiles{}",
                if self.terminating {
                    if self.cull_hidden {
                        ", terminating in waves that drop hidden bricks"
                    } else {
                        ", terminating in waves"
                    }
                } else {
                    ""
                }
            ),
            None => writeln!(f, "raster     footprint draw {:?}", self.footprint),
            Some(s) => writeln!(
                f,
                "sums       {}; up to {} layers a batch; {:.1} MiB left for batches",
                if s.pass.compute { "compute fixed-point sums" } else { "footprint sums" },
                s.pass.layers,
                mib(s.available)
            ),
        }
    }
}
