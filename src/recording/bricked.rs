//! A bricked volume's frame: culling and listing the visible bricks, batches under the
//! device budget, and the per-splat, sheet and slab modes over them. Part of THE recording.
use super::*;
use crate::bricks::{slot_entry, BrickScene, BRICK};
use crate::builds::{Pyramids, Records};
use crate::constants::MAX_GPU_SPLATS;
use crate::options::FrameStats;
use crate::plan::{node_grid, occlusion_len, LOD_LEVELS};
use crate::plan::{BrickedPlan, BrickedSheets, BATCH_BYTES_PER_SPLAT};
use crate::residency::{RecordCache, SLOT_WORDS};
use std::cell::Cell;
use std::sync::Mutex;

/// And per coarse splat (levels of detail), its position in `Res::LodSplats`.
const LOD_SPLAT_BYTES: u64 = 4;

/// A bricked volume's frame: `brick_cull` culls whole bricks on the device (outside
/// the view, or empty under the transfer function) and counts the rest's voxels at their slots in
/// the brick grid's PBTF order; the host lists the visible bricks in that order and cuts batches
/// that fit the budget; per batch `brick_order` writes their voxels in two-level PBTF order,
/// `brick_params` classifies them and makes their parameters, and the raster draws them, each
/// batch carrying on from the image the earlier left. Front to back with early termination, before
/// each later batch `tile_occlusion` and `brick_hidden` drop the bricks that the image so far
/// already hides. A store whose records would take more than half the budget keeps them on the
/// host: each batch uploads its bricks' records, and the bricks' drawn counts come from the host.
/// The sheet and slab modes take the visible list to `record_bricked_sheets`.
pub(super) fn record_bricks(
    e: &mut dyn Engine,
    prep: &Prepared,
    scene: &BrickScene,
    plan: &FramePlan,
    b: &BrickedPlan,
) -> Result<Recorded> {
    let (w, h) = (plan.width, plan.height);
    let (streamed, lod, per_batch, available) = (b.streamed, b.lod, b.per_batch, b.available);
    let (grid, node_levels, split, bf) = (b.grid(), b.node_levels, b.split(), &b.brick_frame);
    let headers = scene.store.headers.len().max(1);
    let frame = &plan.frame;
    let slots = bf.grid[0] as usize * bf.grid[1] as usize * bf.grid[2] as usize;
    e.begin(frame, plan.kernel, w, h)?;
    super::record_host_depth(e, plan)?;
    e.upload(Res::BrickFrame, bytemuck::cast_slice(bytemuck::bytes_of(bf)))?;
    e.upload(Res::Tf, scene.tf_words())?;
    if let Some(bytes) = b.gradients {
        super::gradients::upload(e, scene, bytes)?;
    }
    let cut = Cut { plan: b, cache: &scene.records_cache.0, uploaded: Cell::new(0) };
    if streamed {
        e.ensure(Res::BatchRecords, b.cache_slots as u64 * SLOT_WORDS * 4)?;
        let tag = cut.lock_cache().open(e.tag(Res::BatchRecords), b.cache_slots);
        e.set_tag(Res::BatchRecords, tag);
    }
    if lod {
        for &(res, per_brick) in b.lod_buffers {
            let nodes = if res == Res::LodSummary { b.node_bytes } else { 0 };
            e.ensure(res, headers as u64 * per_brick + nodes)?;
        }
        let id = scene.classification();
        let all = BrickPush { first: 0, count: bf.grid[3], splats: 0, occluded: 0.0 };
        let built = e.tag(Res::LodSummary) == id && (per_batch || e.tag(Res::Pyramid) == id);
        if streamed {
            if !built && bf.grid[3] > 0 {
                // Every brick's summary (and with a resident pyramid its cells, into its own
                // slot), batch by batch through the budget, in batches of at most
                // SUMMARY_BATCH_BYTES: larger ones gain nothing and the host copies each to upload.
                let every = (0..bf.grid[3]).map(|h| [h, 0, 0, 0]);
                let mut done = 0;
                for batch in cut.batches(scene, every, u32::MAX, available.min(SUMMARY_BATCH_BYTES)) {
                    upload_batch(e, scene, &batch, &batch, &cut)?;
                    let push = BrickPush { count: batch.len() as u32, splats: u32::from(!per_batch), ..all };
                    build_pyramids(e, b.build, &push)?;
                    done += batch.len() as u64;
                    e.progress(done, bf.grid[3] as u64)?;
                }
                cut.lock_cache().forget();
                build_nodes(e, grid, node_levels)?;
                e.set_tag(Res::LodSummary, id);
            }
            // Per batch it holds batches' pyramids, not the store's.
            e.set_tag(Res::Pyramid, if per_batch { 0 } else { id });
        } else if !built && bf.grid[3] > 0 {
            // In parts, each its own dispatch, so a host can show how far the build has got.
            for first in (0..bf.grid[3]).step_by(PYRAMID_PART as usize) {
                let count = PYRAMID_PART.min(bf.grid[3] - first);
                build_pyramids(e, cut.plan.gradient_build, &BrickPush { first, count, ..all })?;
                e.progress((first + count) as u64, bf.grid[3] as u64)?;
            }
            build_nodes(e, grid, node_levels)?;
            e.set_tag(Res::Pyramid, id);
            e.set_tag(Res::LodSummary, id);
        }
    }
    if streamed {
        let counts = scene.drawn_counts();
        e.ensure(Res::BrickCounts, counts.len().max(1) as u64 * 4)?;
        e.upload(Res::BrickCounts, counts)?;
    }
    e.ensure(Res::BrickSlots, slots as u64 * 4)?;
    e.fill(Res::BrickSlots, None, 0)?;
    if bf.grid[3] > 0 && node_levels > 0 {
        let count = node_grid(grid, 1).iter().product::<u32>();
        e.run(&Dispatch::new(StageId::BrickNodeCut, Only, groups_1d(count), List::Order, &[])?)?;
    }
    if bf.grid[3] > 0 {
        e.run(&Dispatch::new(StageId::BrickCull, b.build, groups_1d(bf.grid[3]), List::Order, &[])?)?;
    }
    let slot_words = e.read(&[(Res::BrickSlots, slots)])?.remove(0);
    let t = Instant::now();
    let (compute, terminating, cull_hidden) = (b.compute, b.terminating, b.cull_hidden);
    let capacity = if cull_hidden {
        let total: u32 = slot_words.iter().map(|&w| slot_entry(w).2).sum();
        // Two bricks' splats more than the share: batches are cut between bricks, and the last
        // brick or two should not spill into a wave of their own.
        MAX_GPU_SPLATS.min((total.div_ceil(HIDDEN_BATCHES) + 2 * BRICK_SPLATS).max(HIDDEN_BATCH_MIN))
    } else {
        MAX_GPU_SPLATS
    };
    let mut stats = FrameStats { bricks: bf.grid[3], ..Default::default() };
    for &w in slot_words.iter().filter(|&&w| w != 0) {
        let (_, level, n) = slot_entry(w);
        stats.bricks_visible += 1;
        stats.bricks_coarse += u32::from(level > 0);
        stats.nodes += u32::from(level > LOD_LEVELS);
        stats.splats += n as u64;
    }
    // The visible bricks in draw order, cut between bricks into batches.
    let mut visible: Vec<[u32; 4]> = slot_words
        .into_iter()
        .filter(|&w| w != 0)
        .map(|w| {
            let (header, level, n) = slot_entry(w);
            [header, 0, 0, n | level << 16]
        })
        .collect();
    if terminating && node_levels == 0 {
        // Waves in shells (`brick_shell`): each covers the picture, so the next finds more hidden
        // than behind the tree's slabs (the 512³ bonsai draws 2.38 M splats against 3.16 M). Kept
        // with the hidden bricks too (`cull_hidden_bricks` off), so the two draw the same frame. A
        // node stands for bricks consecutive in the tree's order: with nodes the waves keep it.
        visible.sort_by_cached_key(|l| crate::order::brick_shell(scene.store.headers[l[0] as usize].coords(), split));
    }
    let batches = cut.batches(scene, visible, capacity, available);
    stats.waves = batches.len() as u32;
    e.host_time("brick_list", t.elapsed().as_secs_f64() * 1e3);
    let most_entries = batches.iter().map(Vec::len).max().unwrap_or(0).max(1) as u64;
    e.ensure(Res::BrickList, most_entries * 16)?;
    let tiles = w.div_ceil(COMPOSITE_TILE) * h.div_ceil(COMPOSITE_TILE);
    if cull_hidden && batches.len() > 1 {
        e.ensure(Res::Occlusion, occlusion_len(w, h) * 4)?;
        e.ensure(Res::BrickHidden, most_entries * 4)?;
    }
    if let Some(sheets) = &b.sheets {
        let mut recorded = record_bricked_sheets(e, prep, scene, plan, sheets, batches.concat(), &cut)?;
        stats.bytes_uploaded = cut.uploaded.get();
        stats.records_resident = cut.held_bytes();
        recorded.stats = stats;
        return Ok(recorded);
    }
    if !compute {
        e.layers(1)?;
    }
    let words = |b: &[[u32; 4]]| b.iter().flatten().copied().collect::<Vec<u32>>();
    // A projection's texels: each keeps its brightest voxel's claim (project_texels), over every
    // batch before any draws.
    let texels = bf.split[3] > 0;
    if texels {
        e.ensure(Res::ProjectTexels, crate::plan::texel_bytes(w, h, bf.split[3]))?;
        e.fill(Res::ProjectTexels, None, 0)?;
        for batch in batches.iter().filter(|b| !b.is_empty()) {
            record_texels(e, batch, &cut)?;
        }
    }
    let mut batches = batches;
    let mut i = 0;
    while i < batches.len() {
        let mut batch = std::mem::take(&mut batches[i]);
        if cull_hidden && i > 0 && !batch.is_empty() {
            let count = batch.len() as u32;
            e.ensure(Res::BrickHidden, count as u64 * 4)?;
            e.upload(Res::BrickList, &words(&batch))?;
            // One push for both: the map is built for the threshold the bricks are tested at.
            let push = BrickPush { first: 0, count, splats: 0, occluded: b.early_termination };
            let bytes = bytemuck::bytes_of(&push);
            e.run(&Dispatch::new(StageId::TileOcclusion, Only, groups_1d(tiles), List::Order, bytes)?)?;
            e.run(&Dispatch::new(StageId::BrickHidden, Only, groups_1d(count), List::Order, bytes)?)?;
            let hidden = e.read(&[(Res::BrickHidden, count as usize)])?.remove(0);
            // The bricks left, their positions (and streamed records) laid out again.
            let before = batch_splats(&batch);
            let kept = batch.into_iter().zip(hidden).filter(|(_, h)| *h == 0).map(|(l, _)| l);
            batch = cut.batches(scene, kept, u32::MAX, u64::MAX).swap_remove(0);
            stats.bricks_hidden += count - batch.len() as u32;
            let dropped = before - batch_splats(&batch);
            stats.splats -= dropped as u64;
            if i == 1 && dropped * HIDDEN_SHARE < before && i + 1 < batches.len() {
                // The second wave hides next to nothing (translucent data): each wave costs the
                // compositor a pass over the tiles it reaches, so the rest goes in as few batches
                // as the budget allows.
                let rest: Vec<[u32; 4]> = batch.into_iter().chain(batches.drain(i + 1..).flatten()).collect();
                let merged = cut.batches(scene, rest, MAX_GPU_SPLATS, available);
                batches.truncate(i);
                batches.extend(merged);
                batch = std::mem::take(&mut batches[i]);
            }
        }
        let mut n = batch_splats(&batch);
        if texels && !batch.is_empty() {
            // One batch's voxels stay extracted from its texels' pass.
            n = record_winners(e, &batch, &cut, batches.len() > 1)?;
            stats.splats_outshone += (batch_splats(&batch) - n) as u64;
            stats.splats -= (batch_splats(&batch) - n) as u64;
        } else if !batch.is_empty() {
            // The compute tiles take the splats as screen quads, made with them.
            record_brick_batch(e, scene, &batch, &cut, compute)?;
        }
        if compute {
            let made = !texels && !batch.is_empty();
            record_tiles(e, frame, &b.tile_rule(n, w, h, plan.direction), w, h, i > 0, made)?;
        } else {
            let build = b.footprint;
            // A later batch draws on the target (the LOAD pass).
            let push = FootprintPush { carry: u32::from(i > 0), ..Default::default() };
            e.run(&Dispatch::new(StageId::Footprint, build, [0, n, 0], List::Order, bytemuck::bytes_of(&push))?)?;
        }
        i += 1;
    }
    stats.waves = batches.len() as u32;
    stats.bytes_uploaded = cut.uploaded.get();
    stats.records_resident = cut.held_bytes();
    let image = if let Some(p) = &b.projection {
        super::record_project(e, p, if compute { 1 } else { 2 }, w, h)?;
        Res::Accum
    } else if compute {
        Res::Accum
    } else {
        Res::Color
    };
    let mut recorded = finish(e, plan.background, &[image], w, h, false)?;
    recorded.stats = stats;
    Ok(recorded)
}

/// How a bricked frame's visible bricks are cut into batches, by its plan: records streamed or
/// resident, the brick stages' builds, each entry's pyramid bytes (a streamed store's levels of
/// detail with pyramids built per batch, whose coarse entries need their records) and the device's
/// largest storage binding (a batch's records, list and pyramids each fit one).
struct Cut<'a> {
    plan: &'a BrickedPlan,
    /// A streamed store's record cache (`RecordCache`; opened with its slots this frame), and the
    /// record bytes uploaded so far this frame.
    cache: &'a Mutex<RecordCache>,
    uploaded: Cell<u64>,
}

impl Cut<'_> {
    /// Bytes of the record cache's slots that hold a brick (0 when the store is resident).
    fn held_bytes(&self) -> u64 {
        if self.plan.streamed {
            self.lock_cache().held() as u64 * SLOT_WORDS * 4
        } else {
            0
        }
    }

    /// The record cache (a poisoned lock: a panic elsewhere left it; its slots are still valid).
    fn lock_cache(&self) -> std::sync::MutexGuard<'_, RecordCache> {
        self.cache.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// `entries` (header, -, -, voxels) cut, in their order, into batches of at most `capacity`
    /// splats within `available` bytes (header, first position in its batch, first record: in the
    /// store, or in the batch's records when they stream; voxels).
    fn batches(
        &self,
        scene: &BrickScene,
        entries: impl IntoIterator<Item = [u32; 4]>,
        capacity: u32,
        available: u64,
    ) -> Vec<Vec<[u32; 4]>> {
        let mut batches: Vec<Vec<[u32; 4]>> = vec![Vec::new()];
        let cache_slots = if self.plan.streamed { self.lock_cache().slots() } else { 0 };
        let (mut filled, mut slots, mut bytes) = (0u32, 0u32, 0u64);
        for [header, _, _, w] in entries {
            let n = w & 0xffff;
            let hd = &scene.store.headers[header as usize];
            // A streamed brick's records take a slot of the cache, which holds the batch's.
            let slot = u32::from(self.uploads(w));
            let per_splat = BATCH_BYTES_PER_SPLAT + if w >> 16 != 0 { LOD_SPLAT_BYTES } else { 0 };
            let cost = n as u64 * per_splat + self.plan.batch_pyramid;
            let entries = batches.last().map_or(0, |b| b.len()) as u64 + 1;
            let binding = (entries * 16).max(entries * self.plan.batch_pyramid);
            let open = batches.last().is_some_and(|b| !b.is_empty());
            let full = slots + slot > cache_slots;
            if open && (filled + n > capacity || bytes + cost > available || binding > self.plan.range || full) {
                batches.push(Vec::new());
                (filled, slots, bytes) = (0, 0, 0);
            }
            // A streamed brick's first record is its slot's, known when the batch is placed
            // (`upload_batch`).
            // A uniform brick has no records to stream: its first says its value (`record_at`).
            let first = if self.plan.streamed && !hd.is_uniform() { 0 } else { hd.first };
            batches.last_mut().expect("one batch at least").push([header, filled, first, w]);
            (filled, slots, bytes) = (filled + n, slots + slot, bytes + cost);
        }
        batches
    }

    /// Whether an entry (splats | level << 16) uploads its brick's records: its voxels, or with
    /// per-batch pyramids its level-1 cells (levels 2 and 3 stay resident in the summaries).
    fn uploads(&self, w: u32) -> bool {
        self.plan.streamed && (w >> 16 == 0 || (self.plan.batch_pyramid > 0 && w >> 16 == 1))
    }
}

/// Sheet and slab modes over a bricked volume (`visible`: its visible bricks in draw order, as
/// listed for the per-splat frame). When every visible voxel fits one batch, its splats are made
/// and binned once and drawn as a dense set's are. Otherwise the frame streams: per batch of
/// sheets (in visiting order), the bricks that reach its sheets are made, binned and summed part
/// by part into its layers (each part carrying on from the layers the earlier left), then the
/// batch is composited; a brick spanning two batches of sheets is made twice.
fn record_bricked_sheets(
    e: &mut dyn Engine,
    prep: &Prepared,
    scene: &BrickScene,
    plan: &FramePlan,
    s: &BrickedSheets,
    visible: Vec<[u32; 4]>,
    cut: &Cut,
) -> Result<Recorded> {
    let (w, h, frame, direction) = (plan.width, plan.height, &plan.frame, plan.direction);
    let grid = prep.set.grid();
    let (sheet, axis, pass, available) = (s.axis_sheets, s.axis, &s.pass, s.available);
    let geometry = |n: u32| {
        if sheet {
            crate::plan::slab::sheet_geometry(grid, n, axis)
        } else {
            crate::plan::slab::slab_geometry(frame, grid, n as usize, s.slab_thickness, direction)
        }
    };
    let binning = if sheet { SlabBins::AxisSheets } else { SlabBins::Slabs };
    let plan_of = |pc: &SlabPush, starts: &[u32]| -> Result<Vec<plan::Batch>> {
        let batches = if sheet {
            plan::binned_sheet_plan(starts, axis, s.split, direction, pass.layers)
        } else {
            crate::plan::slab::slab_batches(pc, starts, pass.layers)?
        };
        Ok(pass.terminated(batches))
    };
    let parts = cut.batches(scene, visible.iter().copied(), MAX_GPU_SPLATS, available);
    if parts.len() == 1 {
        let part = &parts[0];
        let n = batch_splats(part);
        if n > 0 {
            record_brick_batch(e, scene, part, cut, false)?;
        }
        let pc = geometry(n)?;
        let starts = record_slab_bins(e, &pc, binning)?;
        return record_sheets(e, pass, &plan_of(&pc, &starts)?, plan.background, w, h);
    }
    // Each brick's bins (sheets or slabs, in index order) and each bin's reach (bricks), in
    // visiting position order for the slabs, index order for the sheets, as the binning writes.
    // (The bins do not depend on the splat count; the binning's cell limit is per part.)
    let pc = geometry(MAX_GPU_SPLATS)?;
    let bins = pc.slabs as usize;
    let position = |bin: u32| if sheet || pc.ftb != 0 { bin } else { pc.slabs - 1 - bin };
    let reach: Vec<(u32, u32)> = visible
        .iter()
        .map(|l| {
            let lo = scene.store.headers[l[0] as usize].coords().map(|c| c * BRICK);
            let hi = [0, 1, 2].map(|a| (lo[a] + BRICK - 1).min(grid.dims[a] - 1));
            if sheet {
                (lo[axis], hi[axis])
            } else {
                crate::plan::slab::box_slabs(&pc, frame, grid, lo, hi)
            }
        })
        .collect();
    let mut starts = vec![0u32; bins + 1];
    for &(lo, hi) in &reach {
        for bin in lo..=hi {
            starts[position(bin) as usize + 1] += 1;
        }
    }
    for i in 0..bins {
        starts[i + 1] += starts[i];
    }
    let groups = plan_of(&pc, &starts)?;
    begin_sheets(e, pass, &groups, w, h, false)?;
    for g in &groups {
        let (lo, hi) = if g.push.rank_dir > 0 {
            (g.push.rank_base, g.push.rank_base + g.layers - 1)
        } else {
            (g.push.rank_base + 1 - g.layers, g.push.rank_base)
        };
        let near = visible.iter().zip(&reach).filter(|(_, r)| r.0 <= hi && r.1 >= lo).map(|(l, _)| *l);
        let (p0, p1) = (position(lo).min(position(hi)), position(lo).max(position(hi)));
        for (k, part) in cut.batches(scene, near, MAX_GPU_SPLATS, available).iter().enumerate() {
            let n = batch_splats(part);
            if n > 0 {
                record_brick_batch(e, scene, part, cut, false)?;
            }
            let starts = record_slab_bins(e, &geometry(n)?, binning)?;
            let (first, end) = (starts[p0 as usize], starts[p1 as usize + 1]);
            sum_sheets(e, pass, g, first, end - first, k > 0)?;
        }
        composite_sheets(e, pass, g, w, h)?;
    }
    finish(e, plan.background, &[Res::Accum], w, h, pass.compute)
}

/// Splats of a batch of visible bricks (entries: header, first position, first record, voxels).
fn batch_splats(batch: &[[u32; 4]]) -> u32 {
    batch.last().map(|l| l[1] + (l[3] & 0xffff)).unwrap_or(0)
}

/// One batch of visible bricks (entries: header, first position, first record, voxels): its
/// records when they stream, then `brick_order` and `brick_cells` list its splats and
/// `brick_params` (voxels) and `brick_lod_params` (coarse cells) make their parameters (in buffers
/// sized for the batch: the sheet modes cut their own); with `quads`, `brick_quads` and
/// `brick_lod_quads` make them as footprints in screen space for the compute tile compositor.
fn record_brick_batch(
    e: &mut dyn Engine,
    scene: &BrickScene,
    batch: &[[u32; 4]],
    cut: &Cut,
    quads: bool,
) -> Result<()> {
    let (streamed, build) = (cut.plan.streamed, cut.plan.build);
    let n = batch_splats(batch);
    let (out, size, voxel_stage, cell_stage) = if quads {
        (Res::Quads, std::mem::size_of::<ScreenQuad>(), StageId::BrickQuads, StageId::BrickLodQuads)
    } else {
        (Res::Params, std::mem::size_of::<SplatParams>(), StageId::BrickParams, StageId::BrickLodParams)
    };
    e.ensure(out, n as u64 * size as u64)?;
    e.ensure(Res::Order, n as u64 * 4)?;
    e.ensure(Res::BrickVoxels, n as u64 * 8)?;
    // Voxel bricks first (brick_order's workgroups), then coarse ones (brick_cells' lanes), level 1
    // before levels 2 and 3 (per-batch pyramids build level 1's only): each entry names its own
    // first position, so the list's order is free.
    let (fine, mut coarse): (Vec<[u32; 4]>, Vec<[u32; 4]>) = batch.iter().partition(|l| l[3] >> 16 == 0);
    coarse.sort_by_key(|l| u32::from(l[3] >> 16 > 1));
    let listed: Vec<[u32; 4]> = fine.iter().chain(&coarse).copied().collect();
    if streamed {
        upload_batch(e, scene, batch, &listed, cut)?;
    } else {
        e.upload(Res::BrickList, bytemuck::cast_slice(&listed))?;
    }
    let push = BrickPush { first: 0, count: fine.len() as u32, splats: n, occluded: 0.0 };
    if !fine.is_empty() {
        let groups = plan::groups_per_item(fine.len() as u32);
        e.run(&Dispatch::new(StageId::BrickOrder, build, groups, List::Order, bytemuck::bytes_of(&push))?)?;
    }
    if !coarse.is_empty() {
        let cells = BrickPush { first: fine.len() as u32, count: coarse.len() as u32, ..push };
        let level_1 = coarse.iter().filter(|l| l[3] >> 16 == 1).count() as u32;
        if cut.plan.batch_pyramid > 0 && level_1 > 0 {
            // The level-1 bricks' pyramids, into their entries' slots.
            build_pyramids(e, build, &BrickPush { count: level_1, splats: 0, ..cells })?;
        }
        let groups = groups_1d(coarse.len() as u32);
        let pyramids = if streamed { Pyramids::Streamed } else { Pyramids::Resident };
        e.run(&Dispatch::new(StageId::BrickCells, pyramids, groups, List::Order, bytemuck::bytes_of(&cells))?)?;
    }
    e.run(&Dispatch::new(voxel_stage, cut.plan.gradient_build, groups_1d(n), List::Order, bytemuck::bytes_of(&push))?)?;
    // The coarse splats' positions, for brick_lod_params' lanes.
    let lod_splats: Vec<u32> = coarse.iter().flat_map(|l| l[1]..l[1] + (l[3] & 0xffff)).collect();
    if !lod_splats.is_empty() {
        e.ensure(Res::LodSplats, lod_splats.len() as u64 * LOD_SPLAT_BYTES)?;
        e.upload(Res::LodSplats, &lod_splats)?;
        let cells = BrickPush { splats: lod_splats.len() as u32, ..push };
        let groups = groups_1d(cells.splats);
        e.run(&Dispatch::new(cell_stage, build, groups, List::Order, bytemuck::bytes_of(&cells))?)?;
    }
    Ok(())
}

/// A batch of a projection with texels (resident stores without levels of detail): its voxels
/// extracted in any order, each claiming its texel (`project_texels`, in `brick_order`'s place).
/// Every batch claims before any draws.
fn record_texels(e: &mut dyn Engine, batch: &[[u32; 4]], cut: &Cut) -> Result<BrickPush> {
    let n = batch_splats(batch);
    e.ensure(Res::Params, n as u64 * std::mem::size_of::<SplatParams>() as u64)?;
    e.ensure(Res::Order, n as u64 * 4)?;
    e.ensure(Res::BrickVoxels, n as u64 * 8)?;
    e.ensure(Res::VoxelTexels, n as u64 * 4)?;
    e.upload(Res::BrickList, bytemuck::cast_slice(batch))?;
    let push = BrickPush { first: 0, count: batch.len() as u32, splats: n, occluded: 0.0 };
    let groups = plan::groups_per_item(batch.len() as u32);
    e.run(&Dispatch::new(StageId::ProjectTexels, cut.plan.build, groups, List::Order, bytemuck::bytes_of(&push))?)?;
    Ok(push)
}

/// A batch's voxels that draw, packed (`project_winners`; extracted again when the frame has
/// several batches: claiming again changes no texel), and their parameters: their count.
fn record_winners(e: &mut dyn Engine, batch: &[[u32; 4]], cut: &Cut, extract: bool) -> Result<u32> {
    let n = batch_splats(batch);
    let push = if extract {
        record_texels(e, batch, cut)?
    } else {
        BrickPush { first: 0, count: batch.len() as u32, splats: n, occluded: 0.0 }
    };
    e.ensure(Res::ProjectVoxels, n as u64 * 8)?;
    e.fill(Res::ProjectTexels, Some((0, 4)), 0)?;
    e.run(&Dispatch::new(StageId::ProjectWinners, Only, groups_1d(n), List::Order, bytemuck::bytes_of(&push))?)?;
    let drawn = e.read(&[(Res::ProjectTexels, 1)])?[0][0].min(n);
    let push = BrickPush { splats: drawn, ..push };
    let bytes = bytemuck::bytes_of(&push);
    e.run(&Dispatch::new(StageId::BrickParams, Records::Winners, groups_1d(drawn), List::Order, bytes)?)?;
    Ok(drawn)
}

/// `brick_pyramid` over `push.count` bricks (a resident store's all; a streamed store's batch entries
/// from `push.first`, into their own slots when `push.splats` is not 0).
fn build_pyramids(e: &mut dyn Engine, build: Records, push: &BrickPush) -> Result<()> {
    let groups = plan::groups_per_item(push.count);
    e.run(&Dispatch::new(StageId::BrickPyramid, build, groups, List::Order, bytemuck::bytes_of(push))?)
}

/// `brick_nodes` over tree levels 1..=`levels` of a `grid` of bricks, each from the one below.
fn build_nodes(e: &mut dyn Engine, grid: [u32; 3], levels: u32) -> Result<()> {
    for k in 1..=levels {
        let count = node_grid(grid, k).iter().product::<u32>();
        let push = BrickPush { first: k, count, splats: 0, occluded: 0.0 };
        e.run(&Dispatch::new(StageId::BrickNodes, Only, groups_1d(count), List::Order, bytemuck::bytes_of(&push))?)?;
    }
    Ok(())
}

/// A streamed store's batch on the device: the records of its bricks that read them (`Cut::uploads`)
/// placed in the record cache, uploading those it lacks; `list` (the same entries in any order)
/// with each such entry's first record at its slot; and room for their pyramids when each batch
/// builds its own.
fn upload_batch(
    e: &mut dyn Engine,
    scene: &BrickScene,
    batch: &[[u32; 4]],
    list: &[[u32; 4]],
    cut: &Cut,
) -> Result<()> {
    let s = &scene.store;
    let readers: Vec<u32> =
        batch.iter().filter(|l| cut.uploads(l[3]) && !s.headers[l[0] as usize].is_uniform()).map(|l| l[0]).collect();
    let (slots, new) = cut.lock_cache().place(&readers)?;
    let (mut data, mut regions) = (Vec::new(), Vec::with_capacity(new.len()));
    for (i, slot) in new {
        let hd = &s.headers[readers[i] as usize];
        regions.push([data.len() as u64, slot as u64 * SLOT_WORDS, hd.count as u64]);
        data.extend_from_slice(&s.records[hd.first as usize..(hd.first + hd.count) as usize]);
    }
    e.upload_regions(Res::BatchRecords, &data, &regions)?;
    cut.uploaded.set(cut.uploaded.get() + data.len() as u64 * 4);
    let first: std::collections::HashMap<u32, u32> =
        readers.iter().zip(&slots).map(|(&h, &slot)| (h, slot * SLOT_WORDS as u32)).collect();
    let list: Vec<[u32; 4]> =
        list.iter().map(|&[h, pos, f, w]| [h, pos, first.get(&h).copied().unwrap_or(f), w]).collect();
    e.ensure(Res::BrickList, list.len().max(1) as u64 * 16)?;
    e.upload(Res::BrickList, bytemuck::cast_slice(&list))?;
    if cut.plan.batch_pyramid > 0 {
        e.ensure(Res::Pyramid, list.len().max(1) as u64 * cut.plan.batch_pyramid)?;
    }
    Ok(())
}

/// Most bytes of one batch of a streamed store's one-time pyramid build.
const SUMMARY_BATCH_BYTES: u64 = 64 << 20;

/// Front to back with early termination, a bricked frame is cut into at least this many batches
/// (of at least `HIDDEN_BATCH_MIN` splats), so later batches can drop hidden bricks.
pub const HIDDEN_BATCHES: u32 = 4;
/// See `HIDDEN_BATCHES`.
pub const HIDDEN_BATCH_MIN: u32 = 1 << 16;
/// The waves go on past the second only where it hides at least 1 / HIDDEN_SHARE of its splats
/// (at 512² heptane, the stent and the procedural field hide nothing there, the bonsai 43 %, the
/// head phantom 27 %, the 1024³ field 13 %).
const HIDDEN_SHARE: u32 = 16;
/// A resident store's pyramids are built this many bricks at a time (about a twentieth of the
/// 512³ bonsai's; a dispatch each).
const PYRAMID_PART: u32 = 4096;
/// Most splats of one brick.
const BRICK_SPLATS: u32 = BRICK * BRICK * BRICK;
