//! THE recording of a frame: [`record_frame`] turns (scene, camera, options) into the frame's
//! sequence of stage dispatches (`crate::stages`), fills, readbacks and sizes, and runs it on an
//! [`Engine`]. Where the host must read a count back mid-frame (the slab starts, the tile lists'
//! starts and the loop-budget word), the engine finishes the work so far; the recording is still
//! written once, for every engine.
mod bricked;
mod gradients;
use crate::builds::{CompositeLayers, Footprint, Only, SheetTiles, SlabBins, TileOrder};
use crate::camera::Camera;
use crate::constants::{
    COMPOSITE_TILE, MAX_GPU_RAY_STEPS, RASTER_TILE_H, RASTER_TILE_W, TILE_BIN_WORKGROUP, TILE_SEGMENT,
};
use crate::error::{Error, Result};
use crate::gpu_types::{BrickPush, FootprintPush, Frame, IsoPush, ProjectPush, ScreenQuad, SlabPush, SplatParams};
use crate::image::ImageF32;
use crate::options::RaycastOptions;
use crate::options::{RenderOptions, StageTime};
use crate::plan::{self, groups_1d, Draw, FramePlan, OrderSource, Prepared, SheetPass, SplatRaster, TileRule};
use crate::stages::{Dispatch, Engine, List, Res, StageId, Workgroup};
use std::time::Instant;

/// Bits of the status word (binding 17): a binning invocation, or a footprint-sum invocation, made
/// llvmpipe's 65535 loop iterations and was cut short (glsl/tile_count.comp, footprint_sum.comp).
pub const LOOP_BUDGET_BINNING: u32 = 1;
/// See `LOOP_BUDGET_BINNING`.
pub const LOOP_BUDGET_SUMS: u32 = 2;

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

impl Recorded {
    /// The frame as `Renderer` returns it, with the raster `Raster::Auto` picked (none for a ray cast).
    pub fn rendered(self, raster: Option<crate::RasterChoice>) -> crate::Rendered {
        crate::Rendered { image: self.image, timings: self.timings, raster, stats: self.stats }
    }
}

/// THE recording of a frame: `prep` drawn from `camera` with `opts` (whose raster is already
/// chosen), on `e`: its plan (`plan::frame`), then the plan recorded.
pub fn record_frame(e: &mut dyn Engine, prep: &Prepared, camera: &Camera, opts: &RenderOptions) -> Result<Recorded> {
    let plan = plan::frame(prep, camera, opts, &e.limits())?;
    record_plan(e, prep, &plan)
}

/// A frame's plan recorded on `e`: the plan and the counts the device reads back decide every
/// dispatch.
pub fn record_plan(e: &mut dyn Engine, prep: &Prepared, plan: &FramePlan) -> Result<Recorded> {
    let set = &prep.set;
    let (w, h) = (plan.width, plan.height);
    let frame = &plan.frame;
    let n = set.len() as u32;
    match &plan.draw {
        Draw::Bricked(b) => {
            let scene = prep
                .bricks
                .as_ref()
                .ok_or_else(|| Error::InvalidArgument("a bricked plan for a dense scene".into()))?;
            bricked::record_bricks(e, prep, scene, plan, b)
        }
        Draw::Splats { rows, order, raster, .. } => {
            begin_dense(e, plan, n)?;
            e.layers(1)?;
            e.ensure(Res::Order, n as u64 * 4)?;
            match order {
                OrderSource::Pbtf => {
                    if n > 0 {
                        e.ensure(Res::RowSplit, *rows as u64 * 4)?;
                        e.ensure(Res::Segments, *rows as u64 * 8)?;
                        e.run(&Dispatch::new(StageId::OrderCount, Only, groups_1d(*rows), List::Order, &[])?)?;
                        e.run(&Dispatch::new(StageId::OrderScan, Only, [1, 1, 1], List::Order, &[])?)?;
                        e.run(&Dispatch::new(StageId::OrderScatter, Only, groups_1d(n), List::Order, &[])?)?;
                    }
                }
                &OrderSource::Host(kind) => {
                    let t = Instant::now();
                    let order = crate::order::visibility_order(set, &plan.camera, kind, plan.direction);
                    e.upload(Res::Order, &order)?;
                    let stage = if e.is_device() { "order_cpu" } else { "order" };
                    e.host_time(stage, t.elapsed().as_secs_f64() * 1e3);
                }
            }
            if n > 0 {
                record_params(e, n)?;
            }
            match raster {
                SplatRaster::Tiles(rule) => {
                    record_tiles(e, frame, rule, w, h, false, false)?;
                    finish(e, plan.background, &[Res::Accum], w, h, false)
                }
                &SplatRaster::Draw(build) => {
                    let push = FootprintPush::default();
                    e.run(&Dispatch::new(
                        StageId::Footprint,
                        build,
                        [0, n, 0],
                        List::Order,
                        bytemuck::bytes_of(&push),
                    )?)?;
                    let slotted = matches!(build, Footprint::Slots(_));
                    let images: &[Res] = if slotted { &[Res::Color, Res::Accum] } else { &[Res::Color] };
                    finish(e, plan.background, images, w, h, false)
                }
            }
        }
        Draw::Surface { push, projection } => record_surface(e, prep, plan, push, projection),
        Draw::Projection { raster, projection, .. } => {
            begin_dense(e, plan, n)?;
            e.layers(1)?;
            // No order: the splats in storage order are the draw list.
            e.ensure(Res::Order, n as u64 * 4)?;
            e.upload(Res::Order, &(0..n).collect::<Vec<u32>>())?;
            if n > 0 {
                record_params(e, n)?;
            }
            let source = match raster {
                SplatRaster::Tiles(rule) => {
                    record_tiles(e, frame, rule, w, h, false, false)?;
                    1
                }
                &SplatRaster::Draw(build) => {
                    let push = FootprintPush::default();
                    let bytes = bytemuck::bytes_of(&push);
                    e.run(&Dispatch::new(StageId::Footprint, build, [0, n, 0], List::Order, bytes)?)?;
                    2
                }
            };
            record_project(e, projection, source, w, h)?;
            finish(e, plan.background, &[Res::Accum], w, h, false)
        }
        Draw::Sheets { pass, .. } => {
            begin_dense(e, plan, n)?;
            if n > 0 {
                record_params(e, n)?;
            }
            record_sheets(e, pass, &pass.batches, plan.background, w, h)
        }
        Draw::Slabs { geometry, pass, .. } => {
            begin_dense(e, plan, n)?;
            if n > 0 {
                record_params(e, n)?;
            }
            let starts = record_slab_bins(e, geometry, SlabBins::Slabs)?;
            let batches = pass.terminated(crate::plan::slab::slab_batches(geometry, &starts, pass.layers)?);
            record_sheets(e, pass, &batches, plan.background, w, h)
        }
    }
}

/// A dense set's frame begins: its uniforms and kernel tables, room for its `n` splats' parameters.
fn begin_dense(e: &mut dyn Engine, plan: &FramePlan, n: u32) -> Result<()> {
    e.begin(&plan.frame, plan.kernel, plan.width, plan.height)?;
    record_host_depth(e, plan)?;
    e.ensure(Res::Params, n as u64 * std::mem::size_of::<SplatParams>() as u64)
}

/// `splat_params` over a dense set's `n` splats.
fn record_params(e: &mut dyn Engine, n: u32) -> Result<()> {
    e.run(&Dispatch::new(StageId::SplatParams, Only, groups_1d(n), List::Order, &[])?)
}

/// The slab binning stages (`SlabBins::AxisSheets`: a bricked batch's axis-aligned sheets) over the splats'
/// parameters: (splat, slab) pairs grouped by slab in visiting order (`Res::SlabPairs`). Returns
/// each slab's first pair (slabs + 1 entries, read back to cut the batches).
fn record_slab_bins(e: &mut dyn Engine, pc: &SlabPush, bins: SlabBins) -> Result<Vec<u32>> {
    let push = bytemuck::bytes_of(pc);
    e.ensure(Res::SlabCounts, pc.slabs as u64 * pc.chunks as u64 * 4)?;
    e.ensure(Res::SlabStart, (pc.slabs as u64 + 1) * 4)?;
    e.run(&Dispatch::new(StageId::SlabCount, bins, groups_1d(pc.chunks), List::Order, push)?)?;
    e.run(&Dispatch::new(StageId::SlabScan, Only, [1, 1, 1], List::Order, push)?)?;
    let starts = e.read(&[(Res::SlabStart, pc.slabs as usize + 1)])?.remove(0);
    let total = starts[pc.slabs as usize] as u64;
    if total > crate::plan::slab::MAX_SLAB_PAIRS {
        let limit = crate::plan::slab::MAX_SLAB_PAIRS;
        return Err(Error::TooLarge(format!("{total} splat-slab pairs (limit {limit}): use thicker slabs")));
    }
    e.ensure(Res::SlabPairs, total * 8)?;
    e.run(&Dispatch::new(StageId::SlabScatter, bins, groups_1d(pc.chunks), List::Order, push)?)?;
    Ok(starts)
}

/// Sheet and slab modes after binning: each batch's sheets summed into layers (footprint draws
/// or, with the compute raster, fixed-point sums), then composited onto the frame in visiting order.
fn record_sheets(
    e: &mut dyn Engine,
    pass: &SheetPass,
    batches: &[plan::Batch],
    background: Option<[f32; 4]>,
    w: u32,
    h: u32,
) -> Result<Recorded> {
    let tiles_pass = plan::sheet_tiles_pay(batches, w, h);
    begin_sheets(e, pass, batches, w, h, tiles_pass)?;
    for b in batches {
        sum_sheets(e, pass, b, b.first_instance, b.instances, false)?;
        composite_sheets(e, pass, b, w, h)?;
    }
    finish(e, background, &[Res::Accum], w, h, pass.compute)
}

/// The sheet modes' images and per-frame state for `batches`; with `tiles_pass`, `sheet_tiles`
/// finds each composite tile's sheet range over the batches' whole list.
fn begin_sheets(
    e: &mut dyn Engine,
    pass: &SheetPass,
    batches: &[plan::Batch],
    w: u32,
    h: u32,
    tiles_pass: bool,
) -> Result<()> {
    let compute = pass.compute;
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
            let build = SheetTiles { mode: SheetPass::mode(first)?, points: pass.points };
            let groups = groups_1d(push.count);
            e.run(&Dispatch::new(StageId::SheetTiles, build, groups, pass.list, bytemuck::bytes_of(&push))?)
        }
    }
}

/// Sum `count` entries of the list from `first` into batch `b`'s layers; `carry`: onto what an
/// earlier part of the batch summed (a bricked volume streamed in parts), else onto cleared layers.
fn sum_sheets(
    e: &mut dyn Engine,
    pass: &SheetPass,
    b: &plan::Batch,
    first: u32,
    count: u32,
    carry: bool,
) -> Result<()> {
    let (list, push) = (pass.list, FootprintPush { first, count, carry: carry as u32, ..b.push });
    if pass.compute {
        if !carry {
            e.fill(Res::Fixed, None, 0)?;
        }
        let mode = SheetPass::mode(b)?;
        e.run(&Dispatch::new(StageId::FootprintSum, mode, groups_1d(count), list, bytemuck::bytes_of(&push))?)
    } else {
        let build = pass.footprint(b)?;
        e.run(&Dispatch::new(StageId::Footprint, build, [first, count, 0], list, bytemuck::bytes_of(&push))?)
    }
}

/// Composite batch `b`'s layers onto the frame.
fn composite_sheets(e: &mut dyn Engine, pass: &SheetPass, b: &plan::Batch, w: u32, h: u32) -> Result<()> {
    let compute = pass.compute;
    let push = plan::composite_push(b, pass.back_to_front, w, h);
    let groups = tile_groups(StageId::Composite, w, h);
    let layers = if compute { CompositeLayers::Fixed } else { CompositeLayers::Float };
    e.run(&Dispatch::new(StageId::Composite, layers, groups, pass.list, bytemuck::bytes_of(&push))?)
}

/// The host's depth buffer, when the plan has one: its texels uploaded and turned into eye-space
/// depth per pixel (`host_depth`), which the footprint stages read.
fn record_host_depth(e: &mut dyn Engine, plan: &FramePlan) -> Result<()> {
    let Some(d) = &plan.depth else { return Ok(()) };
    let pixels = plan.width as u64 * plan.height as u64;
    e.ensure(Res::HostDepthRaw, pixels * 4)?;
    let (format, projection) = match d {
        plan::DepthSource::Buffer(b) => {
            e.upload(Res::HostDepthRaw, &b.texels)?;
            (b.format, b.projection)
        }
        &plan::DepthSource::Target(format, projection) => {
            e.copy_target_depth(Res::HostDepthRaw)?;
            (format, projection)
        }
    };
    e.ensure(Res::HostDepth, pixels * 4)?;
    let push = crate::gpu_types::DepthPush {
        inv_proj: projection.inverse().to_cols_array_2d(),
        width: plan.width,
        height: plan.height,
        format: format.code(),
        pad: 0,
    };
    let groups = tile_groups(StageId::HostDepth, plan.width, plan.height);
    e.run(&Dispatch::new(StageId::HostDepth, Only, groups, List::Order, bytemuck::bytes_of(&push))?)
}

/// Device bytes an isosurface frame holds per surface splat: its cell (8), parameters (80),
/// draw-list entry (4), screen quad (80) and about four tile entries.
pub const SURFACE_BYTES_PER_SPLAT: u64 = 8 + 80 + 4 + 80 + 16;

/// The isosurface: the scene's field uploaded on its first frame; the cells the value crosses
/// counted per row (`iso_count`), their first positions scanned (`iso_scan`) and the total read
/// back; the cells listed (`iso_cells`); a disc per cell (`iso_splats`); the discs blended by depth (`record_tiles`, the
/// `Surface` walk) and lit (`project`).
fn record_surface(
    e: &mut dyn Engine,
    prep: &Prepared,
    plan: &FramePlan,
    push: &IsoPush,
    projection: &crate::plan::Projection,
) -> Result<Recorded> {
    let (w, h) = (plan.width, plan.height);
    e.begin(&plan.frame, plan.kernel, w, h)?;
    record_host_depth(e, plan)?;
    e.layers(1)?;
    let limits = e.limits();
    let field = prep.iso_field()?;
    let values = field.words.len() as u64 * 4;
    if values > limits.max_storage_range || field.bytes() > limits.budget_bytes / 2 {
        return Err(Error::TooLarge(format!(
            "the isosurface's field of {} x {} x {} voxels takes {} MiB: more than half the {} MiB GPU budget or              the device's largest binding ({} MiB)",
            field.dims[0],
            field.dims[1],
            field.dims[2],
            field.bytes() >> 20,
            limits.budget_bytes >> 20,
            limits.max_storage_range >> 20
        )));
    }
    e.ensure(Res::IsoField, values)?;
    e.ensure(Res::IsoRows, field.rows.len() as u64 * 4)?;
    if e.tag(Res::IsoField) != field.id || e.tag(Res::IsoRows) != field.id {
        let t = Instant::now();
        e.upload(Res::IsoField, &field.words)?;
        e.upload(Res::IsoRows, &field.rows)?;
        e.set_tag(Res::IsoField, field.id);
        e.set_tag(Res::IsoRows, field.id);
        e.host_time("iso_field", t.elapsed().as_secs_f64() * 1e3);
    }
    let rows = push.rows;
    e.ensure(Res::IsoCounts, (rows as u64 + 1) * 4)?;
    let bytes = bytemuck::bytes_of(push);
    e.run(&Dispatch::new(StageId::IsoCount, Only, groups_1d(rows), List::Order, bytes)?)?;
    e.run(&Dispatch::new(StageId::IsoScan, Only, [1, 1, 1], List::Order, bytes)?)?;
    let n = e.read(&[(Res::IsoCounts, rows as usize + 1)])?[0][rows as usize];
    let room = limits.budget_bytes.saturating_sub(field.bytes());
    if n as u64 * SURFACE_BYTES_PER_SPLAT > room {
        return Err(Error::TooLarge(format!(
            "the isosurface at {} crosses {n} cells: its splats take {} MiB, more than the {} MiB the GPU budget              leaves beside the field; raise the budget or pick a value that crosses fewer cells",
            push.iso,
            (n as u64 * SURFACE_BYTES_PER_SPLAT) >> 20,
            room >> 20
        )));
    }
    e.ensure(Res::Params, n as u64 * std::mem::size_of::<SplatParams>() as u64)?;
    e.ensure(Res::Order, n as u64 * 4)?;
    e.ensure(Res::IsoCells, n as u64 * 8)?;
    if n > 0 {
        e.run(&Dispatch::new(StageId::IsoCells, Only, groups_1d(rows), List::Order, bytes)?)?;
        let push = IsoPush { splats: n, ..*push };
        e.run(&Dispatch::new(StageId::IsoSplats, Only, groups_1d(n), List::Order, bytemuck::bytes_of(&push))?)?;
    }
    let mut rule = TileRule::plan(n, w, h, crate::order::Direction::FrontToBack, 0.0, false);
    rule.composite.order = TileOrder::Surface;
    rule.composite.depth = plan.depth.is_some();
    record_tiles(e, &plan.frame, &rule, w, h, false, false)?;
    record_project(e, projection, 1, w, h)?;
    let mut recorded = finish(e, plan.background, &[Res::Accum], w, h, false)?;
    recorded.stats.splats = n as u64;
    Ok(recorded)
}

/// A projection's colours (`project`) from its blended (key, weight): in the accumulation image
/// (`source` 1) or the raster target (2), written into the accumulation image.
fn record_project(e: &mut dyn Engine, p: &crate::plan::Projection, source: u32, w: u32, h: u32) -> Result<()> {
    e.ensure(Res::ColorMap, p.color_map.len() as u64 * 16)?;
    e.upload(Res::ColorMap, bytemuck::cast_slice(&p.color_map))?;
    let push =
        ProjectPush { mode: p.mode.code(), width: w, height: h, source, centre: p.centre, iso: p.iso, pad: [0; 2] };
    let groups = tile_groups(StageId::Project, w, h);
    e.run(&Dispatch::new(StageId::Project, Only, groups, List::Order, bytemuck::bytes_of(&push))?)
}

/// The compute tile compositor: the footprints in screen space (unless `made`: a bricked batch's
/// `brick_quads` made them), binned into screen tiles (the counts redone with shorter chunks when
/// an invocation ran out of llvmpipe's loop budget), then each tile's list composited
/// `TILE_SEGMENT` entries per dispatch.
fn record_tiles(
    e: &mut dyn Engine,
    frame: &Frame,
    rule: &TileRule,
    w: u32,
    h: u32,
    carry: bool,
    made: bool,
) -> Result<()> {
    let (tx, ty) = crate::plan::tile_grid(frame);
    let tiles = tx as u64 * ty as u64;
    let n = rule.push.count;
    let mut push = FootprintPush { carry: carry as u32, ..rule.push };
    let most = rule.most_chunks;
    e.ensure(Res::Quads, n as u64 * std::mem::size_of::<ScreenQuad>() as u64)?;
    e.ensure(Res::TileStart, (tiles + 1) * 4)?;
    e.ensure(Res::Status, 4)?;
    if !made {
        let bytes = bytemuck::bytes_of(&push);
        e.run(&Dispatch::new(StageId::ScreenQuads, rule.pages, groups_1d(n), List::Order, bytes)?)?;
    }
    let starts = loop {
        let cells = crate::raster::check_tile_cells(tiles, push.chunks)?;
        e.ensure(Res::TileCounts, cells * 4)?;
        e.fill(Res::TileCounts, None, 0)?;
        e.fill(Res::Status, None, 0)?;
        let bytes = bytemuck::bytes_of(&push);
        e.run(&Dispatch::new(StageId::TileCount, rule.pages, tile_chunk_groups(&push), List::Order, bytes)?)?;
        e.run(&Dispatch::new(StageId::TileScan, Only, groups_1d(tiles as u32), List::Order, bytes)?)?;
        e.run(&Dispatch::new(StageId::TileOffsets, Only, [1, 1, 1], List::Order, bytes)?)?;
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
    e.run(&Dispatch::new(StageId::TileScatter, rule.pages, tile_chunk_groups(&push), List::Order, bytes)?)?;
    let build = rule.composite;
    // The isosurface walks the lists twice: each pixel's visible depth, then the discs at it.
    let passes = if build.order == TileOrder::Surface {
        let depth = crate::builds::TileComposite { order: TileOrder::SurfaceDepth, ..build };
        vec![(depth, push), (build, FootprintPush { carry: 1, ..push })]
    } else {
        vec![(build, push)]
    };
    for (build, push) in passes {
        for segment in 0..longest.div_ceil(TILE_SEGMENT).max(1) {
            let push = FootprintPush { first: segment, ..push };
            let groups = tile_groups(StageId::TileComposite, w, h);
            e.run(&Dispatch::new(StageId::TileComposite, build, groups, List::Order, bytemuck::bytes_of(&push))?)?;
        }
    }
    Ok(())
}

/// Read the frame's image, the mean of `images` (one, or the two time slots of `Pass::Slots`), and,
/// after compute sheet sums, the status word; then the timings. Over a background, or into a host's
/// image (`Engine::target_linear`), `present` first makes the final image; a host's image then
/// receives it on the device and nothing is read but the status word; over a host's image
/// (`Engine::target_over`) `present` composites the frame over a copy of what it held.
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
        let mut sources = images.iter().fold(0, |m, &r| m | if r == Res::Accum { 1 } else { 2 });
        if let Some(format) = e.target_over() {
            e.ensure(Res::HostColor, w as u64 * h as u64 * format.texel_bytes() as u64)?;
            e.copy_target_color(Res::HostColor)?;
            sources |= crate::plan::over_bits(format);
        }
        let push = crate::plan::present_push(background, sources, linear.unwrap_or(false), w, h);
        let groups = tile_groups(StageId::Present, w, h);
        e.run(&Dispatch::new(StageId::Present, Only, groups, List::Order, bytemuck::bytes_of(&push))?)?;
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
    let projection = opts.mode.is_projection();
    e.prepare_field(opts.brick, opts.mode)?;
    let words: &[u32] = bytemuck::cast_slice(bytemuck::bytes_of(&params));
    e.ensure(Res::RaycastParams, words.len() as u64 * 4)?;
    e.upload(Res::RaycastParams, words)?;
    let groups = tile_groups(StageId::Raycast, w, h);
    e.run(&Dispatch::new(StageId::Raycast, Only, groups, List::Order, &[])?)?;
    if projection {
        // The rays' (key, weight) mapped as the splats' are; one voxel length of coverage is opaque.
        let p = crate::plan::Projection {
            mode: opts.mode,
            color_map: crate::plan::mode_color_map(opts.colormap.as_ref(), opts.mode),
            centre: 1.0,
            iso: opts.iso.unwrap_or(0.0),
        };
        record_project(e, &p, 1, w, h)?;
    }
    finish(e, None, &[Res::Accum], w, h, false)
}
