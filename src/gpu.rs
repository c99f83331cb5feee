//! The stage list executed on Vulkan through the safe `vk` layer.
use crate::camera::Camera;
use crate::constants::{
    COMPOSITE_TILE, FOOTPRINT_TABLE_SIZE, MAX_GPU_RAY_STEPS, MAX_GPU_SPLATS, RADIAL_TABLE_SIZE, RASTER_TILE_H,
    RASTER_TILE_W, SPLAT_PAGE, TILE_BIN_WORKGROUP, TILE_SEGMENT,
};
use crate::cpu::raycast::{raycast_params, RaycastOptions};
use crate::cpu::ImageF32;
use crate::error::{Error, Result};
use crate::gpu_types::{
    CompositePush, FootprintPush, Frame, SlabPush, SplatParams, SHEET_MODE_AXIS, SHEET_MODE_SLAB, SHEET_MODE_SPLAT,
};
use crate::kernel::Kernel;
use crate::order::{self, Direction, OrderKind};
use crate::pipeline::{
    frame_for, groups_1d, make_frame, sheet_plan, tile_push, Antialias, Composite, Prepared, RenderOptions, Rendered,
    StageTime,
};
use crate::raster::Raster;
use crate::truth::DenseField;
use crate::vk::{
    Bind, Blend, Buffer, BufferUsageFlags as BU, Context, DescriptorSet, Format, Framebuffer, Image, ImageLayout as IL,
    ImageUsageFlags as IU, Layout, Memory, Pipeline, Primitive, Recorder, RenderPass, Sampler, ShaderStageFlags as SS,
    Slot, Stage, Timer,
};
use std::sync::Arc;
use std::time::Instant;

macro_rules! spirv {
    ($name:literal) => {
        include_bytes!(concat!(env!("OUT_DIR"), "/", $name, ".spv"))
    };
}

const COLOR_FORMAT: Format = Format::R32G32B32A32_SFLOAT;

struct Stages {
    order_layout: Layout,
    order_count: Pipeline,
    order_scan: Pipeline,
    order_scatter: Pipeline,
    params_layout: Layout,
    splat_params: Pipeline,
    footprint_layout: Layout,
    target_pass: RenderPass,
    sheet_pass: RenderPass,
    over: Pipeline,
    under: Pipeline,
    add: Pipeline,
    add_slab: Pipeline,
    /// The same four as point sprites.
    over_points: Pipeline,
    under_points: Pipeline,
    add_points: Pipeline,
    add_slab_points: Pipeline,
    /// Compute raster: fixed-point sheet sums (axis, slab) and the tile compositor's stages.
    sum_axis: Pipeline,
    sum_slab: Pipeline,
    /// Two pages of splat records, and one (`ONE_PAGE`, types.glsl): index `one_page(n)`.
    tile_count: [Pipeline; 2],
    tile_scan: Pipeline,
    tile_offsets: Pipeline,
    tile_scatter: [Pipeline; 2],
    /// See [`tile_composite_pipe`].
    tile_composite: Vec<Pipeline>,
    /// Sheet modes' per-tile sheet ranges: [axis quads, axis points, slab quads, slab points].
    sheet_tiles: [Pipeline; 4],
    composite_layout: Layout,
    composite: Pipeline,
    composite_fixed: Pipeline,
    slab_layout: Layout,
    slab_count: Pipeline,
    slab_scan: Pipeline,
    slab_scatter: Pipeline,
    raycast_layout: Layout,
    raycast: Pipeline,
    roofline_layout: Layout,
    roofline_quads: Pipeline,
    roofline_composite: Pipeline,
}

struct SceneGpu {
    n: u32,
    rows: u32,
    splats: Buffer,
    _row_start: Buffer,
    _row_split: Buffer,
    _segments: Buffer,
    order: Buffer,
    params: Buffer,
    /// Slice-grouped draw lists of axes x, y, z.
    draw: [Buffer; 3],
    ranks: Buffer,
    order_set: DescriptorSet,
    /// The ray caster's 3D texture of (colour * tau, tau), built on first use, and its brick
    /// occupancy for empty-space skipping: (brick side, flags).
    field: Option<Image>,
    bricks: Option<(u32, Buffer)>,
    params_set: DescriptorSet,
    /// Footprint sets: 0 = visibility order, 1..=3 = slice-grouped lists of axes x, y, z, 4 = slab
    /// pairs. They bind the target's occlusion map too, so they are built for a (scene, target,
    /// pair buffer) and emptied when any of them is replaced.
    footprint_sets: Vec<DescriptorSet>,
    /// The image-aligned sheets' binning: (splat, slab) pairs, the slab x chunk count matrix, each
    /// slab's first pair (on the device and read back) and their set; grown on demand.
    slab_pairs: Option<Buffer>,
    slab_counts: Option<Buffer>,
    slab_start: Option<(Buffer, Buffer)>,
    slab_set: Option<DescriptorSet>,
    /// The compute tile compositor's binning: tile x chunk counts, each tile's first entry (on the
    /// device and read back) and the entries; grown on demand.
    tile_counts: Option<Buffer>,
    tile_start: Option<(Buffer, Buffer)>,
    tile_entries: Option<Buffer>,
    tile_quads: Option<Buffer>,
}

struct TargetGpu {
    width: u32,
    height: u32,
    layers: u32,
    color: Image,
    color_fb: Framebuffer,
    sums: Image,
    sums_fb: Framebuffer,
    accum: Image,
    /// Largest transmittance left per composite tile (front-to-back early termination).
    occlusion: Buffer,
    /// Per composite tile, the lowest sheet reaching it, then the highest + 1 (sheet_tiles.comp).
    sheet_tiles: Buffer,
    tiles: u32,
    /// The compute raster's fixed-point summation layers, allocated on first use.
    fixed: Option<Buffer>,
    composite_set: DescriptorSet,
    readback: Buffer,
}

pub struct GpuPipeline {
    stages: Stages,
    frame: Buffer,
    /// The radial footprint table (`Kernel::radial_pairs`).
    radial: Buffer,
    /// The kernel-slice table of the image-aligned sheets.
    slices: Image,
    sampler: Sampler,
    /// Set by stages whose loops ran out of llvmpipe's budget (`LOOP_BUDGET_*`), and its copy.
    status: Buffer,
    status_back: Buffer,
    kernel: Option<Kernel>,
    scene: Option<SceneGpu>,
    target: Option<TargetGpu>,
    timer: Timer,
    ctx: Arc<Context>,
}

/// Replace the buffer in `slot` with a power-of-two-sized one when it holds fewer than `bytes`;
/// true when it did (descriptor sets naming the old one must be rebuilt).
fn grow(ctx: &Arc<Context>, slot: &mut Option<Buffer>, name: &str, bytes: u64, memory: Memory) -> Result<bool> {
    if slot.as_ref().is_some_and(|b| b.size() >= bytes) {
        return Ok(false);
    }
    *slot = None;
    let usage = BU::STORAGE_BUFFER | BU::TRANSFER_SRC | BU::TRANSFER_DST;
    *slot = Some(Buffer::new(ctx, name, bytes.max(4).next_power_of_two(), usage, memory)?);
    Ok(true)
}

/// A device buffer and its host-readable copy, grown together (see `grow`).
fn grow_readable(ctx: &Arc<Context>, slot: &mut Option<(Buffer, Buffer)>, name: &str, bytes: u64) -> Result<bool> {
    if slot.as_ref().is_some_and(|(b, _)| b.size() >= bytes) {
        return Ok(false);
    }
    *slot = None;
    let size = bytes.max(4).next_power_of_two();
    let dev = Buffer::new(ctx, name, size, BU::STORAGE_BUFFER | BU::TRANSFER_SRC, Memory::Device)?;
    let back = Buffer::new(ctx, &format!("{name} readback"), size, BU::TRANSFER_DST, Memory::Readback)?;
    *slot = Some((dev, back));
    Ok(true)
}

/// Add `more` to `into`, summing a stage named in both.
fn merge_timings(into: &mut Vec<StageTime>, more: Vec<StageTime>) {
    for t in more {
        match into.iter_mut().find(|p| p.stage == t.stage) {
            Some(p) => p.ms += t.ms,
            None => into.push(t),
        }
    }
}

/// Bits of the status word (binding 17): a binning invocation, or a footprint-sum invocation, made
/// llvmpipe's 65535 loop iterations and was cut short (glsl/tile_count.comp, footprint_sum.comp).
const LOOP_BUDGET_BINNING: u32 = 1;
const LOOP_BUDGET_SUMS: u32 = 2;

/// The two bindings of a per-splat array of 80-byte records (`SPLAT_PAGE` records each, see
/// constants.rs); while the array fits in one page the second binding repeats the first.
fn pages(buf: &Buffer) -> [Bind<'_>; 2] {
    const PAGE: u64 = SPLAT_PAGE as u64 * std::mem::size_of::<SplatParams>() as u64;
    const _: () = assert!(std::mem::size_of::<SplatParams>() == std::mem::size_of::<crate::gpu_types::ScreenQuad>());
    let size = buf.size();
    let hi = if size > PAGE { Bind::Range(buf, PAGE, (size - PAGE).min(PAGE)) } else { Bind::Range(buf, 0, size) };
    [Bind::Range(buf, 0, size.min(PAGE)), hi]
}

fn storage(ctx: &Arc<Context>, name: &str, data: &[u8]) -> Result<Buffer> {
    Buffer::with_data(ctx, name, data, BU::STORAGE_BUFFER)
}

impl GpuPipeline {
    pub fn new(ctx: Arc<Context>) -> Result<Self> {
        let compute = SS::COMPUTE;
        let order_layout = Layout::new(
            &ctx,
            &[Slot::Storage, Slot::Storage, Slot::Storage, Slot::Storage, Slot::Storage, Slot::Storage],
            compute,
            0,
        )?;
        // glsl/splat_params.comp: frame, splats, the two pages of params.
        let params_layout = Layout::new(&ctx, &[Slot::Storage; 4], compute, 0)?;
        // glsl/shared/footprint.glsl: 0-4 frame, params, draw list, splats, ranks; 5 radial table,
        // 6 slice table;
        // 7 occlusion; 8 fixed-point sums; 9-11 tile counts, starts, entries; 12 accumulation;
        // 13 screen quads; 14 per-tile sheet ranges; 15, 16 the second pages of params and quads;
        // 17 the loop-budget status word.
        let footprint_layout = Layout::new(
            &ctx,
            &[
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Texture,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::StorageImage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
                Slot::Storage,
            ],
            SS::VERTEX | SS::FRAGMENT | SS::COMPUTE,
            std::mem::size_of::<FootprintPush>() as u32,
        )?;
        let composite_layout = Layout::new(
            &ctx,
            &[Slot::StorageImage, Slot::StorageImage, Slot::Storage, Slot::Storage, Slot::Storage],
            compute,
            std::mem::size_of::<CompositePush>() as u32,
        )?;
        let raycast_layout =
            Layout::new(&ctx, &[Slot::Storage, Slot::Texture, Slot::StorageImage, Slot::Storage], compute, 0)?;
        // glsl/slab_*.comp: params, counts, pairs, starts, the second page of params.
        let slab_layout = Layout::new(&ctx, &[Slot::Storage; 5], compute, std::mem::size_of::<SlabPush>() as u32)?;
        let roofline_layout = Layout::new(&ctx, &[Slot::Uniform], SS::VERTEX | SS::FRAGMENT, 16)?;
        let target_pass = RenderPass::new(&ctx, COLOR_FORMAT, IL::TRANSFER_SRC_OPTIMAL)?;
        let sheet_pass = RenderPass::new(&ctx, COLOR_FORMAT, IL::GENERAL)?;
        let (vert, frag) = (spirv!("footprint.vert"), spirv!("footprint.frag"));
        let sum_spirv: &[u8] =
            if ctx.int64_atomics() { spirv!("footprint_sum.comp.SUM64") } else { spirv!("footprint_sum.comp") };
        let footprint_pipe = |blend, primitive, mode, pass: &RenderPass| {
            let points = (primitive == Primitive::Points) as u32;
            Pipeline::graphics(&ctx, &footprint_layout, pass, vert, frag, blend, primitive, &[mode, points])
        };
        let stages = Stages {
            order_count: Pipeline::compute(&ctx, &order_layout, spirv!("order_count.comp"))?,
            order_scan: Pipeline::compute(&ctx, &order_layout, spirv!("order_scan.comp"))?,
            order_scatter: Pipeline::compute(&ctx, &order_layout, spirv!("order_scatter.comp"))?,
            splat_params: Pipeline::compute(&ctx, &params_layout, spirv!("splat_params.comp"))?,
            over: footprint_pipe(Blend::Over, Primitive::Quads, SHEET_MODE_SPLAT, &target_pass)?,
            under: footprint_pipe(Blend::Under, Primitive::Quads, SHEET_MODE_SPLAT, &target_pass)?,
            add: footprint_pipe(Blend::Add, Primitive::Quads, SHEET_MODE_AXIS, &sheet_pass)?,
            add_slab: footprint_pipe(Blend::Add, Primitive::Quads, SHEET_MODE_SLAB, &sheet_pass)?,
            over_points: footprint_pipe(Blend::Over, Primitive::Points, SHEET_MODE_SPLAT, &target_pass)?,
            under_points: footprint_pipe(Blend::Under, Primitive::Points, SHEET_MODE_SPLAT, &target_pass)?,
            add_points: footprint_pipe(Blend::Add, Primitive::Points, SHEET_MODE_AXIS, &sheet_pass)?,
            add_slab_points: footprint_pipe(Blend::Add, Primitive::Points, SHEET_MODE_SLAB, &sheet_pass)?,
            sum_axis: Pipeline::compute_specialized(&ctx, &footprint_layout, sum_spirv, &[SHEET_MODE_AXIS])?,
            sum_slab: Pipeline::compute_specialized(&ctx, &footprint_layout, sum_spirv, &[SHEET_MODE_SLAB])?,
            tile_count: [
                Pipeline::compute(&ctx, &footprint_layout, spirv!("tile_count.comp"))?,
                Pipeline::compute(&ctx, &footprint_layout, spirv!("tile_count.comp.ONE_PAGE"))?,
            ],
            tile_scan: Pipeline::compute(&ctx, &footprint_layout, spirv!("tile_scan.comp"))?,
            tile_offsets: Pipeline::compute(&ctx, &footprint_layout, spirv!("tile_offsets.comp"))?,
            tile_scatter: [
                Pipeline::compute(&ctx, &footprint_layout, spirv!("tile_scatter.comp"))?,
                Pipeline::compute(&ctx, &footprint_layout, spirv!("tile_scatter.comp.ONE_PAGE"))?,
            ],
            tile_composite: {
                let (paged, one_page): (&[u8], &[u8]) = if ctx.subgroup_shuffle() {
                    (spirv!("tile_composite.comp.SHUFFLE"), spirv!("tile_composite.comp.SHUFFLE+ONE_PAGE"))
                } else {
                    (spirv!("tile_composite.comp"), spirv!("tile_composite.comp.ONE_PAGE"))
                };
                let mut pipes = Vec::new();
                for spirv in [paged, one_page] {
                    for (btf, terminate) in TILE_COMPOSITE_MODES {
                        for blur in [false, true] {
                            let spec = [SHEET_MODE_SPLAT, btf as u32, terminate as u32, blur as u32];
                            pipes.push(Pipeline::compute_specialized(&ctx, &footprint_layout, spirv, &spec)?);
                        }
                    }
                }
                pipes
            },
            sheet_tiles: {
                let pipe = |mode, points| {
                    Pipeline::compute_specialized(&ctx, &footprint_layout, spirv!("sheet_tiles.comp"), &[mode, points])
                };
                [
                    pipe(SHEET_MODE_AXIS, 0)?,
                    pipe(SHEET_MODE_AXIS, 1)?,
                    pipe(SHEET_MODE_SLAB, 0)?,
                    pipe(SHEET_MODE_SLAB, 1)?,
                ]
            },
            composite_fixed: Pipeline::compute_specialized(&ctx, &composite_layout, spirv!("composite.comp"), &[1])?,
            composite: Pipeline::compute(&ctx, &composite_layout, spirv!("composite.comp"))?,
            slab_count: Pipeline::compute(&ctx, &slab_layout, spirv!("slab_count.comp"))?,
            slab_scan: Pipeline::compute(&ctx, &slab_layout, spirv!("slab_scan.comp"))?,
            slab_scatter: Pipeline::compute(&ctx, &slab_layout, spirv!("slab_scatter.comp"))?,
            slab_layout,
            raycast: Pipeline::compute(&ctx, &raycast_layout, spirv!("raycast.comp"))?,
            raycast_layout,
            roofline_quads: Pipeline::graphics(
                &ctx,
                &roofline_layout,
                &target_pass,
                spirv!("roofline.vert"),
                spirv!("roofline.frag"),
                Blend::Add,
                Primitive::Quads,
                &[],
            )?,
            roofline_composite: Pipeline::compute(&ctx, &composite_layout, spirv!("roofline.comp"))?,
            roofline_layout,
            order_layout,
            params_layout,
            footprint_layout,
            composite_layout,
            target_pass,
            sheet_pass,
        };
        let frame =
            Buffer::new(&ctx, "frame", std::mem::size_of::<Frame>() as u64, BU::STORAGE_BUFFER, Memory::Upload)?;
        let n = FOOTPRINT_TABLE_SIZE;
        let radial_bytes = RADIAL_TABLE_SIZE as u64 * 8;
        let radial = Buffer::new(&ctx, "radial table", radial_bytes, BU::STORAGE_BUFFER, Memory::Upload)?;
        let slices =
            Image::new(&ctx, "slice table", (n, n, 1), Format::R32_SFLOAT, IU::SAMPLED | IU::TRANSFER_DST, false)?;
        let sampler = Sampler::nearest(&ctx)?;
        let timer = Timer::new(&ctx, 16)?;
        let status =
            Buffer::new(&ctx, "status", 4, BU::STORAGE_BUFFER | BU::TRANSFER_SRC | BU::TRANSFER_DST, Memory::Device)?;
        let status_back = Buffer::new(&ctx, "status readback", 4, BU::TRANSFER_DST, Memory::Readback)?;
        Ok(Self {
            stages,
            frame,
            radial,
            slices,
            sampler,
            status,
            status_back,
            kernel: None,
            scene: None,
            target: None,
            timer,
            ctx,
        })
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    fn upload_table(&mut self, kernel: Kernel) -> Result<()> {
        if self.kernel == Some(kernel) {
            return Ok(());
        }
        self.radial.write(bytemuck::cast_slice(&kernel.radial_pairs()))?;
        let slice = kernel.slice_table();
        let staging =
            Buffer::with_data(&self.ctx, "slice table staging", bytemuck::cast_slice(&slice), BU::TRANSFER_SRC)?;
        let table = &self.slices;
        self.ctx.submit(|rec| {
            rec.transition(table, IL::UNDEFINED, IL::TRANSFER_DST_OPTIMAL, Stage::All, Stage::Transfer);
            rec.copy_buffer_to_image(&staging, table);
            rec.transition(table, IL::TRANSFER_DST_OPTIMAL, IL::SHADER_READ_ONLY_OPTIMAL, Stage::Transfer, Stage::All);
            Ok(())
        })?;
        self.kernel = Some(kernel);
        // Footprint sets reference the table objects themselves, not their contents: no rebinding.
        Ok(())
    }

    /// Upload a scene's splats, rows and slice lists; descriptor sets are rebuilt.
    pub fn set_scene(&mut self, prep: &Prepared) -> Result<()> {
        self.ctx.wait_idle();
        self.scene = None;
        let ctx = &self.ctx;
        let set = &prep.set;
        if set.len() > MAX_GPU_SPLATS as usize {
            return Err(Error::TooLarge(format!(
                "{} splats: the GPU path takes at most {MAX_GPU_SPLATS} (two {SPLAT_PAGE}-record pages of 80-byte \
                 per-splat parameters; one storage binding is limited to maxStorageBufferRange). Classify fewer \
                 voxels as non-empty or use the CPU backend (--cpu)",
                set.len()
            )));
        }
        let n = set.len() as u32;
        let rows = (set.row_start().len() - 1) as u32;
        let splats = storage(ctx, "splats", bytemuck::cast_slice(set.splats()))?;
        let row_start = storage(ctx, "row_start", bytemuck::cast_slice(set.row_start()))?;
        let row_split = Buffer::new(ctx, "row_split", rows as u64 * 4, BU::STORAGE_BUFFER, Memory::Device)?;
        let segments = Buffer::new(ctx, "segments", rows as u64 * 8, BU::STORAGE_BUFFER, Memory::Device)?;
        let order = Buffer::new(ctx, "order", n as u64 * 4, BU::STORAGE_BUFFER, Memory::Upload)?;
        let params = Buffer::new(
            ctx,
            "params",
            n as u64 * std::mem::size_of::<SplatParams>() as u64,
            BU::STORAGE_BUFFER | BU::TRANSFER_SRC,
            Memory::Device,
        )?;
        let draw = [
            storage(ctx, "slices x", bytemuck::cast_slice(&prep.slices[0].1))?,
            storage(ctx, "slices y", bytemuck::cast_slice(&prep.slices[1].1))?,
            storage(ctx, "slices z", bytemuck::cast_slice(&prep.slices[2].1))?,
        ];
        let ranks = storage(ctx, "sheet ranks", bytemuck::cast_slice(&prep.ranks))?;
        let st = &self.stages;
        let order_set = st.order_layout.bind(&[
            Bind::Buffer(&self.frame),
            Bind::Buffer(&splats),
            Bind::Buffer(&row_start),
            Bind::Buffer(&row_split),
            Bind::Buffer(&segments),
            Bind::Buffer(&order),
        ])?;
        let [params_lo, params_hi] = pages(&params);
        let params_set =
            st.params_layout.bind(&[Bind::Buffer(&self.frame), Bind::Buffer(&splats), params_lo, params_hi])?;
        self.scene = Some(SceneGpu {
            n,
            rows,
            splats,
            _row_start: row_start,
            _row_split: row_split,
            _segments: segments,
            order,
            params,
            draw,
            ranks,
            order_set,
            field: None,
            bricks: None,
            params_set,
            footprint_sets: Vec::new(),
            slab_pairs: None,
            slab_counts: None,
            slab_start: None,
            slab_set: None,
            tile_counts: None,
            tile_start: None,
            tile_entries: None,
            tile_quads: None,
        });
        Ok(())
    }

    /// Run `splat_params` and the first two binning stages, read back each slab's first pair, and
    /// size the pair buffer: (slab_start, stage times).
    fn slab_prepass(&mut self, pc: &SlabPush) -> Result<(Vec<u32>, Vec<StageTime>)> {
        let ctx = self.ctx.clone();
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let cells = pc.slabs as u64 * pc.chunks as u64 * 4;
        let starts = (pc.slabs as u64 + 1) * 4;
        let mut changed = grow(&ctx, &mut scene.slab_counts, "slab counts", cells, Memory::Device)?;
        changed |= grow_readable(&ctx, &mut scene.slab_start, "slab starts", starts)?;
        if changed {
            scene.slab_set = None;
        }
        self.ensure_slab_set()?;
        let (st, scene) = (&self.stages, self.scene.as_ref().expect("checked above"));
        let set = scene.slab_set.as_ref().expect("ensured");
        let (dev, back) = scene.slab_start.as_ref().expect("ensured");
        let push = bytemuck::bytes_of(pc);
        let n = scene.n;
        let steps: Vec<Step<'_>> = vec![
            (
                "splat_params",
                Box::new(|rec| {
                    rec.dispatch(&st.splat_params, &st.params_layout, &scene.params_set, &[], groups_1d(n));
                    rec.barrier(Stage::Compute, Stage::Compute);
                }),
            ),
            (
                "slab_bins",
                Box::new(move |rec| {
                    rec.dispatch(&st.slab_count, &st.slab_layout, set, push, groups_1d(pc.chunks));
                    rec.barrier(Stage::Compute, Stage::Compute);
                    rec.dispatch(&st.slab_scan, &st.slab_layout, set, push, [1, 1, 1]);
                    rec.barrier(Stage::Compute, Stage::Transfer);
                    rec.copy_buffer(dev, back, starts);
                }),
            ),
        ];
        let timings = execute(&self.ctx, &mut self.timer, &steps)?;
        drop(steps);
        let slab_start = bytemuck::cast_slice::<u8, u32>(&back.read()?[..starts as usize]).to_vec();
        let pairs = slab_start[pc.slabs as usize] as u64 * 8;
        let scene = self.scene.as_mut().expect("checked above");
        if grow(&self.ctx, &mut scene.slab_pairs, "slab pairs", pairs, Memory::Device)? {
            scene.slab_set = None;
            scene.footprint_sets.clear();
        }
        self.ensure_slab_set()?;
        Ok((slab_start, timings))
    }

    /// Compute tile compositing, first half: the order (when on the GPU), `splat_params`, the tile
    /// counts and their scan, then read back the total to size the entry list (checked against
    /// `MAX_TILE_ENTRIES` before allocating). Also returns the longest tile list. When a binning
    /// invocation ran out of llvmpipe's loop budget (footprints covering many tiles), the counts
    /// are redone with chunks a quarter as long (`push.chunks` says what the scatter must use).
    fn tile_prepass(
        &mut self,
        frame: &Frame,
        push: &mut FootprintPush,
        gpu_order: bool,
    ) -> Result<(Vec<StageTime>, u32)> {
        let (tx, ty) = crate::cpu::tile::tile_grid(frame);
        let tiles = tx as u64 * ty as u64;
        let most = (crate::raster::MAX_TILE_CELLS / tiles.max(1)).min(push.count.max(1) as u64) as u32;
        let mut timings: Vec<StageTime> = Vec::new();
        let mut first = true;
        loop {
            let (t, longest, spent) = self.tile_bins_once(frame, push, gpu_order && first, first)?;
            merge_timings(&mut timings, t);
            if !spent {
                return Ok((timings, longest));
            }
            if push.chunks >= most {
                return Err(Error::TooLarge(format!(
                    "the compute tile binning ran out of llvmpipe's 65535 loop iterations per invocation even in \
                     {} chunks (footprints covering very many {RASTER_TILE_W}x{RASTER_TILE_H}-pixel tiles): draw this frame with \
                     --raster graphics or points",
                    push.chunks
                )));
            }
            push.chunks = push.chunks.saturating_mul(4).min(most);
            first = false;
        }
    }

    /// The status word as the last submission that copied it left it (`LOOP_BUDGET_*` bits).
    fn status(&self) -> Result<u32> {
        Ok(bytemuck::cast_slice::<u8, u32>(&self.status_back.read()?[..4])[0])
    }

    /// One binning pass of `tile_prepass`: its timings, the longest list, and whether a binning
    /// invocation ran out of loop iterations (its counts are then incomplete).
    fn tile_bins_once(
        &mut self,
        frame: &Frame,
        push: &FootprintPush,
        gpu_order: bool,
        with_params: bool,
    ) -> Result<(Vec<StageTime>, u32, bool)> {
        let ctx = self.ctx.clone();
        let (tx, ty) = crate::cpu::tile::tile_grid(frame);
        let tiles = tx as u64 * ty as u64;
        let cells = crate::raster::check_tile_cells(tiles, push.chunks)?;
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let mut changed = grow(&ctx, &mut scene.tile_counts, "tile counts", cells * 4, Memory::Device)?;
        changed |= grow_readable(&ctx, &mut scene.tile_start, "tile starts", (tiles + 1) * 4)?;
        let quad_bytes = scene.n as u64 * std::mem::size_of::<crate::gpu_types::ScreenQuad>() as u64;
        changed |= grow(&ctx, &mut scene.tile_quads, "screen quads", quad_bytes, Memory::Device)?;
        if changed {
            scene.footprint_sets.clear();
        }
        self.ensure_footprint_sets()?;
        let (st, scene) = (&self.stages, self.scene.as_ref().expect("checked above"));
        let (dev, back) = scene.tile_start.as_ref().expect("grown");
        let set = &scene.footprint_sets[0];
        let bytes = bytemuck::bytes_of(push);
        let n = scene.n;
        let mut steps: Vec<Step<'_>> = Vec::new();
        if gpu_order && n > 0 {
            steps.push(("order", Box::new(|rec| record_order(rec, st, scene))));
        }
        if with_params && n > 0 {
            steps.push((
                "splat_params",
                Box::new(|rec| {
                    rec.dispatch(&st.splat_params, &st.params_layout, &scene.params_set, &[], groups_1d(n));
                    rec.barrier(Stage::Compute, Stage::Compute);
                }),
            ));
        }
        let counts = scene.tile_counts.as_ref().expect("grown");
        let (status, status_back) = (&self.status, &self.status_back);
        steps.push((
            "tile_bins",
            Box::new(move |rec| {
                rec.fill_buffer(counts, 0);
                rec.fill_buffer(status, 0);
                rec.barrier(Stage::Transfer, Stage::Compute);
                rec.dispatch(&st.tile_count[one_page(n)], &st.footprint_layout, set, bytes, tile_chunk_groups(push));
                rec.barrier(Stage::Compute, Stage::Compute);
                rec.dispatch(&st.tile_scan, &st.footprint_layout, set, bytes, groups_1d(tiles as u32));
                rec.barrier(Stage::Compute, Stage::Compute);
                rec.dispatch(&st.tile_offsets, &st.footprint_layout, set, bytes, [1, 1, 1]);
                rec.barrier(Stage::Compute, Stage::Transfer);
                rec.copy_buffer(dev, back, (tiles + 1) * 4);
                rec.copy_buffer(status, status_back, 4);
            }),
        ));
        let timings = execute(&self.ctx, &mut self.timer, &steps)?;
        drop(steps);
        let spent = self.status()? & LOOP_BUDGET_BINNING != 0;
        let starts = back.read()?;
        let starts = bytemuck::cast_slice::<u8, u32>(&starts[..(tiles as usize + 1) * 4]);
        let total = starts[tiles as usize] as u64;
        let longest = starts.windows(2).map(|w| w[1].saturating_sub(w[0])).max().unwrap_or(0);
        crate::raster::check_tile_entries(total)?;
        let scene = self.scene.as_mut().expect("checked above");
        if grow(&self.ctx, &mut scene.tile_entries, "tile entries", total * 4, Memory::Device)? {
            scene.footprint_sets.clear();
        }
        Ok((timings, longest, spent))
    }

    /// Run the tile binning of the compute tile compositor for this frame and read it back:
    /// (each tile's first entry and the total, the entries).
    pub fn tile_lists(
        &mut self,
        prep: &Prepared,
        camera: &Camera,
        opts: &RenderOptions,
    ) -> Result<(Vec<u32>, Vec<u32>)> {
        camera.validate()?;
        let frame = frame_for(&prep.set, camera, opts);
        self.frame.write(bytemuck::bytes_of(&frame))?;
        let (w, h) = (camera.width, camera.height);
        self.ensure_target(w, h, self.target.as_ref().map(|t| t.layers).unwrap_or(1))?;
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let gpu_order = opts.order == OrderKind::Pbtf;
        if !gpu_order {
            upload_host_order(scene, prep, camera, opts.order, opts.direction())?;
        }
        let mut push = tile_push(opts, scene.n, w, h);
        self.tile_prepass(&frame, &mut push, gpu_order)?;
        self.ensure_footprint_sets()?;
        let scene = self.scene.as_ref().expect("checked above");
        let (tx, ty) = crate::cpu::tile::tile_grid(&frame);
        let tiles = tx as usize * ty as usize;
        let starts =
            bytemuck::cast_slice::<u8, u32>(scene.tile_start.as_ref().expect("grown").1.read()?)[..tiles + 1].to_vec();
        let bytes = starts[tiles] as u64 * 4;
        let readback =
            Buffer::new(&self.ctx, "tile entries readback", bytes.max(4), BU::TRANSFER_DST, Memory::Readback)?;
        let (st, entries) = (&self.stages, scene.tile_entries.as_ref().expect("grown"));
        let set = &scene.footprint_sets[0];
        self.ctx.submit(|rec| {
            rec.dispatch(
                &st.tile_scatter[one_page(scene.n)],
                &st.footprint_layout,
                set,
                bytemuck::bytes_of(&push),
                tile_chunk_groups(&push),
            );
            rec.barrier(Stage::Compute, Stage::Transfer);
            rec.copy_buffer(entries, &readback, bytes);
            Ok(())
        })?;
        let entries = bytemuck::cast_slice::<u8, u32>(&readback.read()?[..bytes as usize]).to_vec();
        Ok((starts, entries))
    }

    /// Run the binning for `frame` and read the pairs back.
    pub fn slab_pairs(&mut self, frame: &Frame, pc: &SlabPush) -> Result<Vec<u32>> {
        self.frame.write(bytemuck::bytes_of(frame))?;
        let (starts, _) = self.slab_prepass(pc)?;
        let bytes = starts[pc.slabs as usize] as u64 * 8;
        let readback = Buffer::new(&self.ctx, "pairs readback", bytes, BU::TRANSFER_DST, Memory::Readback)?;
        let (st, scene) = (&self.stages, self.scene.as_ref().expect("prepass checked"));
        let (set, pairs) = (scene.slab_set.as_ref().expect("ensured"), scene.slab_pairs.as_ref().expect("grown"));
        self.ctx.submit(|rec| {
            rec.dispatch(&st.slab_scatter, &st.slab_layout, set, bytemuck::bytes_of(pc), groups_1d(pc.chunks));
            rec.barrier(Stage::Compute, Stage::Transfer);
            rec.copy_buffer(pairs, &readback, bytes.max(4));
            Ok(())
        })?;
        Ok(bytemuck::cast_slice::<u8, u32>(&readback.read()?[..bytes as usize]).to_vec())
    }

    fn ensure_slab_set(&mut self) -> Result<()> {
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        if scene.slab_set.is_some() {
            return Ok(());
        }
        let (Some(counts), Some((starts, _))) = (&scene.slab_counts, &scene.slab_start) else {
            return Err(Error::InvalidArgument("slab buffers not allocated".into()));
        };
        let pairs = scene.slab_pairs.as_ref().unwrap_or(&scene.order);
        let [params_lo, params_hi] = pages(&scene.params);
        scene.slab_set = Some(self.stages.slab_layout.bind(&[
            params_lo,
            Bind::Buffer(counts),
            Bind::Buffer(pairs),
            Bind::Buffer(starts),
            params_hi,
        ])?);
        Ok(())
    }

    /// Build the footprint sets for the current scene and target if they are missing.
    fn ensure_footprint_sets(&mut self) -> Result<()> {
        let (Some(scene), Some(target)) = (self.scene.as_mut(), self.target.as_ref()) else {
            return Err(Error::InvalidArgument("no scene set".into()));
        };
        if !scene.footprint_sets.is_empty() {
            return Ok(());
        }
        // Buffers not allocated yet are stood in for by one the stage in use never reads.
        let stand_in = &scene.order;
        let pairs = scene.slab_pairs.as_ref().unwrap_or(stand_in);
        let fixed = target.fixed.as_ref().unwrap_or(stand_in);
        let counts = scene.tile_counts.as_ref().unwrap_or(stand_in);
        let starts = scene.tile_start.as_ref().map(|(b, _)| b).unwrap_or(stand_in);
        let entries = scene.tile_entries.as_ref().unwrap_or(stand_in);
        let quads = scene.tile_quads.as_ref().unwrap_or(stand_in);
        let mut sets = Vec::with_capacity(5);
        for list in [&scene.order, &scene.draw[0], &scene.draw[1], &scene.draw[2], pairs] {
            let [params_lo, params_hi] = pages(&scene.params);
            let [quads_lo, quads_hi] = pages(quads);
            sets.push(self.stages.footprint_layout.bind(&[
                Bind::Buffer(&self.frame),
                params_lo,
                Bind::Buffer(list),
                Bind::Buffer(&scene.splats),
                Bind::Buffer(&scene.ranks),
                Bind::Buffer(&self.radial),
                Bind::Texture(&self.slices, &self.sampler),
                Bind::Buffer(&target.occlusion),
                Bind::Buffer(fixed),
                Bind::Buffer(counts),
                Bind::Buffer(starts),
                Bind::Buffer(entries),
                Bind::Image(&target.accum),
                quads_lo,
                Bind::Buffer(&target.sheet_tiles),
                params_hi,
                quads_hi,
                Bind::Buffer(&self.status),
            ])?);
        }
        scene.footprint_sets = sets;
        Ok(())
    }

    fn ensure_target(&mut self, width: u32, height: u32, layers: u32) -> Result<()> {
        if let Some(t) = &self.target {
            if t.width == width && t.height == height && t.layers == layers {
                return Ok(());
            }
        }
        self.ctx.wait_idle();
        if let Some(scene) = self.scene.as_mut() {
            scene.footprint_sets.clear();
        }
        self.target = None;
        let ctx = &self.ctx;
        let color =
            Image::new(ctx, "color", (width, height, 1), COLOR_FORMAT, IU::COLOR_ATTACHMENT | IU::TRANSFER_SRC, false)?;
        let color_fb = Framebuffer::new(ctx, &self.stages.target_pass, &color)?;
        let sums = Image::new(
            ctx,
            "sheet sums",
            (width, height, layers),
            COLOR_FORMAT,
            IU::COLOR_ATTACHMENT | IU::STORAGE,
            true,
        )?;
        let sums_fb = Framebuffer::new(ctx, &self.stages.sheet_pass, &sums)?;
        let accum = Image::new(
            ctx,
            "accumulation",
            (width, height, 1),
            COLOR_FORMAT,
            IU::STORAGE | IU::TRANSFER_SRC | IU::TRANSFER_DST,
            false,
        )?;
        let tiles = width.div_ceil(COMPOSITE_TILE) as u64 * height.div_ceil(COMPOSITE_TILE) as u64;
        let occlusion =
            Buffer::new(ctx, "occlusion", tiles * 4, BU::STORAGE_BUFFER | BU::TRANSFER_DST, Memory::Device)?;
        let sheet_tiles = Buffer::new(
            ctx,
            "sheet tiles",
            tiles * 8,
            BU::STORAGE_BUFFER | BU::TRANSFER_DST | BU::TRANSFER_SRC,
            Memory::Device,
        )?;
        let composite_set = self.stages.composite_layout.bind(&[
            Bind::Image(&sums),
            Bind::Image(&accum),
            Bind::Buffer(&occlusion),
            Bind::Buffer(&occlusion), // stands in for the fixed-point layers until they exist
            Bind::Buffer(&sheet_tiles),
        ])?;
        let readback =
            Buffer::new(ctx, "readback", width as u64 * height as u64 * 16, BU::TRANSFER_DST, Memory::Readback)?;
        self.target = Some(TargetGpu {
            width,
            height,
            layers,
            color,
            color_fb,
            sums,
            sums_fb,
            accum,
            occlusion,
            sheet_tiles,
            tiles: tiles as u32,
            fixed: None,
            composite_set,
            readback,
        });
        Ok(())
    }

    /// Allocate the compute raster's fixed-point layers for the current target (as many as its
    /// summation image) and rebind the sets that name them.
    fn ensure_fixed_sums(&mut self) -> Result<()> {
        let target = self.target.as_mut().ok_or_else(|| Error::InvalidArgument("no target".into()))?;
        if target.fixed.is_some() {
            return Ok(());
        }
        let bytes = target.width as u64 * target.height as u64 * target.layers as u64 * 16;
        let fixed =
            Buffer::new(&self.ctx, "fixed-point sums", bytes, BU::STORAGE_BUFFER | BU::TRANSFER_DST, Memory::Device)?;
        target.composite_set = self.stages.composite_layout.bind(&[
            Bind::Image(&target.sums),
            Bind::Image(&target.accum),
            Bind::Buffer(&target.occlusion),
            Bind::Buffer(&fixed),
            Bind::Buffer(&target.sheet_tiles),
        ])?;
        target.fixed = Some(fixed);
        if let Some(scene) = self.scene.as_mut() {
            scene.footprint_sets.clear();
        }
        Ok(())
    }

    /// The per-tile sheet ranges of the last sheet-mode frame (`sheet_tiles.comp`).
    pub fn last_sheet_tiles(&self) -> Result<Vec<u32>> {
        let target = self.target.as_ref().ok_or_else(|| Error::InvalidArgument("nothing rendered yet".into()))?;
        let bytes = target.tiles as u64 * 8;
        let back = Buffer::new(&self.ctx, "sheet tiles readback", bytes, BU::TRANSFER_DST, Memory::Readback)?;
        self.ctx.submit(|rec| {
            rec.barrier(Stage::All, Stage::Transfer);
            rec.copy_buffer(&target.sheet_tiles, &back, bytes);
            Ok(())
        })?;
        Ok(bytemuck::cast_slice::<u8, u32>(&back.read()?[..bytes as usize]).to_vec())
    }

    /// Run the GPU PBTF order stage alone and read the draw sequence back.
    pub fn order(&mut self, prep: &Prepared, camera: &Camera, direction: Direction) -> Result<Vec<u32>> {
        camera.validate()?;
        let frame = crate::pipeline::order_frame(&prep.set, camera, direction);
        self.frame.write(bytemuck::bytes_of(&frame))?;
        let scene = self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let st = &self.stages;
        self.ctx.submit(|rec| {
            record_order(rec, st, scene);
            Ok(())
        })?;
        let bytes = scene.order.read()?;
        Ok(bytemuck::cast_slice::<u8, u32>(&bytes[..scene.n as usize * 4]).to_vec())
    }

    /// The GPU ray caster (`raycast.comp`), uploading the dense field on first use.
    pub fn raycast(&mut self, prep: &Prepared, camera: &Camera, opts: &RaycastOptions) -> Result<Rendered> {
        camera.validate()?;
        let params = raycast_params(&prep.set, camera, opts);
        let diagonal =
            glam::Vec3::from_slice(&params.box_max[..3]).distance(glam::Vec3::from_slice(&params.box_min[..3]));
        let steps = (diagonal / params.box_min[3]).ceil().min(opts.max_steps as f32);
        if steps > MAX_GPU_RAY_STEPS as f32 {
            return Err(Error::TooLarge(format!(
                "rays of up to {steps} samples: the GPU ray caster takes at most {MAX_GPU_RAY_STEPS} per ray (llvmpipe ends \
                 a shader's loops after 65535 iterations); use a longer step, a lower max_steps or the CPU backend"
            )));
        }
        self.ensure_target(camera.width, camera.height, self.target.as_ref().map(|t| t.layers).unwrap_or(1))?;
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let need_bricks = scene.bricks.as_ref().is_none_or(|(b, _)| *b != opts.brick);
        // The dense field is built on the host only to upload it (and its bricks), then dropped.
        let dense = if scene.field.is_none() || need_bricks { Some(DenseField::new(&prep.set)?) } else { None };
        if let (true, Some(dense)) = (need_bricks, dense.as_ref()) {
            let (_, occ) = crate::cpu::raycast::brick_occupancy(dense, opts.brick.max(1));
            scene.bricks = None;
            scene.bricks = Some((opts.brick, storage(&self.ctx, "raycast bricks", bytemuck::cast_slice(&occ))?));
        }
        if let (None, Some(dense)) = (scene.field.as_ref(), dense.as_ref()) {
            let [nx, ny, nz] = dense.dims;
            let image = Image::new_3d(
                &self.ctx,
                "raycast field",
                (nx, ny, nz),
                Format::R32G32B32A32_SFLOAT,
                IU::SAMPLED | IU::TRANSFER_DST,
            )?;
            let staging =
                Buffer::with_data(&self.ctx, "field staging", bytemuck::cast_slice(&dense.values), BU::TRANSFER_SRC)?;
            self.ctx.submit(|rec| {
                rec.transition(&image, IL::UNDEFINED, IL::TRANSFER_DST_OPTIMAL, Stage::Compute, Stage::Transfer);
                rec.copy_buffer_to_image(&staging, &image);
                rec.transition(
                    &image,
                    IL::TRANSFER_DST_OPTIMAL,
                    IL::SHADER_READ_ONLY_OPTIMAL,
                    Stage::Transfer,
                    Stage::Compute,
                );
                Ok(())
            })?;
            scene.field = Some(image);
        }
        let ubo = Buffer::with_data(&self.ctx, "raycast params", bytemuck::bytes_of(&params), BU::STORAGE_BUFFER)?;
        let (st, scene, target) =
            (&self.stages, self.scene.as_ref().expect("set"), self.target.as_ref().expect("ensured"));
        let field = scene.field.as_ref().expect("built above");
        let bricks = &scene.bricks.as_ref().expect("built above").1;
        let set = st.raycast_layout.bind(&[
            Bind::Buffer(&ubo),
            Bind::Texture(field, &self.sampler),
            Bind::Image(&target.accum),
            Bind::Buffer(bricks),
        ])?;
        let (w, h) = (camera.width, camera.height);
        let steps: Vec<Step<'_>> = vec![
            (
                UNTIMED,
                Box::new(|rec| rec.transition(&target.accum, IL::UNDEFINED, IL::GENERAL, Stage::All, Stage::Compute)),
            ),
            (
                "raycast",
                Box::new(|rec| {
                    let groups = [w.div_ceil(COMPOSITE_TILE), h.div_ceil(COMPOSITE_TILE), 1];
                    rec.dispatch(&st.raycast, &st.raycast_layout, &set, &[], groups);
                    rec.barrier(Stage::Compute, Stage::Compute);
                }),
            ),
            (UNTIMED, Box::new(|rec| read_back_accum(rec, target))),
        ];
        let timings = execute(&self.ctx, &mut self.timer, &steps)?;
        drop(steps);
        Ok(Rendered { image: read_image(&target.readback, w, h)?, timings, raster: None })
    }

    /// GPU milliseconds for `instances` additive `size`-pixel quads into a `width`x`height` RGBA32F
    /// target with the cheapest shaders (the raster roofline).
    pub fn roofline_quads(&mut self, width: u32, height: u32, size: u32, instances: u32) -> Result<f64> {
        self.ensure_target(width, height, self.target.as_ref().map(|t| t.layers).unwrap_or(1))?;
        let set = self.stages.roofline_layout.bind(&[Bind::Buffer(&self.frame)])?;
        let push: [u32; 4] = [(width / size).max(1), size, width, height];
        let (st, target) = (&self.stages, self.target.as_ref().expect("ensured"));
        let steps: Vec<Step<'_>> = vec![(
            "roofline",
            Box::new(|rec| {
                rec.begin_pass(&st.target_pass, &target.color_fb);
                rec.draw_quads(&st.roofline_quads, &st.roofline_layout, &set, bytemuck::bytes_of(&push), 0, instances);
                rec.end_pass();
            }),
        )];
        let t = execute(&self.ctx, &mut self.timer, &steps)?;
        Ok(t.first().map(|s| s.ms).unwrap_or(f64::NAN))
    }

    /// GPU milliseconds of the compositing roofline (`roofline.comp`: read `layers` summation
    /// layers, write the accumulation image) and of `composite.comp` on the same data.
    pub fn roofline_composite(&mut self, width: u32, height: u32, layers: u32) -> Result<(f64, f64)> {
        self.ensure_target(width, height, layers)?;
        let (st, target) = (&self.stages, self.target.as_ref().expect("ensured"));
        let push = CompositePush { layers, width, height, rank_dir: 1, tiles: target.tiles, ..Default::default() };
        let groups = [width.div_ceil(COMPOSITE_TILE), height.div_ceil(COMPOSITE_TILE), 1];
        let bytes = bytemuck::bytes_of(&push);
        let set = &target.composite_set;
        let steps: Vec<Step<'_>> = vec![
            (
                UNTIMED,
                Box::new(|rec| {
                    // An empty sheet pass clears the layers and leaves them in GENERAL.
                    rec.begin_pass(&st.sheet_pass, &target.sums_fb);
                    rec.end_pass();
                    rec.transition(&target.accum, IL::UNDEFINED, IL::GENERAL, Stage::All, Stage::Compute);
                    // Every layer reaches every tile: the composite reads them all.
                    fill_sheet_tiles(rec, target, [0, layers]);
                    rec.barrier(Stage::Transfer, Stage::Compute);
                }),
            ),
            (
                "roofline",
                Box::new(|rec| {
                    rec.dispatch(&st.roofline_composite, &st.composite_layout, set, bytes, groups);
                    rec.barrier(Stage::Compute, Stage::Compute);
                }),
            ),
            (
                "composite",
                Box::new(|rec| {
                    rec.dispatch(&st.composite, &st.composite_layout, set, bytes, groups);
                    rec.barrier(Stage::Compute, Stage::Compute);
                }),
            ),
        ];
        let t = execute(&self.ctx, &mut self.timer, &steps)?;
        let get = |n: &str| t.iter().find(|s| s.stage == n).map(|s| s.ms).unwrap_or(f64::NAN);
        Ok((get("roofline"), get("composite")))
    }

    /// Run the splat_params stage alone and read its output back (for comparison with the mirror).
    pub fn splat_params(
        &mut self,
        prep: &Prepared,
        camera: &Camera,
        kernel: Kernel,
        antialias: Antialias,
    ) -> Result<Vec<SplatParams>> {
        camera.validate()?;
        let split = order::pbtf_split(&prep.set, camera);
        let frame = make_frame(&prep.set, camera, kernel, antialias, None, split, true);
        self.frame.write(bytemuck::bytes_of(&frame))?;
        let scene = self.scene.as_ref().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let bytes = scene.n as u64 * std::mem::size_of::<SplatParams>() as u64;
        let readback = Buffer::new(&self.ctx, "params readback", bytes, BU::TRANSFER_DST, Memory::Readback)?;
        let st = &self.stages;
        self.ctx.submit(|rec| {
            if scene.n > 0 {
                rec.dispatch(&st.splat_params, &st.params_layout, &scene.params_set, &[], groups_1d(scene.n));
                rec.barrier(Stage::Compute, Stage::Transfer);
                rec.copy_buffer(&scene.params, &readback, bytes);
            }
            Ok(())
        })?;
        Ok(bytemuck::cast_slice::<u8, SplatParams>(&readback.read()?[..bytes as usize]).to_vec())
    }

    pub fn render(&mut self, prep: &Prepared, camera: &Camera, opts: &RenderOptions) -> Result<Rendered> {
        camera.validate()?;
        let (max_side, max_layers) = self.ctx.image_limits();
        if camera.width > max_side || camera.height > max_side {
            return Err(Error::InvalidArgument(format!(
                "image {}x{} exceeds the device's limit of {max_side} per side",
                camera.width, camera.height
            )));
        }
        self.upload_table(opts.kernel)?;
        let (w, h) = (camera.width, camera.height);
        let direction = opts.direction();
        let btf = direction == Direction::BackToFront;
        let mut layers = opts.batch_layers(w, h).min(max_layers.max(1));
        if opts.raster == Raster::Compute && opts.composite != Composite::Splat {
            // The fixed-point layers are one storage binding: no more than its range allows.
            let layer_bytes = w as u64 * h as u64 * 16;
            layers = layers.min((self.ctx.max_storage_range() / layer_bytes.max(1)).max(1) as u32);
        }
        let frame = frame_for(&prep.set, camera, opts);
        let mut host_ms = None;
        let mut pre_timings = Vec::new();
        let mut slab_pc = None;
        self.frame.write(bytemuck::bytes_of(&frame))?;
        let (axis, mut batches) = match opts.composite {
            Composite::Sheet => sheet_plan(prep, camera, direction, layers),
            Composite::Slab => {
                let pc = crate::slab::slab_geometry(
                    &frame,
                    prep.set.grid(),
                    prep.set.len(),
                    opts.slab_thickness,
                    direction,
                )?;
                let (starts, t) = self.slab_prepass(&pc)?;
                pre_timings = t;
                slab_pc = Some(pc);
                (0, crate::slab::slab_batches(&pc, &starts, layers)?)
            }
            Composite::Splat => (0, Vec::new()),
        };
        opts.set_early_termination(&mut batches);
        let points = opts.raster == Raster::Points;
        let compute = opts.raster == Raster::Compute;
        let tiles = compute && opts.composite == Composite::Splat;
        // Allocate only as many layers as the largest batch needs.
        let layers = batches.iter().map(|b| b.layers).max().unwrap_or(1);
        self.ensure_target(w, h, layers)?;
        if compute && !tiles {
            self.ensure_fixed_sums()?;
        }
        let scene = self.scene.as_mut().ok_or_else(|| Error::InvalidArgument("no scene set".into()))?;
        let gpu_order = opts.composite == Composite::Splat && opts.order == OrderKind::Pbtf;
        if opts.composite == Composite::Splat && !gpu_order {
            let t = Instant::now();
            upload_host_order(scene, prep, camera, opts.order, direction)?;
            host_ms = Some(("order_cpu", t));
        }
        let host_ms = host_ms.map(|(stage, t)| StageTime { stage, ms: t.elapsed().as_secs_f64() * 1e3 });
        let mut tile_pc = tile_push(opts, scene.n, w, h);
        // The compositor takes each tile's list TILE_SEGMENT entries per dispatch (see constants.rs).
        let mut segments = vec![tile_pc];
        if tiles {
            let (timings, longest) = self.tile_prepass(&frame, &mut tile_pc, gpu_order)?;
            pre_timings = timings;
            segments =
                (0..longest.div_ceil(TILE_SEGMENT).max(1)).map(|s| FootprintPush { first: s, ..tile_pc }).collect();
        }
        self.ensure_footprint_sets()?;
        let (st, scene, target) =
            (&self.stages, self.scene.as_ref().expect("set above"), self.target.as_ref().expect("ensured"));
        let (status, status_back) = (&self.status, &self.status_back);
        let n = scene.n;
        let mut steps: Vec<Step<'_>> = Vec::new();
        if gpu_order && n > 0 && !tiles {
            steps.push(("order", Box::new(|rec| record_order(rec, st, scene))));
        }
        if let (Some(pc), Some(set)) = (slab_pc.as_ref(), scene.slab_set.as_ref()) {
            steps.push((
                "slab_bins",
                Box::new(move |rec| {
                    let push = bytemuck::bytes_of(pc);
                    rec.dispatch(&st.slab_scatter, &st.slab_layout, set, push, groups_1d(pc.chunks));
                    rec.barrier(Stage::Compute, Stage::All);
                }),
            ));
        } else if n > 0 && !tiles {
            steps.push((
                "splat_params",
                Box::new(|rec| {
                    rec.dispatch(&st.splat_params, &st.params_layout, &scene.params_set, &[], groups_1d(n));
                    rec.barrier(Stage::Compute, Stage::All);
                }),
            ));
        }
        match opts.composite {
            Composite::Splat if tiles => {
                let set = &scene.footprint_sets[0];
                let push = bytemuck::bytes_of(&tile_pc);
                steps.push((
                    "tile_bins",
                    Box::new(move |rec| {
                        rec.dispatch(
                            &st.tile_scatter[one_page(n)],
                            &st.footprint_layout,
                            set,
                            push,
                            tile_chunk_groups(&tile_pc),
                        );
                        rec.barrier(Stage::Compute, Stage::Compute);
                    }),
                ));
                steps.push((
                    UNTIMED,
                    Box::new(|rec| {
                        rec.transition(&target.accum, IL::UNDEFINED, IL::GENERAL, Stage::All, Stage::Compute)
                    }),
                ));
                steps.push((
                    "footprint",
                    Box::new(move |rec| {
                        let groups = [w.div_ceil(RASTER_TILE_W), h.div_ceil(RASTER_TILE_H), 1];
                        let pipe = tile_composite_pipe(st, n, &tile_pc, opts.motion.is_some());
                        for segment in &segments {
                            let push = bytemuck::bytes_of(segment);
                            rec.dispatch(pipe, &st.footprint_layout, set, push, groups);
                            rec.barrier(Stage::Compute, Stage::Compute);
                        }
                    }),
                ));
                steps.push((UNTIMED, Box::new(|rec| read_back_accum(rec, target))));
            }
            Composite::Splat => {
                steps.push((
                    "footprint",
                    Box::new(move |rec| {
                        rec.begin_pass(&st.target_pass, &target.color_fb);
                        if n > 0 {
                            let push = FootprintPush::default();
                            let push = bytemuck::bytes_of(&push);
                            let set = &scene.footprint_sets[0];
                            let layout = &st.footprint_layout;
                            match (points, btf) {
                                (false, true) => rec.draw_quads(&st.over, layout, set, push, 0, n),
                                (false, false) => rec.draw_quads(&st.under, layout, set, push, 0, n),
                                (true, true) => rec.draw_points(&st.over_points, layout, set, push, 0, n),
                                (true, false) => rec.draw_points(&st.under_points, layout, set, push, 0, n),
                            }
                        }
                        rec.end_pass();
                    }),
                ));
                steps.push((
                    UNTIMED,
                    Box::new(|rec| rec.copy_image_to_buffer(&target.color, IL::TRANSFER_SRC_OPTIMAL, &target.readback)),
                ));
            }
            Composite::Sheet | Composite::Slab => {
                let set = match opts.composite {
                    Composite::Slab => &scene.footprint_sets[4],
                    _ => &scene.footprint_sets[1 + axis],
                };
                steps.push((
                    UNTIMED,
                    Box::new(|rec| {
                        rec.transition(&target.accum, IL::UNDEFINED, IL::GENERAL, Stage::All, Stage::Transfer);
                        rec.clear_image(&target.accum, IL::GENERAL, [0.0; 4]);
                        rec.fill_buffer(&target.occlusion, 1.0f32.to_bits());
                        if compute {
                            rec.fill_buffer(status, 0);
                            // composite.comp's fixed-point variant still names the sums image.
                            rec.transition(&target.sums, IL::UNDEFINED, IL::GENERAL, Stage::All, Stage::Compute);
                        }
                        rec.barrier(Stage::Transfer, Stage::All);
                    }),
                ));
                match batches.first().filter(|_| crate::pipeline::sheet_tiles_pay(&batches, w, h)) {
                    None => steps.push((
                        UNTIMED,
                        Box::new(|rec| {
                            fill_sheet_tiles(rec, target, crate::pipeline::ALL_SHEETS);
                            rec.barrier(Stage::Transfer, Stage::All);
                        }),
                    )),
                    Some(first) => {
                        let slab = first.push.sheet_mode == SHEET_MODE_SLAB;
                        let push = crate::pipeline::sheet_tiles_push(&batches, first);
                        let entries = push.count;
                        steps.push((
                            "sheet_tiles",
                            Box::new(move |rec| {
                                // No sheet reaches any tile until the pass says so.
                                fill_sheet_tiles(rec, target, [u32::MAX, 0]);
                                rec.barrier(Stage::Transfer, Stage::Compute);
                                let pipe = &st.sheet_tiles[2 * slab as usize + points as usize];
                                let bytes = bytemuck::bytes_of(&push);
                                rec.dispatch(pipe, &st.footprint_layout, set, bytes, groups_1d(entries));
                                rec.barrier(Stage::Compute, Stage::Compute);
                            }),
                        ));
                    }
                }
                for b in &batches {
                    let slab = b.push.sheet_mode == SHEET_MODE_SLAB;
                    steps.push((
                        "footprint",
                        Box::new(move |rec| {
                            if let (true, Some(fixed)) = (compute, target.fixed.as_ref()) {
                                rec.fill_buffer(fixed, 0);
                                rec.barrier(Stage::Transfer, Stage::Compute);
                                let push = FootprintPush { first: b.first_instance, count: b.instances, ..b.push };
                                let pipe = if slab { &st.sum_slab } else { &st.sum_axis };
                                let push = bytemuck::bytes_of(&push);
                                rec.dispatch(pipe, &st.footprint_layout, set, push, groups_1d(b.instances));
                                rec.barrier(Stage::Compute, Stage::Compute);
                                return;
                            }
                            rec.begin_pass(&st.sheet_pass, &target.sums_fb);
                            let push = bytemuck::bytes_of(&b.push);
                            let layout = &st.footprint_layout;
                            let (first, count) = (b.first_instance, b.instances);
                            match (points, slab) {
                                (false, false) => rec.draw_quads(&st.add, layout, set, push, first, count),
                                (false, true) => rec.draw_quads(&st.add_slab, layout, set, push, first, count),
                                (true, false) => rec.draw_points(&st.add_points, layout, set, push, first, count),
                                (true, true) => rec.draw_points(&st.add_slab_points, layout, set, push, first, count),
                            }
                            rec.end_pass();
                        }),
                    ));
                    steps.push((
                        "composite",
                        Box::new(move |rec| {
                            let push = crate::pipeline::composite_push(b, btf, w, h);
                            let groups = [w.div_ceil(COMPOSITE_TILE), h.div_ceil(COMPOSITE_TILE), 1];
                            let set = &target.composite_set;
                            let pipe = if compute { &st.composite_fixed } else { &st.composite };
                            rec.dispatch(pipe, &st.composite_layout, set, bytemuck::bytes_of(&push), groups);
                            // The next batch's footprints read the occlusion map.
                            rec.barrier(Stage::Compute, Stage::All);
                        }),
                    ));
                }
                steps.push((
                    UNTIMED,
                    Box::new(move |rec| {
                        read_back_accum(rec, target);
                        if compute {
                            rec.copy_buffer(status, status_back, 4);
                        }
                    }),
                ));
            }
        }
        let mut timings = execute(&self.ctx, &mut self.timer, &steps)?;
        drop(steps);
        let sums = compute && matches!(opts.composite, Composite::Sheet | Composite::Slab);
        if sums && self.status()? & LOOP_BUDGET_SUMS != 0 {
            return Err(Error::TooLarge(
                "a footprint larger than about 240 x 240 pixels: the compute sheet sums ran out of llvmpipe's 65535 \
                 loop iterations per invocation; draw this frame with --raster graphics or points"
                    .into(),
            ));
        }
        if let Some(t) = host_ms {
            timings.insert(0, t);
        }
        // The slab or tile pre-pass ran first.
        merge_timings(&mut pre_timings, timings);
        let timings = pre_timings;
        let target = self.target.as_ref().expect("ensured");
        Ok(Rendered { image: read_image(&target.readback, w, h)?, timings, raster: None })
    }
}

/// A named piece of GPU work; `UNTIMED` steps (layout transitions, copies) are not reported.
type Step<'a> = (&'static str, Box<dyn Fn(&Recorder<'_>) + 'a>);
const UNTIMED: &str = "";

/// Run `steps` and time each named stage (summed over steps of the same name, in first-seen
/// order). On a GPU: one submission with a timestamp after every step. On a CPU device (lavapipe)
/// timestamps are taken when the rasterizer next flushes, not when compute work ends, so there each
/// step is its own submission timed on the host (fence to fence, so submission overhead is
/// included).
fn execute(ctx: &Arc<Context>, timer: &mut Timer, steps: &[Step<'_>]) -> Result<Vec<StageTime>> {
    let mut per_step = vec![0.0f64; steps.len()];
    if ctx.is_cpu_device() || ctx.timestamp_period.is_none() {
        for (i, (_, f)) in steps.iter().enumerate() {
            let t = Instant::now();
            ctx.submit(|rec| {
                f(rec);
                Ok(())
            })?;
            per_step[i] = t.elapsed().as_secs_f64() * 1e3;
        }
    } else {
        let needed = steps.len() as u32 + 1;
        if timer.capacity < needed {
            *timer = Timer::new(ctx, needed.next_power_of_two())?;
        }
        let timer = &*timer;
        ctx.submit(|rec| {
            rec.reset_timer(timer);
            rec.timestamp(timer, 0);
            for (i, (_, f)) in steps.iter().enumerate() {
                f(rec);
                rec.timestamp(timer, i as u32 + 1);
            }
            Ok(())
        })?;
        if let Some(ms) = timer.read_ms(needed)? {
            per_step.copy_from_slice(&ms);
        }
    }
    let mut out: Vec<StageTime> = Vec::new();
    for ((name, _), ms) in steps.iter().zip(per_step) {
        if name.is_empty() {
            continue;
        }
        match out.iter_mut().find(|t| t.stage == *name) {
            Some(t) => t.ms += ms,
            None => out.push(StageTime { stage: name, ms }),
        }
    }
    Ok(out)
}

/// Copy the accumulation image (written by compute, in GENERAL) to the readback buffer.
fn read_back_accum(rec: &Recorder<'_>, target: &TargetGpu) {
    rec.transition(&target.accum, IL::GENERAL, IL::TRANSFER_SRC_OPTIMAL, Stage::Compute, Stage::Transfer);
    rec.copy_image_to_buffer(&target.accum, IL::TRANSFER_SRC_OPTIMAL, &target.readback);
}

fn read_image(readback: &Buffer, w: u32, h: u32) -> Result<ImageF32> {
    let bytes = readback.read()?;
    let floats: &[f32] = bytemuck::cast_slice(&bytes[..(w * h * 16) as usize]);
    let pixels = floats.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    Ok(ImageF32 { width: w, height: h, pixels })
}

/// Upload a visibility order computed on the host (orders other than PBTF) as the draw list.
fn upload_host_order(
    scene: &mut SceneGpu,
    prep: &Prepared,
    camera: &Camera,
    kind: OrderKind,
    dir: Direction,
) -> Result<()> {
    scene.order.write(bytemuck::cast_slice(&order::visibility_order(&prep.set, camera, kind, dir)))
}

/// Set every tile's sheet range to [lowest, highest + 1) = `range`.
fn fill_sheet_tiles(rec: &Recorder<'_>, target: &TargetGpu, range: [u32; 2]) {
    let half = target.tiles as u64 * 4;
    rec.fill_buffer_range(&target.sheet_tiles, 0, half, range[0]);
    rec.fill_buffer_range(&target.sheet_tiles, half, half, range[1]);
}

/// The tile compositor's builds: (back to front, early termination), each still and motion-blurred,
/// for two pages of splat records and for one (`ONE_PAGE`, types.glsl).
const TILE_COMPOSITE_MODES: [(bool, bool); 3] = [(true, false), (false, false), (false, true)];

/// The compositor pipeline for a scene of `n` splats, the frame's push constants and whether it is
/// motion-blurred.
fn tile_composite_pipe<'a>(st: &'a Stages, n: u32, push: &FootprintPush, blur: bool) -> &'a Pipeline {
    let btf = push.back_to_front != 0;
    let mode = (btf, !btf && push.occluded > 0.0);
    let m = TILE_COMPOSITE_MODES.iter().position(|&x| x == mode).expect("every mode is built");
    &st.tile_composite[(one_page(n) * TILE_COMPOSITE_MODES.len() + m) * 2 + usize::from(blur)]
}

/// 1 where a scene of `n` splats fits one page of splat records (the `ONE_PAGE` builds read only
/// that page: llvmpipe runs both sides of the paged reader's branch), else 0.
fn one_page(n: u32) -> usize {
    usize::from(n <= SPLAT_PAGE)
}

/// Workgroups of the tile binning passes that walk the draw list chunk by chunk.
fn tile_chunk_groups(push: &FootprintPush) -> [u32; 3] {
    [push.chunks.div_ceil(TILE_BIN_WORKGROUP), 1, 1]
}

fn record_order(rec: &crate::vk::Recorder<'_>, st: &Stages, scene: &SceneGpu) {
    if scene.n == 0 {
        return;
    }
    rec.dispatch(&st.order_count, &st.order_layout, &scene.order_set, &[], groups_1d(scene.rows));
    rec.barrier(Stage::Compute, Stage::Compute);
    rec.dispatch(&st.order_scan, &st.order_layout, &scene.order_set, &[], [1, 1, 1]);
    rec.barrier(Stage::Compute, Stage::Compute);
    rec.dispatch(&st.order_scatter, &st.order_layout, &scene.order_set, &[], groups_1d(scene.n));
    rec.barrier(Stage::Compute, Stage::Graphics);
}

impl Drop for GpuPipeline {
    fn drop(&mut self) {
        // Resources free themselves; make sure the GPU is done with them first.
        self.ctx.wait_idle();
    }
}
