//! THE recording of a frame: [`record_frame`] turns (scene, camera, options) into the frame's
//! sequence of stage dispatches (`crate::stages`), fills, readbacks and sizes, and runs it on an
//! [`Engine`]. Where the host must read a count back mid-frame (the slab starts, the tile lists'
//! starts and the loop-budget word), the engine finishes the work so far; the recording is still
//! written once, for every engine.
mod bricked;
mod gradients;
use crate::camera::Camera;
use crate::constants::{
    COMPOSITE_TILE, MAX_GPU_RAY_STEPS, RASTER_TILE_H, RASTER_TILE_W, RECORD_PAGE, SPLAT_PAGE, TILE_BIN_WORKGROUP,
    TILE_SEGMENT,
};
use crate::dispatch::Blend;
use crate::error::{Error, Result};
use crate::gpu_types::{
    BrickPush, FootprintPush, Frame, ScreenQuad, SlabPush, SplatParams, SHEET_MODE_BINNED, SHEET_MODE_SLAB,
    SHEET_MODE_SPLAT,
};
use crate::image::ImageF32;
use crate::options::RaycastOptions;
use crate::options::{Composite, Lod, RenderOptions, StageTime};
use crate::order::{Direction, OrderKind};
use crate::plan::{self, groups_1d, Prepared};
use crate::raster::Raster;
use crate::stages::{Dispatch, Engine, List, Res, StageId, Workgroup};
pub use bricked::{
    bricked_min_budget, bricked_resident_bytes, BATCH_BYTES_PER_SPLAT, HIDDEN_BATCHES, HIDDEN_BATCH_MIN,
};
use std::time::Instant;

/// Bits of the status word (binding 17): a binning invocation, or a footprint-sum invocation, made
/// llvmpipe's 65535 loop iterations and was cut short (glsl/tile_count.comp, footprint_sum.comp).
pub const LOOP_BUDGET_BINNING: u32 = 1;
/// See `LOOP_BUDGET_BINNING`.
pub const LOOP_BUDGET_SUMS: u32 = 2;

/// 1 where a scene of `n` splats fits one page of splat records (the `ONE_PAGE` builds read only
/// that page: llvmpipe runs both sides of the paged reader's branch), else 0.
pub fn one_page(n: u32) -> usize {
    usize::from(n <= SPLAT_PAGE)
}

/// The two-slot footprint draw's variant (`Pass::Slots`, after the others in stages.rs).
pub fn footprint_slots_variant(blend: Blend) -> usize {
    if blend == Blend::Over {
        10
    } else {
        11
    }
}

/// The footprint draw's variant.
pub fn footprint_variant(blend: Blend, points: bool, mode: u32) -> usize {
    match (blend, mode) {
        (Blend::Add, m) if m == SHEET_MODE_BINNED => 8 + points as usize,
        (Blend::Over, _) => 4 * points as usize,
        (Blend::Under, _) => 1 + 4 * points as usize,
        (Blend::Add, m) if m == SHEET_MODE_SLAB => 3 + 4 * points as usize,
        (Blend::Add, _) => 2 + 4 * points as usize,
    }
}

/// The tile compositor's variant for a scene of `n` splats, the frame's push constants and
/// whether it is motion-blurred.
pub fn tile_composite_variant(n: u32, push: &FootprintPush, blur: bool) -> usize {
    let btf = push.back_to_front != 0;
    let mode = if btf {
        0
    } else if push.occluded > 0.0 {
        2
    } else {
        1
    };
    (one_page(n) * 3 + mode) * 2 + usize::from(blur)
}

/// Workgroups of the tile binning passes that walk the draw list chunk by chunk.
fn tile_chunk_groups(push: &FootprintPush) -> [u32; 3] {
    [push.chunks.div_ceil(TILE_BIN_WORKGROUP), 1, 1]
}

/// Workgroups covering a `width` x `height` image in tiles.
fn tile_groups(stage: StageId, width: u32, height: u32) -> [u32; 3] {
    match stage.desc().workgroup {
        Workgroup::Tile(tw, th) => [width.div_ceil(tw), height.div_ceil(th), 1],
        _ => [1, 1, 1],
    }
}

/// A frame's words of an image resource (RGBA32F).
fn image_words(width: u32, height: u32) -> usize {
    width as usize * height as usize * 4
}

/// The output of [`record_frame`].
pub struct Recorded {
    /// The frame.
    pub image: ImageF32,
    /// Per-stage times.
    pub timings: Vec<StageTime>,
    /// What a bricked volume's frame drew and culled.
    pub stats: crate::options::FrameStats,
}

/// THE recording of a frame: `prep` drawn from `camera` with `opts` (whose raster is already
/// chosen), on `e`.
pub fn record_frame(e: &mut dyn Engine, prep: &Prepared, camera: &Camera, opts: &RenderOptions) -> Result<Recorded> {
    camera.validate()?;
    let slotted = opts.slotted();
    if let Some(scene) = &prep.bricks {
        if slotted {
            return Err(Error::Unsupported(
                "the slotted blur draws dense splat sets; a bricked volume takes splat:tapered".into(),
            ));
        }
        return bricked::record_bricks(e, prep, scene, camera, opts);
    }
    let set = &prep.set;
    let (w, h) = (camera.width, camera.height);
    let direction = opts.direction();
    let btf = direction == Direction::BackToFront;
    let frame = plan::frame_for(set, camera, opts);
    let n = set.len() as u32;
    let rows = (set.row_start().len() - 1) as u32;
    let compute = opts.raster == Raster::Compute;
    let points = opts.raster == Raster::Points;
    e.begin(&frame, opts.kernel, w, h)?;
    e.ensure(Res::Params, n as u64 * std::mem::size_of::<SplatParams>() as u64)?;
    let params = || Dispatch::new(StageId::SplatParams, 0, groups_1d(n), List::Order, &[]);

    if opts.composite == Composite::Splat {
        e.layers(1)?;
        e.ensure(Res::Order, n as u64 * 4)?;
        if opts.order == OrderKind::Pbtf {
            if n > 0 {
                e.ensure(Res::RowSplit, rows as u64 * 4)?;
                e.ensure(Res::Segments, rows as u64 * 8)?;
                e.run(&Dispatch::new(StageId::OrderCount, 0, groups_1d(rows), List::Order, &[]))?;
                e.run(&Dispatch::new(StageId::OrderScan, 0, [1, 1, 1], List::Order, &[]))?;
                e.run(&Dispatch::new(StageId::OrderScatter, 0, groups_1d(n), List::Order, &[]))?;
            }
        } else {
            let t = Instant::now();
            let order = crate::order::visibility_order(set, camera, opts.order, direction);
            e.upload(Res::Order, &order)?;
            let stage = if e.is_device() { "order_cpu" } else { "order" };
            e.host_time(stage, t.elapsed().as_secs_f64() * 1e3);
        }
        if n > 0 {
            e.run(&params())?;
        }
        if compute {
            record_tiles(e, &frame, n, opts, w, h, false)?;
            return finish(e, opts.background, &[Res::Accum], w, h, false);
        }
        let blend = if btf { Blend::Over } else { Blend::Under };
        let variant =
            if slotted { footprint_slots_variant(blend) } else { footprint_variant(blend, points, SHEET_MODE_SPLAT) };
        let push = FootprintPush::default();
        e.run(&Dispatch::new(StageId::Footprint, variant, [0, n, 0], List::Order, bytemuck::bytes_of(&push)))?;
        let images: &[Res] = if slotted { &[Res::Color, Res::Accum] } else { &[Res::Color] };
        return finish(e, opts.background, images, w, h, false);
    }

    // Sheet and slab modes: summation layers in batches, composited in visiting order.
    let layers = sheet_layers(e, opts, w, h);
    let (list, batches) = if opts.composite == Composite::Sheet {
        if n > 0 {
            e.run(&params())?;
        }
        let (axis, batches) = plan::sheet_plan(prep, camera, direction, layers);
        (List::Slices(axis as u8), batches)
    } else {
        let pc = crate::slab::slab_geometry(&frame, set.grid(), set.len(), opts.slab_thickness, direction)?;
        if n > 0 {
            e.run(&params())?;
        }
        let starts = record_slab_bins(e, &pc, 0)?;
        (List::SlabPairs, crate::slab::slab_batches(&pc, &starts, layers)?)
    };
    record_sheets(e, list, batches, opts, w, h)
}

/// The slab binning stages (`variant` 1: a bricked batch's axis-aligned sheets) over the splats'
/// parameters: (splat, slab) pairs grouped by slab in visiting order (`Res::SlabPairs`). Returns
/// each slab's first pair (slabs + 1 entries, read back to cut the batches).
fn record_slab_bins(e: &mut dyn Engine, pc: &SlabPush, variant: usize) -> Result<Vec<u32>> {
    let push = bytemuck::bytes_of(pc);
    e.ensure(Res::SlabCounts, pc.slabs as u64 * pc.chunks as u64 * 4)?;
    e.ensure(Res::SlabStart, (pc.slabs as u64 + 1) * 4)?;
    e.run(&Dispatch::new(StageId::SlabCount, variant, groups_1d(pc.chunks), List::Order, push))?;
    e.run(&Dispatch::new(StageId::SlabScan, 0, [1, 1, 1], List::Order, push))?;
    let starts = e.read(&[(Res::SlabStart, pc.slabs as usize + 1)])?.remove(0);
    let total = starts[pc.slabs as usize] as u64;
    if total > crate::slab::MAX_SLAB_PAIRS {
        let limit = crate::slab::MAX_SLAB_PAIRS;
        return Err(Error::TooLarge(format!("{total} splat-slab pairs (limit {limit}): use thicker slabs")));
    }
    e.ensure(Res::SlabPairs, total * 8)?;
    e.run(&Dispatch::new(StageId::SlabScatter, variant, groups_1d(pc.chunks), List::Order, push))?;
    Ok(starts)
}

/// Summation layers a sheet batch may use at `w` x `h`: the options' memory budget, the device's
/// layer limit and, for the fixed-point layers (one storage binding), its range.
fn sheet_layers(e: &dyn Engine, opts: &RenderOptions, w: u32, h: u32) -> u32 {
    let limits = e.limits();
    let layers = opts.batch_layers(w, h).min(limits.max_layers.max(1));
    let layer_bytes = w as u64 * h as u64 * 16;
    if opts.raster == Raster::Compute {
        layers.min((limits.max_storage_range / layer_bytes.max(1)).clamp(1, u32::MAX as u64) as u32)
    } else {
        layers
    }
}

/// Sheet and slab modes after binning: each batch's sheets summed into layers (footprint draws
/// or, with the compute raster, fixed-point sums), then composited onto the frame in visiting order.
fn record_sheets(
    e: &mut dyn Engine,
    list: List,
    mut batches: Vec<plan::Batch>,
    opts: &RenderOptions,
    w: u32,
    h: u32,
) -> Result<Recorded> {
    plan::set_early_termination(opts, &mut batches);
    let tiles_pass = plan::sheet_tiles_pay(&batches, w, h);
    begin_sheets(e, list, &batches, opts, w, h, tiles_pass)?;
    for b in &batches {
        sum_sheets(e, list, b, opts, b.first_instance, b.instances, false)?;
        composite_sheets(e, list, b, opts, w, h)?;
    }
    finish(e, opts.background, &[Res::Accum], w, h, opts.raster == Raster::Compute)
}

/// The sheet modes' images and per-frame state for `batches`; with `tiles_pass`, `sheet_tiles`
/// finds each composite tile's sheet range over the batches' whole list.
fn begin_sheets(
    e: &mut dyn Engine,
    list: List,
    batches: &[plan::Batch],
    opts: &RenderOptions,
    w: u32,
    h: u32,
    tiles_pass: bool,
) -> Result<()> {
    let compute = opts.raster == Raster::Compute;
    // Allocate only as many layers as the largest batch needs.
    let layers = batches.iter().map(|b| b.layers).max().unwrap_or(1);
    e.layers(layers)?;
    let tiles = w.div_ceil(COMPOSITE_TILE) as u64 * h.div_ceil(COMPOSITE_TILE) as u64;
    e.ensure(Res::Occlusion, tiles * 4)?;
    e.ensure(Res::SheetTiles, tiles * 8)?;
    e.fill(Res::Accum, None, 0)?;
    e.fill(Res::Occlusion, None, 1.0f32.to_bits())?;
    if compute {
        e.ensure(Res::Fixed, w as u64 * h as u64 * 16 * layers as u64)?;
        e.ensure(Res::Status, 4)?;
        e.fill(Res::Status, None, 0)?;
    }
    let halves = |e: &mut dyn Engine, range: [u32; 2]| -> Result<()> {
        e.fill(Res::SheetTiles, Some((0, tiles)), range[0])?;
        e.fill(Res::SheetTiles, Some((tiles, tiles)), range[1])
    };
    match batches.first().filter(|_| tiles_pass) {
        None => halves(e, plan::ALL_SHEETS),
        Some(first) => {
            // No sheet reaches any tile until the pass says so.
            halves(e, [u32::MAX, 0])?;
            let push = plan::sheet_tiles_push(batches, first);
            let variant = 2 * (first.push.sheet_mode as usize - 1) + (opts.raster == Raster::Points) as usize;
            let groups = groups_1d(push.count);
            e.run(&Dispatch::new(StageId::SheetTiles, variant, groups, list, bytemuck::bytes_of(&push)))
        }
    }
}

/// Sum `count` entries of the list from `first` into batch `b`'s layers; `carry`: onto what an
/// earlier part of the batch summed (a bricked volume streamed in parts), else onto cleared layers.
fn sum_sheets(
    e: &mut dyn Engine,
    list: List,
    b: &plan::Batch,
    opts: &RenderOptions,
    first: u32,
    count: u32,
    carry: bool,
) -> Result<()> {
    let push = FootprintPush { first, count, carry: carry as u32, ..b.push };
    if opts.raster == Raster::Compute {
        if !carry {
            e.fill(Res::Fixed, None, 0)?;
        }
        let variant = b.push.sheet_mode as usize - 1;
        e.run(&Dispatch::new(StageId::FootprintSum, variant, groups_1d(count), list, bytemuck::bytes_of(&push)))
    } else {
        let variant = footprint_variant(Blend::Add, opts.raster == Raster::Points, b.push.sheet_mode);
        e.run(&Dispatch::new(StageId::Footprint, variant, [first, count, 0], list, bytemuck::bytes_of(&push)))
    }
}

/// Composite batch `b`'s layers onto the frame.
fn composite_sheets(
    e: &mut dyn Engine,
    list: List,
    b: &plan::Batch,
    opts: &RenderOptions,
    w: u32,
    h: u32,
) -> Result<()> {
    let compute = opts.raster == Raster::Compute;
    let push = plan::composite_push(b, opts.direction() == Direction::BackToFront, w, h);
    let groups = tile_groups(StageId::Composite, w, h);
    e.run(&Dispatch::new(StageId::Composite, compute as usize, groups, list, bytemuck::bytes_of(&push)))
}

/// The compute tile compositor: bin the draw list into screen tiles (redoing the counts with
/// shorter chunks when an invocation ran out of llvmpipe's loop budget), then composite each
/// tile's list `TILE_SEGMENT` entries per dispatch.
fn record_tiles(
    e: &mut dyn Engine,
    frame: &Frame,
    n: u32,
    opts: &RenderOptions,
    w: u32,
    h: u32,
    carry: bool,
) -> Result<()> {
    let (tx, ty) = crate::plan::tile_grid(frame);
    let tiles = tx as u64 * ty as u64;
    let mut push = FootprintPush { carry: carry as u32, ..plan::tile_push(opts, n, w, h) };
    let most = (crate::raster::MAX_TILE_CELLS / tiles.max(1)).min(push.count.max(1) as u64) as u32;
    e.ensure(Res::Quads, n as u64 * std::mem::size_of::<ScreenQuad>() as u64)?;
    e.ensure(Res::TileStart, (tiles + 1) * 4)?;
    e.ensure(Res::Status, 4)?;
    let starts = loop {
        let cells = crate::raster::check_tile_cells(tiles, push.chunks)?;
        e.ensure(Res::TileCounts, cells * 4)?;
        e.fill(Res::TileCounts, None, 0)?;
        e.fill(Res::Status, None, 0)?;
        let bytes = bytemuck::bytes_of(&push);
        e.run(&Dispatch::new(StageId::TileCount, one_page(n), tile_chunk_groups(&push), List::Order, bytes))?;
        e.run(&Dispatch::new(StageId::TileScan, 0, groups_1d(tiles as u32), List::Order, bytes))?;
        e.run(&Dispatch::new(StageId::TileOffsets, 0, [1, 1, 1], List::Order, bytes))?;
        let mut back = e.read(&[(Res::TileStart, tiles as usize + 1), (Res::Status, 1)])?;
        let spent = back[1][0] & LOOP_BUDGET_BINNING != 0;
        crate::raster::check_tile_entries(back[0][tiles as usize] as u64)?;
        if !spent {
            break back.swap_remove(0);
        }
        if push.chunks >= most {
            return Err(Error::TooLarge(format!(
                "the compute tile binning ran out of llvmpipe's 65535 loop iterations per invocation even in {} \
                 chunks (footprints covering very many {RASTER_TILE_W}x{RASTER_TILE_H}-pixel tiles): draw this \
                 frame with --raster graphics or points",
                push.chunks
            )));
        }
        push.chunks = push.chunks.saturating_mul(4).min(most);
    };
    let total = starts[tiles as usize] as u64;
    let longest = starts.windows(2).map(|w| w[1].saturating_sub(w[0])).max().unwrap_or(0);
    e.ensure(Res::TileEntries, total * 4)?;
    let bytes = bytemuck::bytes_of(&push);
    e.run(&Dispatch::new(StageId::TileScatter, one_page(n), tile_chunk_groups(&push), List::Order, bytes))?;
    let variant = tile_composite_variant(n, &push, opts.motion.is_some());
    for segment in 0..longest.div_ceil(TILE_SEGMENT).max(1) {
        let push = FootprintPush { first: segment, ..push };
        let groups = tile_groups(StageId::TileComposite, w, h);
        e.run(&Dispatch::new(StageId::TileComposite, variant, groups, List::Order, bytemuck::bytes_of(&push)))?;
    }
    Ok(())
}

/// Read the frame's image, the mean of `images` (one, or the two time slots of `Pass::Slots`), and,
/// after compute sheet sums, the status word; then the timings. Over a background, or into a host's
/// image (`Engine::target_linear`), `present` first makes the final image; a host's image then
/// receives it on the device and nothing is read but the status word.
fn finish(
    e: &mut dyn Engine,
    background: Option<[f32; 4]>,
    images: &[Res],
    w: u32,
    h: u32,
    status: bool,
) -> Result<Recorded> {
    let linear = e.target_linear();
    let images = if background.is_some() || linear.is_some() {
        let sources = images.iter().fold(0, |m, &r| m | if r == Res::Accum { 1 } else { 2 });
        let push = crate::plan::present_push(background, sources, linear.unwrap_or(false), w, h);
        let groups = tile_groups(StageId::Present, w, h);
        e.run(&Dispatch::new(StageId::Present, 0, groups, List::Order, bytemuck::bytes_of(&push)))?;
        &[Res::Accum][..]
    } else {
        images
    };
    if linear.is_some() {
        e.deliver()?;
        if status {
            check_status(e.read(&[(Res::Status, 1)])?[0][0])?;
        }
        let timings = e.finish()?;
        return Ok(Recorded {
            image: ImageF32 { width: w, height: h, pixels: Vec::new() },
            timings,
            stats: Default::default(),
        });
    }
    let mut what: Vec<(Res, usize)> = images.iter().map(|&r| (r, image_words(w, h))).collect();
    if status {
        what.push((Res::Status, 1));
    }
    let back = e.read(&what)?;
    let (layers, rest) = back.split_at(images.len());
    if status {
        check_status(rest[0][0])?;
    }
    let at = |l: &[u32], i: usize| f32::from_bits(l[i]);
    let scale = 1.0 / images.len() as f32;
    let pixels = (0..layers[0].len() / 4)
        .map(|p| {
            [0, 1, 2, 3].map(|c| {
                let sum = layers[1..].iter().fold(at(&layers[0], 4 * p + c), |acc, l| acc + at(l, 4 * p + c));
                if layers.len() > 1 {
                    sum * scale
                } else {
                    sum
                }
            })
        })
        .collect();
    let timings = e.finish()?;
    Ok(Recorded { image: ImageF32 { width: w, height: h, pixels }, timings, stats: Default::default() })
}

/// The compute sheet sums' status word: a footprint too large for llvmpipe's loop budget.
fn check_status(word: u32) -> Result<()> {
    if word & LOOP_BUDGET_SUMS != 0 {
        return Err(Error::TooLarge(
            "a footprint larger than about 240 x 240 pixels: the compute sheet sums ran out of llvmpipe's 65535 \
             loop iterations per invocation; draw this frame with --raster graphics or points"
                .into(),
        ));
    }
    Ok(())
}

/// THE recording of the reference ray caster (`raycast.comp` and its mirror): `prep` cast from
/// `camera` with `opts` (at full size: the caller resamples a render scale).
pub fn record_raycast(e: &mut dyn Engine, prep: &Prepared, camera: &Camera, opts: &RaycastOptions) -> Result<Recorded> {
    camera.validate()?;
    let params = crate::plan::raycast_params(&prep.set, camera, opts);
    let g = prep.set.grid();
    let [lo, hi] = g.world_box(glam::Vec3::splat(-1.0), glam::Vec3::from(g.dims.map(|d| d as f32)));
    let diagonal = hi.distance(lo);
    let steps = (diagonal / params.box_min[3]).ceil();
    if e.is_device() && steps > MAX_GPU_RAY_STEPS as f32 {
        return Err(Error::TooLarge(format!(
            "rays of up to {steps} samples: the GPU ray caster takes at most {MAX_GPU_RAY_STEPS} per ray (llvmpipe \
             ends a shader's loops after 65535 iterations); use a longer step or the CPU backend"
        )));
    }
    // Both engines refuse rays that max_steps would end early (a silently faint picture otherwise).
    if steps.is_nan() || steps > opts.max_steps as f32 {
        return Err(Error::TooLarge(format!(
            "rays of up to {steps} samples at step {}: more than max_steps ({}); use a longer step",
            opts.step, opts.max_steps
        )));
    }
    let (w, h) = (camera.width, camera.height);
    let frame = plan::frame_for(&prep.set, camera, &RenderOptions::default());
    e.begin(&frame, crate::kernel::Kernel::Gaussian, w, h)?;
    e.prepare_field(opts.brick)?;
    let words: &[u32] = bytemuck::cast_slice(bytemuck::bytes_of(&params));
    e.ensure(Res::RaycastParams, words.len() as u64 * 4)?;
    e.upload(Res::RaycastParams, words)?;
    let groups = tile_groups(StageId::Raycast, w, h);
    e.run(&Dispatch::new(StageId::Raycast, 0, groups, List::Order, &[]))?;
    finish(e, None, &[Res::Accum], w, h, false)
}
