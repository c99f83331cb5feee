//! Every stage's descriptor layout and pipelines, built from the stage table.
use crate::error::{Error, Result};
use crate::shaders::{spirv_build, Shaders};
use crate::stages::{Feature, Kind, Pass, Res, StageDesc, STAGES};
use crate::vk::{
    Blend, Context, Format, ImageLayout as IL, Layout, Pipeline, Primitive, RenderPass, ShaderStageFlags as SS, Slot,
};
use std::sync::Arc;

/// The attachments' format (RGBA32F, blendable on lavapipe).
pub const COLOR_FORMAT: Format = Format::R32G32B32A32_SFLOAT;

/// What binding slot a resource takes.
fn slot(res: Res) -> Slot {
    match res {
        Res::SliceTable | Res::Field => Slot::Texture,
        Res::Accum | Res::Sums | Res::Color => Slot::StorageImage,
        _ => Slot::Storage,
    }
}

/// One stage's layout and its builds, in the order of its `variants`.
pub struct StagePipelines {
    pub layout: Layout,
    pub variants: Vec<Pipeline>,
}

/// The pipelines of every stage (indexed like `STAGES`) and the two render passes.
pub struct Pipelines {
    pub stages: Vec<StagePipelines>,
    /// Into the raster target (left in TRANSFER_SRC for the readback), and into the summation
    /// layers (left in GENERAL for the composite pass).
    pub target_pass: RenderPass,
    /// The same, drawing on the target (a later batch of a bricked volume).
    pub target_load_pass: RenderPass,
    pub sheet_pass: RenderPass,
    /// The same, summing onto the layers (a later part of a bricked volume's sheet batch).
    pub sheet_load_pass: RenderPass,
    /// Into the target and the accumulation image at once (`Pass::Slots`; both left in
    /// TRANSFER_SRC for the readback).
    pub slots_pass: RenderPass,
}

impl Pipelines {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let target_pass = RenderPass::new(ctx, COLOR_FORMAT, IL::TRANSFER_SRC_OPTIMAL, false)?;
        let target_load_pass = RenderPass::new(ctx, COLOR_FORMAT, IL::TRANSFER_SRC_OPTIMAL, true)?;
        let sheet_pass = RenderPass::new(ctx, COLOR_FORMAT, IL::GENERAL, false)?;
        let sheet_load_pass = RenderPass::new(ctx, COLOR_FORMAT, IL::GENERAL, true)?;
        let slots_pass = RenderPass::with_attachments(ctx, COLOR_FORMAT, 2, IL::TRANSFER_SRC_OPTIMAL, false)?;
        let mut stages = Vec::with_capacity(STAGES.len());
        for desc in STAGES.iter() {
            stages.push(build(ctx, desc, [&target_pass, &sheet_pass, &slots_pass])?);
        }
        Ok(Self { stages, target_pass, target_load_pass, sheet_pass, sheet_load_pass, slots_pass })
    }
}

fn has(ctx: &Context, feature: Feature) -> bool {
    match feature {
        Feature::SubgroupShuffle => ctx.subgroup_shuffle(),
        Feature::Int64Atomics => ctx.int64_atomics(),
    }
}

/// A driver's refusal of a stage's pipeline names the stage: a driver, or a layer instrumenting the
/// shader, can refuse one shader of many with nothing more than `VK_ERROR_UNKNOWN`.
fn refused_stage(e: Error, stage: &str) -> Error {
    match e {
        Error::Vulkan { call, result } => {
            Error::Unsupported(format!("the driver refused the pipeline of stage {stage} ({call}: {result})"))
        }
        e => e,
    }
}

fn build(ctx: &Arc<Context>, desc: &StageDesc, passes: [&RenderPass; 3]) -> Result<StagePipelines> {
    let slots: Vec<Slot> = desc.bindings.iter().map(|&r| slot(r)).collect();
    let flags = match desc.kind {
        Kind::Compute => SS::COMPUTE,
        Kind::Draw => SS::VERTEX | SS::FRAGMENT,
    };
    let layout = Layout::new(ctx, &slots, flags, desc.push)?;
    let device = desc.device_build.filter(|(f, _)| has(ctx, *f)).map(|(_, d)| d);
    let mut variants = Vec::with_capacity(desc.builds.variants.len());
    for v in desc.builds.variants {
        let defines: Vec<&str> = device.into_iter().chain((!v.defines.is_empty()).then_some(v.defines)).collect();
        let defines = defines.join("+");
        let pipe = match (desc.kind, v.draw, desc.shaders) {
            (Kind::Compute, _, Shaders::Compute(comp)) => {
                Pipeline::compute_specialized(ctx, &layout, spirv_build(comp, &defines, desc.name)?, v.spec)
                    .map_err(|e| refused_stage(e, desc.name))?
            }
            (Kind::Draw, Some(state), Shaders::Draw(vert, frag)) => {
                let vert = spirv_build(vert, &defines, desc.name)?;
                let frag = spirv_build(frag, &defines, desc.name)?;
                let blend = match state.blend {
                    crate::dispatch::Blend::Over => Blend::Over,
                    crate::dispatch::Blend::Under => Blend::Under,
                    crate::dispatch::Blend::Add => Blend::Add,
                    crate::dispatch::Blend::Max => Blend::Max,
                };
                let primitive = if state.points { Primitive::Points } else { Primitive::Quads };
                let pass = match state.pass {
                    Pass::Target => passes[0],
                    Pass::Sheet => passes[1],
                    Pass::Slots => passes[2],
                };
                Pipeline::graphics(ctx, &layout, pass, vert, frag, blend, primitive, v.spec)
                    .map_err(|e| refused_stage(e, desc.name))?
            }
            (Kind::Draw, None, _) => {
                return Err(Error::Unsupported(format!("{}: a draw variant without raster state", desc.name)))
            }
            _ => return Err(Error::Unsupported(format!("{}: its shaders are not of its kind", desc.name))),
        };
        variants.push(pipe);
    }
    Ok(StagePipelines { layout, variants })
}
