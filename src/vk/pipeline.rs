//! Descriptor layouts and sets, compute and graphics pipelines, render passes — all freed in Drop.
use super::{Buffer, Context, Image, Sampler};
use crate::error::{Error, Result};
use ash::vk;
use std::sync::Arc;

/// What a binding slot holds. Slots are numbered by their position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// A uniform buffer.
    Uniform,
    /// A storage buffer.
    Storage,
    /// A storage image (GENERAL layout).
    StorageImage,
    /// A sampled image with its sampler.
    Texture,
    /// A slot number the stage does not use (keeps binding numbers aligned with the GLSL).
    Unused,
}

impl Slot {
    fn kind(self) -> Option<vk::DescriptorType> {
        match self {
            Slot::Uniform => Some(vk::DescriptorType::UNIFORM_BUFFER),
            Slot::Storage => Some(vk::DescriptorType::STORAGE_BUFFER),
            Slot::StorageImage => Some(vk::DescriptorType::STORAGE_IMAGE),
            Slot::Texture => Some(vk::DescriptorType::COMBINED_IMAGE_SAMPLER),
            Slot::Unused => None,
        }
    }
}

/// A resource bound to a slot.
pub enum Bind<'a> {
    /// The whole buffer; a storage buffer larger than the device's binding range is refused.
    Buffer(&'a Buffer),
    /// `range` bytes of a buffer from `offset` (a multiple of the device's offset alignment).
    Range(&'a Buffer, u64, u64),
    /// A storage image.
    Image(&'a Image),
    /// A sampled image and its sampler.
    Texture(&'a Image, &'a Sampler),
    /// Nothing (an unused slot).
    None,
}

/// A descriptor set layout plus the pipeline layout built on it (one set, one push range).
pub struct Layout {
    ctx: Arc<Context>,
    slots: Vec<Slot>,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) pipeline_layout: vk::PipelineLayout,
    pub(crate) push_stages: vk::ShaderStageFlags,
}

impl Layout {
    /// A layout whose slot i holds `slots[i]`, visible to `stages`, with `push_size` bytes of push constants.
    pub fn new(ctx: &Arc<Context>, slots: &[Slot], stages: vk::ShaderStageFlags, push_size: u32) -> Result<Self> {
        let bindings: Vec<_> = slots
            .iter()
            .enumerate()
            .filter_map(|(i, s)| {
                s.kind().map(|k| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(i as u32)
                        .descriptor_type(k)
                        .descriptor_count(1)
                        .stage_flags(stages)
                })
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
        // SAFETY: valid create info.
        let set_layout = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
            .map_err(Error::vk("vkCreateDescriptorSetLayout"))?;
        let set_layouts = [set_layout];
        let ranges = [vk::PushConstantRange { stage_flags: stages, offset: 0, size: push_size }];
        let mut pinfo = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_size > 0 {
            pinfo = pinfo.push_constant_ranges(&ranges);
        }
        // SAFETY: valid create info.
        let pipeline_layout = match unsafe { ctx.device.create_pipeline_layout(&pinfo, None) } {
            Ok(l) => l,
            Err(e) => {
                // SAFETY: unused layout.
                unsafe { ctx.device.destroy_descriptor_set_layout(set_layout, None) };
                return Err(Error::vk("vkCreatePipelineLayout")(e));
            }
        };
        Ok(Self { ctx: ctx.clone(), slots: slots.to_vec(), set_layout, pipeline_layout, push_stages: stages })
    }

    /// A descriptor set with `binds[i]` in slot i.
    pub fn bind(&self, binds: &[Bind<'_>]) -> Result<DescriptorSet> {
        if binds.len() != self.slots.len() {
            return Err(Error::InvalidArgument(format!("{} binds for {} slots", binds.len(), self.slots.len())));
        }
        let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
        for s in &self.slots {
            if let Some(k) = s.kind() {
                match sizes.iter_mut().find(|p| p.ty == k) {
                    Some(p) => p.descriptor_count += 1,
                    None => sizes.push(vk::DescriptorPoolSize { ty: k, descriptor_count: 1 }),
                }
            }
        }
        let info = vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes);
        // SAFETY: valid create info.
        let pool = unsafe { self.ctx.device.create_descriptor_pool(&info, None) }
            .map_err(Error::vk("vkCreateDescriptorPool"))?;
        let mut set = DescriptorSet { ctx: self.ctx.clone(), pool, raw: vk::DescriptorSet::null() };
        let layouts = [self.set_layout];
        let alloc = vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts);
        // SAFETY: the pool was sized for exactly this layout.
        let raw = unsafe { self.ctx.device.allocate_descriptor_sets(&alloc) }
            .map_err(Error::vk("vkAllocateDescriptorSets"))?[0];
        set.raw = raw;

        let mut buffer_infos = Vec::new();
        let mut image_infos = Vec::new();
        let limit = self.ctx.max_storage_range();
        let too_large = |bytes: u64| {
            Error::TooLarge(format!(
                "a storage binding of {bytes} bytes exceeds this device's maxStorageBufferRange ({limit} bytes)"
            ))
        };
        for (slot, b) in self.slots.iter().zip(binds) {
            match (slot, b) {
                (Slot::Uniform | Slot::Storage, Bind::Buffer(buf)) => {
                    if *slot == Slot::Storage && buf.size() > limit {
                        return Err(too_large(buf.size()));
                    }
                    buffer_infos.push(vk::DescriptorBufferInfo { buffer: buf.raw, offset: 0, range: vk::WHOLE_SIZE })
                }
                (Slot::Uniform | Slot::Storage, Bind::Range(buf, offset, range)) => {
                    if *slot == Slot::Storage && *range > limit {
                        return Err(too_large(*range));
                    }
                    if *range == 0 || offset + range > buf.size() {
                        return Err(Error::InvalidArgument(format!(
                            "binding range {offset}+{range} outside a buffer of {} bytes",
                            buf.size()
                        )));
                    }
                    buffer_infos.push(vk::DescriptorBufferInfo { buffer: buf.raw, offset: *offset, range: *range })
                }
                (Slot::StorageImage, Bind::Image(img)) => image_infos.push(vk::DescriptorImageInfo {
                    sampler: vk::Sampler::null(),
                    image_view: img.view,
                    image_layout: vk::ImageLayout::GENERAL,
                }),
                (Slot::Texture, Bind::Texture(img, sampler)) => image_infos.push(vk::DescriptorImageInfo {
                    sampler: sampler.raw,
                    image_view: img.view,
                    image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                }),
                (Slot::Unused, Bind::None) => {}
                (s, _) => return Err(Error::InvalidArgument(format!("resource does not fit a {s:?} slot"))),
            }
        }
        let (mut bi, mut ii) = (0, 0);
        let mut writes = Vec::new();
        for (i, slot) in self.slots.iter().enumerate() {
            let Some(kind) = slot.kind() else { continue };
            let w = vk::WriteDescriptorSet::default().dst_set(raw).dst_binding(i as u32).descriptor_type(kind);
            let w = match slot {
                Slot::Uniform | Slot::Storage => {
                    bi += 1;
                    w.buffer_info(std::slice::from_ref(&buffer_infos[bi - 1]))
                }
                _ => {
                    ii += 1;
                    w.image_info(std::slice::from_ref(&image_infos[ii - 1]))
                }
            };
            writes.push(w);
        }
        // SAFETY: every write points at live resources and infos that outlive the call.
        unsafe { self.ctx.device.update_descriptor_sets(&writes, &[]) };
        Ok(set)
    }
}

impl Drop for Layout {
    fn drop(&mut self) {
        // SAFETY: pipelines and sets using this layout are dropped before it by their owner.
        unsafe {
            self.ctx.device.destroy_pipeline_layout(self.pipeline_layout, None);
            self.ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A descriptor set in its own pool.
pub struct DescriptorSet {
    ctx: Arc<Context>,
    pool: vk::DescriptorPool,
    pub(crate) raw: vk::DescriptorSet,
}

impl Drop for DescriptorSet {
    fn drop(&mut self) {
        // SAFETY: destroying the pool frees its set; owners wait idle first.
        unsafe { self.ctx.device.destroy_descriptor_pool(self.pool, None) };
    }
}

/// What a graphics pipeline draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Primitive {
    /// Instanced 4-vertex triangle strips.
    Quads,
    /// One point sprite per vertex.
    Points,
}

fn spec_entries(specialization: &[u32]) -> Vec<vk::SpecializationMapEntry> {
    (0..specialization.len() as u32)
        .map(|i| vk::SpecializationMapEntry { constant_id: i, offset: 4 * i, size: 4 })
        .collect()
}

fn shader_module(ctx: &Context, spirv: &[u8]) -> Result<vk::ShaderModule> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
        .map_err(|e| Error::Unsupported(format!("bad SPIR-V: {e}")))?;
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: the words are SPIR-V produced by build.rs.
    unsafe { ctx.device.create_shader_module(&info, None) }.map_err(Error::vk("vkCreateShaderModule"))
}

/// A compute or graphics pipeline.
pub struct Pipeline {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Pipeline,
    pub(crate) bind_point: vk::PipelineBindPoint,
}

impl Pipeline {
    /// A compute pipeline from SPIR-V.
    pub fn compute(ctx: &Arc<Context>, layout: &Layout, spirv: &[u8]) -> Result<Self> {
        Self::compute_specialized(ctx, layout, spirv, &[])
    }

    /// A compute pipeline with `specialization[i]` as `constant_id = i` (see [`Pipeline::graphics`]).
    pub fn compute_specialized(
        ctx: &Arc<Context>,
        layout: &Layout,
        spirv: &[u8],
        specialization: &[u32],
    ) -> Result<Self> {
        let module = shader_module(ctx, spirv)?;
        let entries = spec_entries(specialization);
        let spec = vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(specialization));
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout.pipeline_layout);
        // SAFETY: valid module and layout.
        let result = unsafe { ctx.device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) };
        // SAFETY: the module is no longer needed once the pipeline exists.
        unsafe { ctx.device.destroy_shader_module(module, None) };
        let raw = result.map_err(|(_, e)| Error::vk("vkCreateComputePipelines")(e))?[0];
        Ok(Self { ctx: ctx.clone(), raw, bind_point: vk::PipelineBindPoint::COMPUTE })
    }

    /// Instanced triangle-strip quads (4 vertices per instance) or a point list (one vertex per
    /// point), no vertex buffers, with the given blend. `specialization[i]` sets `constant_id = i`
    /// in both stages: a mode fixed per pipeline costs nothing at run time, where a branch on a push
    /// constant makes llvmpipe pay for both sides. Every colour attachment of `pass` blends alike.
    #[allow(clippy::too_many_arguments)]
    pub fn graphics(
        ctx: &Arc<Context>,
        layout: &Layout,
        pass: &RenderPass,
        vert: &[u8],
        frag: &[u8],
        blend: Blend,
        primitive: Primitive,
        specialization: &[u32],
    ) -> Result<Self> {
        let vm = shader_module(ctx, vert)?;
        let fm = match shader_module(ctx, frag) {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: unused module.
                unsafe { ctx.device.destroy_shader_module(vm, None) };
                return Err(e);
            }
        };
        let entries = spec_entries(specialization);
        let data: &[u8] = bytemuck::cast_slice(specialization);
        let spec = vk::SpecializationInfo::default().map_entries(&entries).data(data);
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vm)
                .name(c"main")
                .specialization_info(&spec),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fm)
                .name(c"main")
                .specialization_info(&spec),
        ];
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(match primitive {
            Primitive::Quads => vk::PrimitiveTopology::TRIANGLE_STRIP,
            Primitive::Points => vk::PrimitiveTopology::POINT_LIST,
        });
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(vk::CullModeFlags::NONE)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let (src_c, dst_c, src_a, dst_a) = match blend {
            Blend::Over => (
                vk::BlendFactor::ONE,
                vk::BlendFactor::ONE_MINUS_SRC_ALPHA,
                vk::BlendFactor::ONE,
                vk::BlendFactor::ONE_MINUS_SRC_ALPHA,
            ),
            Blend::Under => (
                vk::BlendFactor::ONE_MINUS_DST_ALPHA,
                vk::BlendFactor::ONE,
                vk::BlendFactor::ONE_MINUS_DST_ALPHA,
                vk::BlendFactor::ONE,
            ),
            // MAX ignores the factors.
            Blend::Add | Blend::Max => {
                (vk::BlendFactor::ONE, vk::BlendFactor::ONE, vk::BlendFactor::ONE, vk::BlendFactor::ONE)
            }
        };
        let op = if blend == Blend::Max { vk::BlendOp::MAX } else { vk::BlendOp::ADD };
        let attachment = vk::PipelineColorBlendAttachmentState::default()
            .blend_enable(true)
            .src_color_blend_factor(src_c)
            .dst_color_blend_factor(dst_c)
            .color_blend_op(op)
            .src_alpha_blend_factor(src_a)
            .dst_alpha_blend_factor(dst_a)
            .alpha_blend_op(op)
            .color_write_mask(vk::ColorComponentFlags::RGBA);
        let attachments = vec![attachment; pass.attachments as usize];
        let color_blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .color_blend_state(&color_blend)
            .dynamic_state(&dynamic)
            .layout(layout.pipeline_layout)
            .render_pass(pass.raw)
            .subpass(0);
        // SAFETY: all state structs live until the call returns.
        let result = unsafe { ctx.device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) };
        // SAFETY: modules are not needed after creation.
        unsafe {
            ctx.device.destroy_shader_module(vm, None);
            ctx.device.destroy_shader_module(fm, None);
        }
        let raw = result.map_err(|(_, e)| Error::vk("vkCreateGraphicsPipelines")(e))?[0];
        Ok(Self { ctx: ctx.clone(), raw, bind_point: vk::PipelineBindPoint::GRAPHICS })
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: owners wait idle first.
        unsafe { self.ctx.device.destroy_pipeline(self.raw, None) };
    }
}

/// How footprints combine with what is already in the attachment (premultiplied colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Back-to-front: src + (1 - src.a) dst.
    Over,
    /// Front-to-back: (1 - dst.a) src + dst.
    Under,
    /// Sheet summation: src + dst.
    Add,
    /// Maximum projections: max(src, dst).
    Max,
}

/// A single-subpass render pass over RGBA32F colour attachments (one, or several written by one
/// fragment: time slots), cleared on load (or loaded, to draw on). Its external dependencies order
/// it after earlier compute/attachment work and before compute reads or copies.
pub struct RenderPass {
    ctx: Arc<Context>,
    pub(crate) raw: vk::RenderPass,
    /// Colour attachments (at most `MAX_ATTACHMENTS`).
    pub(crate) attachments: u32,
    /// Whether it clears them (else it loads them, and takes no clear values).
    pub(crate) clears: bool,
}

/// Most colour attachments a render pass here takes (`begin_pass` clears this many).
pub const MAX_ATTACHMENTS: u32 = 4;

impl RenderPass {
    /// A render pass over one `format` attachment, left in `final_layout`; `load`: drawing on what
    /// the attachment holds (in `final_layout`, where an earlier such pass left it), else cleared.
    /// Both kinds are compatible, so one framebuffer and one pipeline serve both.
    pub fn new(ctx: &Arc<Context>, format: vk::Format, final_layout: vk::ImageLayout, load: bool) -> Result<Self> {
        Self::with_attachments(ctx, format, 1, final_layout, load)
    }

    /// As `new`, over `count` attachments alike (1..=`MAX_ATTACHMENTS`).
    pub fn with_attachments(
        ctx: &Arc<Context>,
        format: vk::Format,
        count: u32,
        final_layout: vk::ImageLayout,
        load: bool,
    ) -> Result<Self> {
        if !(1..=MAX_ATTACHMENTS).contains(&count) {
            return Err(Error::InvalidArgument(format!("{count} colour attachments (1..={MAX_ATTACHMENTS})")));
        }
        let (load_op, initial) = if load {
            (vk::AttachmentLoadOp::LOAD, final_layout)
        } else {
            (vk::AttachmentLoadOp::CLEAR, vk::ImageLayout::UNDEFINED)
        };
        let attachment = vk::AttachmentDescription::default()
            .format(format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(load_op)
            .store_op(vk::AttachmentStoreOp::STORE)
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(initial)
            .final_layout(final_layout);
        let attachments = vec![attachment; count as usize];
        let color_refs: Vec<vk::AttachmentReference> = (0..count)
            .map(|attachment| vk::AttachmentReference { attachment, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL })
            .collect();
        let subpasses = [vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&color_refs)];
        let dependencies = [
            vk::SubpassDependency {
                src_subpass: vk::SUBPASS_EXTERNAL,
                dst_subpass: 0,
                src_stage_mask: vk::PipelineStageFlags::COMPUTE_SHADER
                    | vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT
                    | vk::PipelineStageFlags::TRANSFER,
                dst_stage_mask: vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::VERTEX_SHADER,
                src_access_mask: vk::AccessFlags::SHADER_WRITE
                    | vk::AccessFlags::COLOR_ATTACHMENT_WRITE
                    | vk::AccessFlags::TRANSFER_WRITE,
                dst_access_mask: vk::AccessFlags::COLOR_ATTACHMENT_WRITE
                    | vk::AccessFlags::COLOR_ATTACHMENT_READ
                    | vk::AccessFlags::SHADER_READ,
                dependency_flags: vk::DependencyFlags::empty(),
            },
            vk::SubpassDependency {
                src_subpass: 0,
                dst_subpass: vk::SUBPASS_EXTERNAL,
                src_stage_mask: vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT,
                dst_stage_mask: vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
                src_access_mask: vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
                dst_access_mask: vk::AccessFlags::SHADER_READ | vk::AccessFlags::TRANSFER_READ,
                dependency_flags: vk::DependencyFlags::empty(),
            },
        ];
        let info = vk::RenderPassCreateInfo::default()
            .attachments(&attachments)
            .subpasses(&subpasses)
            .dependencies(&dependencies);
        // SAFETY: valid create info.
        let raw = unsafe { ctx.device.create_render_pass(&info, None) }.map_err(Error::vk("vkCreateRenderPass"))?;
        Ok(Self { ctx: ctx.clone(), raw, attachments: count, clears: !load })
    }
}

impl Drop for RenderPass {
    fn drop(&mut self) {
        // SAFETY: framebuffers and pipelines using it are dropped first by the owner.
        unsafe { self.ctx.device.destroy_render_pass(self.raw, None) };
    }
}

/// A framebuffer over all layers of one image.
pub struct Framebuffer {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Framebuffer,
    pub(crate) width: u32,
    pub(crate) height: u32,
}

impl Framebuffer {
    /// A framebuffer over every layer of `image` for `pass`.
    pub fn new(ctx: &Arc<Context>, pass: &RenderPass, image: &Image) -> Result<Self> {
        Self::over(ctx, pass, &[image])
    }

    /// A framebuffer whose attachments are `images` in order (as many as `pass` has, all of one
    /// size and layer count).
    pub fn over(ctx: &Arc<Context>, pass: &RenderPass, images: &[&Image]) -> Result<Self> {
        let first = images.first().ok_or_else(|| Error::InvalidArgument("a framebuffer without images".into()))?;
        if images.len() != pass.attachments as usize
            || images.iter().any(|i| (i.width, i.height, i.layers) != (first.width, first.height, first.layers))
        {
            return Err(Error::InvalidArgument(format!(
                "{} images of mixed sizes for a pass of {} attachments",
                images.len(),
                pass.attachments
            )));
        }
        let image = first;
        let views: Vec<vk::ImageView> = images.iter().map(|i| i.view).collect();
        let info = vk::FramebufferCreateInfo::default()
            .render_pass(pass.raw)
            .attachments(&views)
            .width(image.width)
            .height(image.height)
            .layers(image.layers);
        // SAFETY: views and pass are compatible (same format, one view per attachment).
        let raw = unsafe { ctx.device.create_framebuffer(&info, None) }.map_err(Error::vk("vkCreateFramebuffer"))?;
        Ok(Self { ctx: ctx.clone(), raw, width: image.width, height: image.height })
    }
}

impl Drop for Framebuffer {
    fn drop(&mut self) {
        // SAFETY: owners wait idle first.
        unsafe { self.ctx.device.destroy_framebuffer(self.raw, None) };
    }
}
