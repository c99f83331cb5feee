//! One-shot command recording and submission with a fence. `Recorder` is the safe face of a
//! command buffer: every command the pipeline records goes through it.
use super::{Buffer, Context, DescriptorSet, Framebuffer, Image, Layout, Pipeline, RenderPass, Timer};
use crate::error::{Error, Result};
use ash::vk;
use std::sync::atomic::Ordering;

/// A command buffer being recorded (see `Context::submit`).
pub struct Recorder<'a> {
    pub(super) ctx: &'a Context,
    pub(super) cmd: vk::CommandBuffer,
}

/// Pipeline stages a barrier connects (a small vocabulary is all the pipeline needs).
#[derive(Clone, Copy, Debug)]
pub enum Stage {
    /// Compute shaders.
    Compute,
    /// Copies and fills.
    Transfer,
    /// Vertex and fragment shaders and attachments.
    Graphics,
    /// Host reads and writes.
    Host,
    /// Every stage the engine records: compute, transfer, vertex input, shaders and attachments.
    /// Named one by one rather than ALL_COMMANDS, which drains stages (ray tracing, mesh,
    /// acceleration builds) the engine never uses, and which best-practices validation flags.
    All,
}

/// The stages [`Stage::All`] orders: everything the engine's command buffers record.
pub(crate) const ENGINE_STAGES: vk::PipelineStageFlags = vk::PipelineStageFlags::from_raw(
    vk::PipelineStageFlags::COMPUTE_SHADER.as_raw()
        | vk::PipelineStageFlags::TRANSFER.as_raw()
        | vk::PipelineStageFlags::VERTEX_INPUT.as_raw()
        | vk::PipelineStageFlags::VERTEX_SHADER.as_raw()
        | vk::PipelineStageFlags::FRAGMENT_SHADER.as_raw()
        | vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT.as_raw(),
);

impl Stage {
    fn flags(self) -> (vk::PipelineStageFlags, vk::AccessFlags, vk::AccessFlags) {
        use vk::AccessFlags as A;
        use vk::PipelineStageFlags as P;
        match self {
            Stage::Compute => (P::COMPUTE_SHADER, A::SHADER_WRITE, A::SHADER_READ | A::SHADER_WRITE),
            Stage::Transfer => (P::TRANSFER, A::TRANSFER_WRITE, A::TRANSFER_READ | A::TRANSFER_WRITE),
            Stage::Graphics => (
                P::VERTEX_SHADER | P::FRAGMENT_SHADER | P::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE,
                A::SHADER_READ | A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
            ),
            Stage::Host => (P::HOST, A::HOST_WRITE, A::HOST_READ),
            Stage::All => (ENGINE_STAGES, A::MEMORY_WRITE, A::MEMORY_READ | A::MEMORY_WRITE),
        }
    }
}

/// The access an image in `layout` takes at `stages`: one kind where the layout admits one
/// (a transfer's source or destination, a shader's read-only), `otherwise` elsewhere. Naming
/// accesses a layout cannot take is meaningless, and best-practices validation says so.
pub(crate) fn layout_access(
    layout: vk::ImageLayout,
    stages: vk::PipelineStageFlags,
    otherwise: vk::AccessFlags,
) -> vk::AccessFlags {
    use vk::{AccessFlags as A, ImageLayout as L, PipelineStageFlags as P};
    let shaders = P::COMPUTE_SHADER | P::VERTEX_SHADER | P::FRAGMENT_SHADER;
    match layout {
        L::TRANSFER_DST_OPTIMAL if stages.contains(P::TRANSFER) => A::TRANSFER_WRITE,
        L::TRANSFER_SRC_OPTIMAL if stages.contains(P::TRANSFER) => A::TRANSFER_READ,
        L::SHADER_READ_ONLY_OPTIMAL if stages.intersects(shaders) => A::SHADER_READ,
        _ => otherwise,
    }
}

impl Recorder<'_> {
    /// Make all writes of `src` visible to `dst`.
    pub fn barrier(&self, src: Stage, dst: Stage) {
        let (s, sa, _) = src.flags();
        let (d, _, da) = dst.flags();
        let mb = [vk::MemoryBarrier::default().src_access_mask(sa).dst_access_mask(da)];
        // SAFETY: recording into a command buffer in the recording state.
        unsafe { self.ctx.device.cmd_pipeline_barrier(self.cmd, s, d, vk::DependencyFlags::empty(), &mb, &[], &[]) };
    }

    /// Transition all layers of `image`, ordering `src` work before `dst` work.
    pub fn transition(&self, image: &Image, from: vk::ImageLayout, to: vk::ImageLayout, src: Stage, dst: Stage) {
        let (s, sa, _) = src.flags();
        let (d, _, da) = dst.flags();
        let (sa, da) = (layout_access(from, s, sa), layout_access(to, d, da));
        let b = [vk::ImageMemoryBarrier::default()
            .old_layout(from)
            .new_layout(to)
            .src_access_mask(sa)
            .dst_access_mask(da)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image.raw)
            .subresource_range(image.range())];
        // SAFETY: recording state; image alive for the submission.
        unsafe { self.ctx.device.cmd_pipeline_barrier(self.cmd, s, d, vk::DependencyFlags::empty(), &[], &[], &b) };
    }

    /// Clear every layer of `image` (in `layout`) to `color`.
    pub fn clear_image(&self, image: &Image, layout: vk::ImageLayout, color: [f32; 4]) {
        let value = vk::ClearColorValue { float32: color };
        // SAFETY: image is in `layout` (GENERAL or TRANSFER_DST) per the caller's transitions.
        unsafe { self.ctx.device.cmd_clear_color_image(self.cmd, image.raw, layout, &value, &[image.range()]) };
    }

    /// Copy `buffer` into `image` (in TRANSFER_DST_OPTIMAL).
    pub fn copy_buffer_to_image(&self, buffer: &Buffer, image: &Image) {
        let region = [vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D { width: image.width, height: image.height, depth: image.depth })];
        // SAFETY: image in TRANSFER_DST_OPTIMAL; buffer holds width*height*depth texels.
        unsafe {
            self.ctx.device.cmd_copy_buffer_to_image(
                self.cmd,
                buffer.raw,
                image.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            )
        };
    }

    /// Fill a whole buffer with one 32-bit pattern (e.g. the bits of 1.0f).
    pub fn fill_buffer(&self, buffer: &Buffer, value: u32) {
        // SAFETY: outside a render pass; the buffer was created with TRANSFER_DST.
        unsafe { self.ctx.device.cmd_fill_buffer(self.cmd, buffer.raw, 0, vk::WHOLE_SIZE, value) };
    }

    /// Fill `bytes` from `offset` (both multiples of 4, clamped to the buffer) with `value`.
    pub fn fill_buffer_range(&self, buffer: &Buffer, offset: u64, bytes: u64, value: u32) {
        let size = bytes.min(buffer.size().saturating_sub(offset)) & !3;
        if size == 0 || !offset.is_multiple_of(4) {
            return;
        }
        // SAFETY: outside a render pass; TRANSFER_DST buffer; the range lies within it.
        unsafe { self.ctx.device.cmd_fill_buffer(self.cmd, buffer.raw, offset, size, value) };
    }

    /// Copy the first `bytes` of `src` to `dst` (clamped to both).
    pub fn copy_buffer(&self, src: &Buffer, dst: &Buffer, bytes: u64) {
        let size = bytes.min(src.size()).min(dst.size());
        if size == 0 {
            return;
        }
        let region = [vk::BufferCopy { src_offset: 0, dst_offset: 0, size }];
        // SAFETY: both buffers alive for the submission; size within both.
        unsafe { self.ctx.device.cmd_copy_buffer(self.cmd, src.raw, dst.raw, &region) };
    }

    /// Copy `regions` (source offset, destination offset, size, in bytes) of `src` into `dst`.
    pub fn copy_buffer_regions(&self, src: &Buffer, dst: &Buffer, regions: &[[u64; 3]]) {
        let regions: Vec<vk::BufferCopy> = regions
            .iter()
            .filter(|r| r[2] > 0 && r[0] + r[2] <= src.size() && r[1] + r[2] <= dst.size())
            .map(|&[src_offset, dst_offset, size]| vk::BufferCopy { src_offset, dst_offset, size })
            .collect();
        if regions.is_empty() {
            return;
        }
        // SAFETY: both buffers alive for the submission; every region within both (filtered).
        unsafe { self.ctx.device.cmd_copy_buffer(self.cmd, src.raw, dst.raw, &regions) };
    }

    /// Copy layer 0 of `image` (in `layout`) to `buffer`.
    pub fn copy_image_to_buffer(&self, image: &Image, layout: vk::ImageLayout, buffer: &Buffer) {
        self.copy_raw_to_buffer(image.raw, (image.width, image.height), layout, buffer);
    }

    /// Copy layer 0 of a `width` x `height` image (ours or a host's, in `layout`) to `buffer`.
    pub(super) fn copy_raw_to_buffer(
        &self,
        image: vk::Image,
        (width, height): (u32, u32),
        layout: vk::ImageLayout,
        buffer: &Buffer,
    ) {
        let region = [vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D { width, height, depth: 1 })];
        // SAFETY: image in `layout` (GENERAL or TRANSFER_SRC); buffer large enough (checked by caller).
        unsafe { self.ctx.device.cmd_copy_image_to_buffer(self.cmd, image, layout, buffer.raw, &region) };
    }

    fn bind(&self, pipeline: &Pipeline, layout: &Layout, set: &DescriptorSet, push: &[u8]) {
        // SAFETY: pipeline, layout and set are compatible (built from the same Layout).
        unsafe {
            self.ctx.device.cmd_bind_pipeline(self.cmd, pipeline.bind_point, pipeline.raw);
            self.ctx.device.cmd_bind_descriptor_sets(
                self.cmd,
                pipeline.bind_point,
                layout.pipeline_layout,
                0,
                &[set.raw],
                &[],
            );
            if !push.is_empty() {
                self.ctx.device.cmd_push_constants(self.cmd, layout.pipeline_layout, layout.push_stages, 0, push);
            }
        }
    }

    /// Bind and dispatch a compute pipeline.
    pub fn dispatch(&self, pipeline: &Pipeline, layout: &Layout, set: &DescriptorSet, push: &[u8], groups: [u32; 3]) {
        self.bind(pipeline, layout, set, push);
        // SAFETY: compute pipeline bound above.
        unsafe { self.ctx.device.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]) };
    }

    /// Begin `pass` on `fb`, clearing it.
    pub fn begin_pass(&self, pass: &RenderPass, fb: &Framebuffer) {
        let clear = [vk::ClearValue { color: vk::ClearColorValue { float32: [0.0; 4] } };
            super::pipeline::MAX_ATTACHMENTS as usize];
        let area = vk::Rect2D {
            offset: vk::Offset2D { x: 0, y: 0 },
            extent: vk::Extent2D { width: fb.width, height: fb.height },
        };
        let info = vk::RenderPassBeginInfo::default()
            .render_pass(pass.raw)
            .framebuffer(fb.raw)
            .render_area(area)
            .clear_values(&clear[..if pass.clears { pass.attachments as usize } else { 0 }]);
        let viewport = [vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: fb.width as f32,
            height: fb.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        }];
        // SAFETY: framebuffer built for this pass.
        unsafe {
            self.ctx.device.cmd_begin_render_pass(self.cmd, &info, vk::SubpassContents::INLINE);
            self.ctx.device.cmd_set_viewport(self.cmd, 0, &viewport);
            self.ctx.device.cmd_set_scissor(self.cmd, 0, &[area]);
        }
    }

    /// Instanced quads: 4 strip vertices per instance.
    pub fn draw_quads(
        &self,
        pipeline: &Pipeline,
        layout: &Layout,
        set: &DescriptorSet,
        push: &[u8],
        first_instance: u32,
        instances: u32,
    ) {
        self.bind(pipeline, layout, set, push);
        // SAFETY: inside a render pass with a graphics pipeline bound.
        unsafe { self.ctx.device.cmd_draw(self.cmd, 4, instances, 0, first_instance) };
    }

    /// A point list: vertex `first + i` for i < `count` (the vertex index picks the draw-list entry).
    pub fn draw_points(
        &self,
        pipeline: &Pipeline,
        layout: &Layout,
        set: &DescriptorSet,
        push: &[u8],
        first: u32,
        count: u32,
    ) {
        self.bind(pipeline, layout, set, push);
        // SAFETY: inside a render pass with a graphics pipeline bound.
        unsafe { self.ctx.device.cmd_draw(self.cmd, count, 1, first, 0) };
    }

    /// End the render pass.
    pub fn end_pass(&self) {
        // SAFETY: matches begin_pass.
        unsafe { self.ctx.device.cmd_end_render_pass(self.cmd) };
    }

    /// Write timestamp `index` of `timer` when all earlier work is done.
    pub fn timestamp(&self, timer: &Timer, index: u32) {
        if let Some(pool) = timer.pool {
            if index < timer.capacity {
                // SAFETY: query index within the pool, reset at the start of the recording.
                unsafe {
                    self.ctx.device.cmd_write_timestamp(self.cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, pool, index)
                };
            }
        }
    }

    /// Reset every query of `timer`.
    pub fn reset_timer(&self, timer: &Timer) {
        if let Some(pool) = timer.pool {
            // SAFETY: outside a render pass.
            unsafe { self.ctx.device.cmd_reset_query_pool(self.cmd, pool, 0, timer.capacity) };
        }
    }
}

impl Context {
    /// Record with `f`, submit, and wait on a fence. Everything `f` referenced must live until
    /// this returns, which the borrow of the recorder guarantees for resources passed by reference.
    pub fn submit<T>(&self, f: impl FnOnce(&Recorder<'_>) -> Result<T>) -> Result<T> {
        self.submit_synced(None, f)
    }

    /// `submit`, waiting on the host's semaphores of `target` before any of its commands run and
    /// signalling its others when they are done (the frame that writes into the host's image).
    pub fn submit_synced<T>(
        &self,
        target: Option<&super::HostTarget>,
        f: impl FnOnce(&Recorder<'_>) -> Result<T>,
    ) -> Result<T> {
        if self.is_lost() {
            return Err(Error::DeviceLost("a submission after the device was lost".into()));
        }
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        // SAFETY: valid device; the pool is destroyed below on every path.
        let pool =
            unsafe { self.device.create_command_pool(&pool_info, None) }.map_err(Error::vk("vkCreateCommandPool"))?;
        let result = self.submit_in(pool, target, f);
        // SAFETY: submit_in waited on its fence (or never submitted) before returning.
        unsafe { self.device.destroy_command_pool(pool, None) };
        result
    }

    fn submit_in<T>(
        &self,
        pool: vk::CommandPool,
        target: Option<&super::HostTarget>,
        f: impl FnOnce(&Recorder<'_>) -> Result<T>,
    ) -> Result<T> {
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: pool from this device.
        let cmd =
            unsafe { self.device.allocate_command_buffers(&alloc) }.map_err(Error::vk("vkAllocateCommandBuffers"))?[0];
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: fresh command buffer.
        unsafe { self.device.begin_command_buffer(cmd, &begin) }.map_err(Error::vk("vkBeginCommandBuffer"))?;
        let rec = Recorder { ctx: self, cmd };
        // Earlier submissions on this queue touched the same resources: order them first.
        rec.barrier(Stage::All, Stage::All);
        let value = f(&rec)?;
        rec.barrier(Stage::All, Stage::Host);
        // SAFETY: recording state.
        unsafe { self.device.end_command_buffer(cmd) }.map_err(Error::vk("vkEndCommandBuffer"))?;
        // SAFETY: fence destroyed below.
        let fence = unsafe { self.device.create_fence(&vk::FenceCreateInfo::default(), None) }
            .map_err(Error::vk("vkCreateFence"))?;
        let cmds = [cmd];
        let (wait, signal) = target.map(|t| (&t.wait[..], &t.signal[..])).unwrap_or((&[], &[]));
        // The host's semaphores hold back every stage of this submission.
        let stages = vec![ENGINE_STAGES; wait.len()];
        // Empty lists stay null pointers: a dangling pointer with a count of 0 is legal, but
        // best-practices validation reports it.
        let mut info = vk::SubmitInfo::default().command_buffers(&cmds);
        if !wait.is_empty() {
            info = info.wait_semaphores(wait).wait_dst_stage_mask(&stages);
        }
        if !signal.is_empty() {
            info = info.signal_semaphores(signal);
        }
        let submit = [info];
        let submitted = {
            let queue = self.queue.lock().map_err(|_| Error::Unsupported("queue lock poisoned".into()))?;
            // SAFETY: the queue is externally synchronised by the mutex.
            unsafe { self.device.queue_submit(*queue, &submit, fence) }.map_err(Error::vk("vkQueueSubmit"))
        };
        let waited = submitted.and_then(|_| {
            // SAFETY: fence from this device.
            unsafe { self.device.wait_for_fences(&[fence], true, u64::MAX) }.map_err(Error::vk("vkWaitForFences"))
        });
        let injected = self.injected.swap(0, Ordering::AcqRel);
        let waited = if injected != 0 && waited.is_ok() {
            Err(Error::vk("vkWaitForFences")(vk::Result::from_raw(injected)))
        } else {
            waited
        };
        if matches!(waited, Err(Error::DeviceLost(_))) {
            self.lost.store(true, Ordering::Release);
        }
        if waited.is_err() {
            // Device lost or similar: make sure nothing is still running before the pool goes.
            self.wait_idle();
        }
        // SAFETY: the fence has signalled or the device is idle/lost.
        unsafe { self.device.destroy_fence(fence, None) };
        waited.map(|_| value)
    }
}
