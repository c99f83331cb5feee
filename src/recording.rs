//! THE recording of a frame: [`record_frame`] turns (scene, camera, options) into the frame's
//! sequence of stage dispatches (`crate::stages`), fills, readbacks and sizes, and runs it on an
//! [`Engine`]. Where the host must read a count back mid-frame (the slab starts, the tile lists'
//! starts and the loop-budget word), the engine finishes the work so far; the recording is still
//! written once, for every engine.
use crate::bricks::{BrickScene, BRICK};
use crate::camera::Camera;
use crate::constants::{
    COMPOSITE_TILE, MAX_GPU_RAY_STEPS, MAX_GPU_SPLATS, RASTER_TILE_H, RASTER_TILE_W, RECORD_PAGE, SPLAT_PAGE,
    TILE_BIN_WORKGROUP, TILE_SEGMENT,
};
use crate::cpu::footprint::Blend;
use crate::cpu::raycast::RaycastOptions;
use crate::error::{Error, Result};
use crate::gpu_types::{BrickPush, FootprintPush, Frame, ScreenQuad, SplatParams, SHEET_MODE_SLAB, SHEET_MODE_SPLAT};
use crate::image::ImageF32;
use crate::options::{Composite, RenderOptions, StageTime};
use crate::order::{Direction, OrderKind};
use crate::plan::{self, groups_1d, Prepared};
use crate::raster::Raster;
use crate::stages::{Dispatch, Engine, List, Res, StageId, Workgroup};
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

/// The footprint draw's variant.
pub fn footprint_variant(blend: Blend, points: bool, mode: u32) -> usize {
    let base = match (blend, mode) {
        (Blend::Over, _) => 0,
        (Blend::Under, _) => 1,
        (Blend::Add, m) if m == SHEET_MODE_SLAB => 3,
        (Blend::Add, _) => 2,
    };
    base + 4 * points as usize
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
}

/// THE recording of a frame: `prep` drawn from `camera` with `opts` (whose raster is already
/// chosen), on `e`.
pub fn record_frame(e: &mut dyn Engine, prep: &Prepared, camera: &Camera, opts: &RenderOptions) -> Result<Recorded> {
    camera.validate()?;
    if let Some(scene) = &prep.bricks {
        return record_bricks(e, prep, scene, camera, opts);
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
            return finish(e, Res::Accum, w, h, false);
        }
        let blend = if btf { Blend::Over } else { Blend::Under };
        let variant = footprint_variant(blend, points, SHEET_MODE_SPLAT);
        let push = FootprintPush::default();
        e.run(&Dispatch::new(StageId::Footprint, variant, [0, n, 0], List::Order, bytemuck::bytes_of(&push)))?;
        return finish(e, Res::Color, w, h, false);
    }

    // Sheet and slab modes: summation layers in batches, composited in visiting order.
    let limits = e.limits();
    let mut layers = opts.batch_layers(w, h).min(limits.max_layers.max(1));
    let layer_bytes = w as u64 * h as u64 * 16;
    if compute {
        // The fixed-point layers are one storage binding: no more than its range allows.
        layers = layers.min((limits.max_storage_range / layer_bytes.max(1)).clamp(1, u32::MAX as u64) as u32);
    }
    let (list, mut batches) = if opts.composite == Composite::Sheet {
        if n > 0 {
            e.run(&params())?;
        }
        let (axis, batches) = plan::sheet_plan(prep, camera, direction, layers);
        (List::Slices(axis as u8), batches)
    } else {
        let pc = crate::slab::slab_geometry(&frame, set.grid(), set.len(), opts.slab_thickness, direction)?;
        let push = bytemuck::bytes_of(&pc);
        e.ensure(Res::SlabCounts, pc.slabs as u64 * pc.chunks as u64 * 4)?;
        e.ensure(Res::SlabStart, (pc.slabs as u64 + 1) * 4)?;
        if n > 0 {
            e.run(&params())?;
        }
        e.run(&Dispatch::new(StageId::SlabCount, 0, groups_1d(pc.chunks), List::Order, push))?;
        e.run(&Dispatch::new(StageId::SlabScan, 0, [1, 1, 1], List::Order, push))?;
        let starts = e.read(&[(Res::SlabStart, pc.slabs as usize + 1)])?.remove(0);
        let batches = crate::slab::slab_batches(&pc, &starts, layers)?;
        e.ensure(Res::SlabPairs, starts[pc.slabs as usize] as u64 * 8)?;
        e.run(&Dispatch::new(StageId::SlabScatter, 0, groups_1d(pc.chunks), List::Order, push))?;
        (List::SlabPairs, batches)
    };
    plan::set_early_termination(opts, &mut batches);
    // Allocate only as many layers as the largest batch needs.
    let layers = batches.iter().map(|b| b.layers).max().unwrap_or(1);
    e.layers(layers)?;
    let tiles = w.div_ceil(COMPOSITE_TILE) as u64 * h.div_ceil(COMPOSITE_TILE) as u64;
    e.ensure(Res::Occlusion, tiles * 4)?;
    e.ensure(Res::SheetTiles, tiles * 8)?;
    e.fill(Res::Accum, None, 0)?;
    e.fill(Res::Occlusion, None, 1.0f32.to_bits())?;
    if compute {
        e.ensure(Res::Fixed, layer_bytes * layers as u64)?;
        e.ensure(Res::Status, 4)?;
        e.fill(Res::Status, None, 0)?;
    }
    let halves = |e: &mut dyn Engine, range: [u32; 2]| -> Result<()> {
        e.fill(Res::SheetTiles, Some((0, tiles)), range[0])?;
        e.fill(Res::SheetTiles, Some((tiles, tiles)), range[1])
    };
    match batches.first().filter(|_| plan::sheet_tiles_pay(&batches, w, h)) {
        None => halves(e, plan::ALL_SHEETS)?,
        Some(first) => {
            // No sheet reaches any tile until the pass says so.
            halves(e, [u32::MAX, 0])?;
            let slab = first.push.sheet_mode == SHEET_MODE_SLAB;
            let push = plan::sheet_tiles_push(&batches, first);
            let variant = 2 * slab as usize + points as usize;
            let groups = groups_1d(push.count);
            e.run(&Dispatch::new(StageId::SheetTiles, variant, groups, list, bytemuck::bytes_of(&push)))?;
        }
    }
    for b in &batches {
        let slab = b.push.sheet_mode == SHEET_MODE_SLAB;
        if compute {
            e.fill(Res::Fixed, None, 0)?;
            let push = FootprintPush { first: b.first_instance, count: b.instances, ..b.push };
            let groups = groups_1d(b.instances);
            e.run(&Dispatch::new(StageId::FootprintSum, slab as usize, groups, list, bytemuck::bytes_of(&push)))?;
        } else {
            let variant = footprint_variant(Blend::Add, points, b.push.sheet_mode);
            let groups = [b.first_instance, b.instances, 0];
            e.run(&Dispatch::new(StageId::Footprint, variant, groups, list, bytemuck::bytes_of(&b.push)))?;
        }
        let push = plan::composite_push(b, btf, w, h);
        let groups = tile_groups(StageId::Composite, w, h);
        e.run(&Dispatch::new(StageId::Composite, compute as usize, groups, list, bytemuck::bytes_of(&push)))?;
    }
    finish(e, Res::Accum, w, h, compute)
}

/// Device bytes a bricked frame holds per splat of a batch: its parameters (80), order entry and
/// voxel (8),
/// and for the tile compositor its screen quad (80) and about four tile entries.
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
    store + s.index.len() as u64 * (4 + 4 + 16) + width as u64 * height as u64 * 16 * 3
}

/// The least budget that draws `scene` at `width` x `height`: resident data and one brick's splats
/// (and records, when they stream).
pub fn bricked_min_budget(scene: &BrickScene, budget: u64, width: u32, height: u32) -> u64 {
    let brick = (BRICK as u64).pow(3) * (BATCH_BYTES_PER_SPLAT + 4 * scene.streams(budget) as u64);
    bricked_resident_bytes(scene, budget, width, height) + brick
}

/// A bricked volume's frame (issue 23): `brick_cull` culls whole bricks on the device (outside
/// the view, or empty under the transfer function) and counts the rest's voxels at their slots in
/// the brick grid's PBTF order; the host lists the visible bricks in that order and cuts batches
/// that fit the budget; per batch `brick_order` writes their voxels in two-level PBTF order,
/// `brick_params` classifies them and makes their parameters, and the raster draws them, each
/// batch carrying on from the image the earlier left. Front to back with early termination, before
/// each later batch `tile_occlusion` and `brick_hidden` drop the bricks that the image so far
/// already hides. A store whose records would take more than half the budget keeps them on the
/// host: each batch uploads its bricks' records, and the bricks' drawn counts come from the host.
fn record_bricks(
    e: &mut dyn Engine,
    prep: &Prepared,
    scene: &BrickScene,
    camera: &Camera,
    opts: &RenderOptions,
) -> Result<Recorded> {
    if opts.composite != Composite::Splat || opts.order != OrderKind::Pbtf {
        return Err(Error::Unsupported(
            "a bricked volume is drawn per splat in PBTF order (composite splat, order pbtf); the sheet and slab modes \
             and the other orders need a classified splat set"
                .into(),
        ));
    }
    let (w, h) = (camera.width, camera.height);
    let budget = e.limits().budget_bytes;
    let streamed = scene.streams(budget);
    if streamed && (scene.shading().is_some() || scene.transfer_function().gradient_weight > 0.0) {
        return Err(Error::Unsupported(format!(
            "this volume's store ({} MiB) streams through the {} MiB GPU budget, and gradients (shading, gradient \
             weighting) read neighbouring bricks that a batch does not hold: a budget of at least {} MiB keeps it \
             resident",
            scene.store.bytes() >> 20,
            budget >> 20,
            (scene.store.records.len() as u64 * 8).div_ceil(1 << 20) + 1
        )));
    }
    let least = bricked_min_budget(scene, budget, w, h);
    if budget < least {
        return Err(Error::TooLarge(format!(
            "a GPU budget of {} MiB cannot hold this volume's bricked store ({} MiB) and one brick of splats at \
             {w}x{h}: the minimum is {} MiB",
            budget >> 20,
            scene.store.bytes() >> 20,
            least.div_ceil(1 << 20)
        )));
    }
    let available = budget - bricked_resident_bytes(scene, budget, w, h);
    let frame = plan::frame_for(&prep.set, camera, opts);
    let bf = scene.uniforms(crate::order::brick_split(&prep.set, camera, BRICK));
    let slots = bf.grid[0] as usize * bf.grid[1] as usize * bf.grid[2] as usize;
    // The brick stages' build: one page of store records, the paged reader, or streamed records.
    let build = if streamed { 2 } else { usize::from(scene.store.len() > RECORD_PAGE as usize) };
    e.begin(&frame, opts.kernel, w, h)?;
    e.upload(Res::BrickFrame, bytemuck::cast_slice(bytemuck::bytes_of(&bf)))?;
    e.upload(Res::Tf, scene.tf_words())?;
    if streamed {
        let counts = scene.drawn_counts();
        e.ensure(Res::BrickCounts, counts.len().max(1) as u64 * 4)?;
        e.upload(Res::BrickCounts, counts)?;
    }
    e.ensure(Res::BrickSlots, slots as u64 * 4)?;
    e.fill(Res::BrickSlots, None, 0)?;
    if bf.grid[3] > 0 {
        e.run(&Dispatch::new(StageId::BrickCull, build, plan::groups_per_item(bf.grid[3]), List::Order, &[]))?;
    }
    let slot_words = e.read(&[(Res::BrickSlots, slots)])?.remove(0);
    let t = Instant::now();
    let compute = opts.raster == Raster::Compute;
    // Front to back with early termination, later batches drop the bricks that what is drawn
    // already hides: cut the frame into a few batches even when it fits one.
    let cull_hidden = compute
        && opts.cull_hidden_bricks
        && opts.direction() == Direction::FrontToBack
        && opts.early_termination > 0.0;
    let capacity = if cull_hidden {
        let total: u32 = slot_words.iter().map(|w| w & 1023).sum();
        MAX_GPU_SPLATS.min(total.div_ceil(HIDDEN_BATCHES).max(HIDDEN_BATCH_MIN))
    } else {
        MAX_GPU_SPLATS
    };
    // The visible bricks in draw order (header, first position in its batch, first record: in
    // the store, or in the batch's records when they stream; voxels), cut between bricks into
    // batches of at most `capacity` splats whose bytes fit what the budget leaves.
    let mut batches: Vec<Vec<[u32; 4]>> = vec![Vec::new()];
    let (mut filled, mut records, mut bytes) = (0u32, 0u32, 0u64);
    for word in slot_words.into_iter().filter(|&w| w != 0) {
        let (header, n) = (word >> 10, word & 1023);
        let hd = &scene.store.headers[header as usize];
        let cost = n as u64 * BATCH_BYTES_PER_SPLAT + if streamed { hd.count as u64 * 4 } else { 0 };
        let open = batches.last().is_some_and(|b| !b.is_empty());
        if open && (filled + n > capacity || bytes + cost > available) {
            batches.push(Vec::new());
            (filled, records, bytes) = (0, 0, 0);
        }
        let first = if streamed { records } else { hd.first };
        batches.last_mut().expect("one batch at least").push([header, filled, first, n]);
        (filled, records, bytes) = (filled + n, records + hd.count, bytes + cost);
    }
    e.host_time("brick_list", t.elapsed().as_secs_f64() * 1e3);
    let splats = |b: &[[u32; 4]]| b.last().map(|l| l[1] + l[3]).unwrap_or(0);
    let most_entries = batches.iter().map(Vec::len).max().unwrap_or(0).max(1) as u64;
    e.ensure(Res::BrickList, most_entries * 16)?;
    let largest = batches.iter().map(|b| splats(b)).max().unwrap_or(0);
    e.ensure(Res::Params, largest as u64 * std::mem::size_of::<SplatParams>() as u64)?;
    e.ensure(Res::Order, largest as u64 * 4)?;
    e.ensure(Res::BrickVoxels, largest as u64 * 8)?;
    let tiles = w.div_ceil(COMPOSITE_TILE) * h.div_ceil(COMPOSITE_TILE);
    if cull_hidden && batches.len() > 1 {
        e.ensure(Res::Occlusion, tiles as u64 * 4)?;
        e.ensure(Res::BrickHidden, most_entries * 4)?;
    }
    if !compute {
        e.layers(1)?;
    }
    let words = |b: &[[u32; 4]]| b.iter().flatten().copied().collect::<Vec<u32>>();
    for (i, mut batch) in batches.into_iter().enumerate() {
        if cull_hidden && i > 0 && !batch.is_empty() {
            let count = batch.len() as u32;
            e.upload(Res::BrickList, &words(&batch))?;
            e.run(&Dispatch::new(StageId::TileOcclusion, 0, groups_1d(tiles), List::Order, &[]))?;
            let push = BrickPush { first: 0, count, splats: 0, occluded: opts.early_termination };
            e.run(&Dispatch::new(StageId::BrickHidden, 0, groups_1d(count), List::Order, bytemuck::bytes_of(&push)))?;
            let hidden = e.read(&[(Res::BrickHidden, count as usize)])?.remove(0);
            batch = batch.into_iter().zip(hidden).filter(|(_, h)| *h == 0).map(|(l, _)| l).collect();
            let (mut at, mut rec) = (0, 0);
            for l in &mut batch {
                l[1] = at;
                at += l[3];
                if streamed {
                    l[2] = rec;
                    rec += scene.store.headers[l[0] as usize].count;
                }
            }
        }
        let n = splats(&batch);
        if !batch.is_empty() {
            if streamed {
                // The batch's bricks' records, in list order.
                let s = &scene.store;
                let recs: Vec<u32> = batch
                    .iter()
                    .flat_map(|l| {
                        let hd = &s.headers[l[0] as usize];
                        s.records[hd.first as usize..(hd.first + hd.count) as usize].iter().copied()
                    })
                    .collect();
                e.upload(Res::BatchRecords, &recs)?;
            }
            e.upload(Res::BrickList, &words(&batch))?;
            let push = BrickPush { first: 0, count: batch.len() as u32, splats: n, occluded: 0.0 };
            let push = bytemuck::bytes_of(&push);
            let groups = plan::groups_per_item(batch.len() as u32);
            e.run(&Dispatch::new(StageId::BrickOrder, build, groups, List::Order, push))?;
            e.run(&Dispatch::new(StageId::BrickParams, build, groups_1d(n), List::Order, push))?;
        }
        if compute {
            record_tiles(e, &frame, n, opts, w, h, i > 0)?;
        } else {
            let blend = if opts.direction() == Direction::BackToFront { Blend::Over } else { Blend::Under };
            let variant = footprint_variant(blend, opts.raster == Raster::Points, SHEET_MODE_SPLAT);
            // A later batch draws on the target (the LOAD pass).
            let push = FootprintPush { rank_base: u32::from(i > 0), ..Default::default() };
            e.run(&Dispatch::new(StageId::Footprint, variant, [0, n, 0], List::Order, bytemuck::bytes_of(&push)))?;
        }
    }
    finish(e, if compute { Res::Accum } else { Res::Color }, w, h, false)
}

/// Front to back with early termination, a bricked frame is cut into at least this many batches
/// (of at least `HIDDEN_BATCH_MIN` splats), so later batches can drop hidden bricks.
pub const HIDDEN_BATCHES: u32 = 4;
/// See `HIDDEN_BATCHES`.
pub const HIDDEN_BATCH_MIN: u32 = 1 << 16;

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
    let (tx, ty) = crate::cpu::tile::tile_grid(frame);
    let tiles = tx as u64 * ty as u64;
    let mut push = FootprintPush { rank_base: carry as u32, ..plan::tile_push(opts, n, w, h) };
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

/// Read the frame's image (and, after compute sheet sums, the status word) and the timings.
fn finish(e: &mut dyn Engine, image: Res, w: u32, h: u32, status: bool) -> Result<Recorded> {
    let mut what = vec![(image, image_words(w, h))];
    if status {
        what.push((Res::Status, 1));
    }
    let back = e.read(&what)?;
    if status && back[1][0] & LOOP_BUDGET_SUMS != 0 {
        return Err(Error::TooLarge(
            "a footprint larger than about 240 x 240 pixels: the compute sheet sums ran out of llvmpipe's 65535 \
             loop iterations per invocation; draw this frame with --raster graphics or points"
                .into(),
        ));
    }
    let pixels = back[0].chunks_exact(4).map(|c| [0, 1, 2, 3].map(|i| f32::from_bits(c[i]))).collect();
    let timings = e.finish()?;
    Ok(Recorded { image: ImageF32 { width: w, height: h, pixels }, timings })
}

/// THE recording of the reference ray caster (`raycast.comp` and its mirror): `prep` cast from
/// `camera` with `opts` (at full size: the caller resamples a render scale).
pub fn record_raycast(e: &mut dyn Engine, prep: &Prepared, camera: &Camera, opts: &RaycastOptions) -> Result<Recorded> {
    camera.validate()?;
    let params = crate::cpu::raycast::raycast_params(&prep.set, camera, opts);
    if e.is_device() {
        let diagonal =
            glam::Vec3::from_slice(&params.box_max[..3]).distance(glam::Vec3::from_slice(&params.box_min[..3]));
        let steps = (diagonal / params.box_min[3]).ceil().min(opts.max_steps as f32);
        if steps > MAX_GPU_RAY_STEPS as f32 {
            return Err(Error::TooLarge(format!(
                "rays of up to {steps} samples: the GPU ray caster takes at most {MAX_GPU_RAY_STEPS} per ray (llvmpipe \
                 ends a shader's loops after 65535 iterations); use a longer step, a lower max_steps or the CPU backend"
            )));
        }
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
    finish(e, Res::Accum, w, h, false)
}
