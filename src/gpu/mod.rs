//! The Vulkan side: pipelines built from the stage table (`pipelines`), resources by name
//! (`resources`), the engine that runs a frame's recording (`exec`); and the two passes outside
//! the frame recording: the bench's rooflines (and the ray caster's field upload, a scene cache).
pub mod exec;
pub mod pipelines;
pub mod resources;

use crate::constants::COMPOSITE_TILE;
use crate::error::Result;
use crate::gpu_types::CompositePush;
use crate::plan::Prepared;
use crate::shaders::spirv_build;
use crate::stages::{List, Res, StageId};
use crate::vk::{
    Bind, Blend, Buffer, BufferUsageFlags as BU, Context, Format, Image, ImageLayout as IL, ImageUsageFlags as IU,
    Layout, Pipeline, Primitive, ShaderStageFlags as SS, Slot, Stage, Timer,
};
use crate::volume::DenseField;
use pipelines::Pipelines;
use resources::Resources;
use std::sync::Arc;
use std::time::Instant;

/// Passes that are not stages of a frame: the rooflines.
struct Extra {
    roofline_layout: Layout,
    roofline_quads: Pipeline,
    roofline_composite: Pipeline,
}

/// A renderer's device state.
pub struct Gpu {
    pub(crate) pipes: Pipelines,
    pub(crate) res: Resources,
    pub(crate) timer: Timer,
    extra: Extra,
    pub(crate) ctx: Arc<Context>,
    /// Device memory a frame may hold (`Limits::budget_bytes`).
    pub(crate) budget_bytes: u64,
}

impl Gpu {
    pub fn new(ctx: Arc<Context>) -> Result<Self> {
        let pipes = Pipelines::new(&ctx)?;
        let roofline_layout = Layout::new(&ctx, &[Slot::Uniform], SS::VERTEX | SS::FRAGMENT, 16)?;
        let composite_layout = &pipes.stages[StageId::Composite as usize].layout;
        let extra = Extra {
            roofline_quads: Pipeline::graphics(
                &ctx,
                &roofline_layout,
                &pipes.target_pass,
                spirv_build(crate::shaders::roofline::VERT, "", "roofline")?,
                spirv_build(crate::shaders::roofline::FRAG, "", "roofline")?,
                Blend::Add,
                Primitive::Quads,
                &[],
            )?,
            roofline_composite: Pipeline::compute(
                &ctx,
                composite_layout,
                spirv_build(crate::shaders::roofline::COMP, "", "roofline")?,
            )?,
            roofline_layout,
        };
        let budget_bytes = ctx.choices().default_budget;
        Ok(Self { res: Resources::new(&ctx)?, timer: Timer::new(&ctx, 16)?, pipes, extra, ctx, budget_bytes })
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    pub fn set_scene(&mut self, prep: &Prepared) -> Result<()> {
        self.res.set_scene(prep, self.budget_bytes)
    }

    /// Follow `patch` of the scene's store (`Resources::patch_store`); the bytes written.
    pub fn patch_store(&mut self, prep: &Prepared, patch: &crate::bricks::Patch) -> Result<u64> {
        self.res.patch_store(prep, patch, self.budget_bytes)
    }

    /// An engine for one frame of `prep` (the scene `set_scene` uploaded).
    pub fn engine<'a>(&'a mut self, prep: &'a Prepared) -> exec::GpuEngine<'a> {
        exec::GpuEngine::new(self, prep)
    }

    /// An engine for one frame of `prep` that goes into the host's image `target`.
    pub fn engine_to<'a>(&'a mut self, prep: &'a Prepared, target: &'a crate::vk::HostTarget) -> exec::GpuEngine<'a> {
        exec::GpuEngine::to_target(self, prep, target)
    }

    /// The dense field as a 3D texture and its brick occupancy for `brick`, built once per scene
    /// (the host copy is dropped after the upload).
    pub(crate) fn upload_field(&mut self, prep: &Prepared, brick: u32, mode: crate::options::Mode) -> Result<()> {
        let kind = crate::plan::FieldKind::of(mode);
        let scene = self.res.scene_mut()?;
        // One field at a time: a frame of another kind replaces it, with its bricks.
        let need_bricks = scene.bricks.as_ref().is_none_or(|(b, _)| *b != brick) || scene.field_kind != kind;
        if scene.field_kind != kind {
            scene.field = None;
        }
        if scene.field.is_some() && !need_bricks {
            return Ok(());
        }
        self.res.clear_sets();
        let scene = self.res.scene_mut()?;
        scene.field_kind = kind;
        let dense = match kind {
            crate::plan::FieldKind::Composite => DenseField::new(&prep.set)?,
            crate::plan::FieldKind::Projection => DenseField::projection(&prep.set)?,
            crate::plan::FieldKind::Iso => prep.iso_field()?.dense(),
        };
        if need_bricks {
            let (_, occ) = dense.brick_occupancy(brick.max(1));
            scene.bricks = None;
            let buf = Buffer::with_data(&self.ctx, "raycast bricks", bytemuck::cast_slice(&occ), BU::STORAGE_BUFFER)?;
            scene.bricks = Some((brick, buf));
        }
        if scene.field.is_none() {
            let [nx, ny, nz] = dense.dims;
            let usage = IU::SAMPLED | IU::TRANSFER_DST;
            let image = Image::new_3d(&self.ctx, "raycast field", (nx, ny, nz), Format::R32G32B32A32_SFLOAT, usage)?;
            let staging =
                Buffer::with_data(&self.ctx, "field staging", bytemuck::cast_slice(&dense.values), BU::TRANSFER_SRC)?;
            self.ctx.submit(|rec| {
                rec.transition(&image, IL::UNDEFINED, IL::TRANSFER_DST_OPTIMAL, Stage::Compute, Stage::Transfer);
                rec.copy_buffer_to_image(&staging, &image);
                let to = IL::SHADER_READ_ONLY_OPTIMAL;
                rec.transition(&image, IL::TRANSFER_DST_OPTIMAL, to, Stage::Transfer, Stage::Compute);
                Ok(())
            })?;
            scene.field = Some(image);
        }
        Ok(())
    }

    /// GPU milliseconds for `instances` additive `size`-pixel quads into a `width`x`height` RGBA32F
    /// target with the cheapest shaders (the raster roofline).
    pub fn roofline_quads(&mut self, width: u32, height: u32, size: u32, instances: u32) -> Result<f64> {
        let layers = self.res.current_target().map(|t| t.layers).unwrap_or(1);
        self.res.target(&self.pipes, width, height, layers)?;
        let set = self.extra.roofline_layout.bind(&[Bind::Buffer(&self.res.frame)])?;
        let push: [u32; 4] = [(width / size).max(1), size, width, height];
        let target = self.res.current_target()?;
        let t = Instant::now();
        self.ctx.submit(|rec| {
            rec.begin_pass(&self.pipes.target_pass, &target.color_fb);
            let (pipe, layout) = (&self.extra.roofline_quads, &self.extra.roofline_layout);
            rec.draw_quads(pipe, layout, &set, bytemuck::bytes_of(&push), 0, instances);
            rec.end_pass();
            Ok(())
        })?;
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    /// GPU milliseconds of the compositing roofline (`roofline.comp`: read `layers` summation
    /// layers, write the accumulation image) and of `composite.comp` on the same data.
    pub fn roofline_composite(&mut self, width: u32, height: u32, layers: u32) -> Result<(f64, f64)> {
        self.res.target(&self.pipes, width, height, layers)?;
        let tiles = width.div_ceil(COMPOSITE_TILE) as u64 * height.div_ceil(COMPOSITE_TILE) as u64;
        self.res.ensure(Res::Occlusion, tiles * 4)?;
        self.res.ensure(Res::SheetTiles, tiles * 8)?;
        self.res.ensure_set(&self.pipes, StageId::Composite, List::Order)?;
        let push = CompositePush { layers, width, height, rank_dir: 1, tiles: tiles as u32, ..Default::default() };
        let groups = [width.div_ceil(COMPOSITE_TILE), height.div_ceil(COMPOSITE_TILE), 1];
        let (res, target) = (&self.res, self.res.current_target()?);
        let set = res.set(StageId::Composite, List::Order)?;
        let stage = &self.pipes.stages[StageId::Composite as usize];
        let sheet_tiles = res.buffer(Res::SheetTiles)?;
        self.ctx.submit(|rec| {
            // An empty sheet pass clears the layers and leaves them in GENERAL.
            rec.begin_pass(&self.pipes.sheet_pass, &target.sums_fb);
            rec.end_pass();
            rec.transition(&target.accum, IL::UNDEFINED, IL::GENERAL, Stage::All, Stage::Compute);
            // Every layer reaches every tile: the composite reads them all.
            rec.fill_buffer_range(sheet_tiles, 0, tiles * 4, 0);
            rec.fill_buffer_range(sheet_tiles, tiles * 4, tiles * 4, layers);
            rec.barrier(Stage::Transfer, Stage::Compute);
            Ok(())
        })?;
        let time = |pipe: &Pipeline| -> Result<f64> {
            let t = Instant::now();
            self.ctx.submit(|rec| {
                rec.dispatch(pipe, &stage.layout, set, bytemuck::bytes_of(&push), groups);
                rec.barrier(Stage::Compute, Stage::Compute);
                Ok(())
            })?;
            Ok(t.elapsed().as_secs_f64() * 1e3)
        };
        let roofline = time(&self.extra.roofline_composite)?;
        let composite = time(&stage.variants[0])?;
        Ok((roofline, composite))
    }
}
