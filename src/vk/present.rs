//! A window's swapchain on voxsplat's own device, with an egui overlay (feature `window`): each
//! frame copies the volume's image into a rectangle of the swapchain image, draws the overlay's
//! triangles over it and presents. What `voxsplat view` draws with; a host with its own device
//! embeds voxsplat through `Context::from_host` and `Renderer::render_to` instead.
use super::host::color_range;
use super::submit::layout_access;
use super::{target_format, Buffer, Context, ContextOptions, HostTarget, Memory, Semaphore, TargetImage};
use crate::error::{Error, Result};
use ash::vk;
use egui_ash_renderer::{Options as OverlayOptions, RenderMode, Renderer as Overlay};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::mem::ManuallyDrop;
use std::sync::Arc;

/// A window the presenter can draw into. It is held for the presenter's life, so its handles stay
/// valid while the surface made from them exists.
pub trait PresentWindow: HasWindowHandle + HasDisplayHandle + Send + Sync {}
impl<T: HasWindowHandle + HasDisplayHandle + Send + Sync> PresentWindow for T {}

/// How a presenter presents.
#[derive(Clone, Debug, Default)]
pub struct PresentOptions {
    /// The device's options (validation, device name).
    pub context: ContextOptions,
    /// Present without waiting for the display's refresh (mailbox or immediate, when the surface
    /// has one); vsync (FIFO) otherwise.
    pub no_vsync: bool,
}

/// The overlay of one frame: egui's triangles and texture changes (`egui::Context::tessellate`,
/// `FullOutput::textures_delta`).
pub struct OverlayFrame<'a> {
    /// The tessellated shapes, in points.
    pub primitives: &'a [egui::ClippedPrimitive],
    /// Fonts and images to upload before, and free after, the frame.
    pub textures: &'a egui::TexturesDelta,
    /// Physical pixels per point.
    pub pixels_per_point: f32,
}

/// What draws the volume into the image it is given (`Renderer::render_to`).
pub type DrawView<'a> = &'a mut dyn FnMut(&HostTarget) -> Result<()>;

/// Where the volume's image goes in the window, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Viewport {
    /// Left edge.
    pub x: u32,
    /// Top edge.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

/// A presented frame: whether it reached the window and, when asked, the window's pixels.
pub struct Presented {
    /// False when the swapchain was out of date (after a resize): nothing was drawn, draw again.
    pub shown: bool,
    /// The whole window as RGBA8, as the display shows it (sRGB-encoded bytes).
    pub window_rgba: Option<Vec<u8>>,
}

struct Chain {
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    framebuffers: Vec<vk::Framebuffer>,
    /// One "drawn" semaphore per image: the present waits on it.
    done: Vec<Semaphore>,
    extent: vk::Extent2D,
}

/// A window's swapchain, the volume's image and the overlay renderer, on a context made for them.
pub struct Presenter {
    ctx: Arc<Context>,
    surface_fn: ash::khr::surface::Instance,
    swapchain_fn: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    format: vk::Format,
    color_space: vk::ColorSpaceKHR,
    present_mode: vk::PresentModeKHR,
    render_pass: vk::RenderPass,
    pool: vk::CommandPool,
    overlay: ManuallyDrop<Overlay<egui_ash_renderer::allocator::DefaultAllocator>>,
    chain: Option<Chain>,
    acquire: Option<Semaphore>,
    view: Option<TargetImage>,
    view_size: (u32, u32),
    /// The host's drawing under the next view drawn (`underlay`): RGBA8, its size.
    under: Option<(Vec<u8>, (u32, u32))>,
    _window: Arc<dyn PresentWindow>,
}

fn overlay_err(e: egui_ash_renderer::RendererError) -> Error {
    Error::Unsupported(format!("egui overlay: {e}"))
}

impl Presenter {
    /// A device that can present to `window`, its swapchain at `size` (the window's inner size in
    /// pixels) and an overlay renderer.
    pub fn new(window: Arc<dyn PresentWindow>, size: (u32, u32), options: &PresentOptions) -> Result<Self> {
        let display = window.display_handle().map_err(|e| Error::Unsupported(format!("window: {e}")))?.as_raw();
        let handle = window.window_handle().map_err(|e| Error::Unsupported(format!("window: {e}")))?.as_raw();
        let extensions = ash_window::enumerate_required_extensions(display)
            .map_err(|e| Error::Unsupported(format!("no Vulkan surface for this window system: {e}")))?;
        let ctx = Context::create(&options.context, extensions)?;
        let entry = ctx.handles().entry;
        // SAFETY: the handles are the window's, which `_window` keeps alive past the surface.
        let surface = unsafe { ash_window::create_surface(&entry, &ctx.instance, display, handle, None) }
            .map_err(Error::vk("vkCreate*SurfaceKHR"))?;
        let surface_fn = ash::khr::surface::Instance::new(&entry, &ctx.instance);
        let swapchain_fn = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        let destroy_surface = |e: Error| {
            // SAFETY: nothing made from the surface exists yet.
            unsafe { surface_fn.destroy_surface(surface, None) };
            e
        };
        // SAFETY: plain queries on the context's physical device and the surface.
        let support =
            unsafe { surface_fn.get_physical_device_surface_support(ctx.physical, ctx.queue_family, surface) }
                .unwrap_or(false);
        if !support {
            return Err(destroy_surface(Error::Unsupported(format!(
                "{} cannot present to this window from its graphics queue",
                ctx.device_name()
            ))));
        }
        let (format, color_space, present_mode) =
            Self::pick_formats(&surface_fn, &ctx, surface, options.no_vsync).map_err(destroy_surface)?;
        let render_pass = Self::render_pass(&ctx, format).map_err(destroy_surface)?;
        let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family);
        // SAFETY: valid device; destroyed in Drop.
        let pool = unsafe { ctx.device.create_command_pool(&pool_info, None) };
        let pool = pool.map_err(|e| {
            // SAFETY: unused.
            unsafe { ctx.device.destroy_render_pass(render_pass, None) };
            destroy_surface(Error::vk("vkCreateCommandPool")(e))
        })?;
        let srgb = matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB);
        let overlay = Overlay::with_default_allocator(
            &ctx.instance,
            ctx.physical,
            ctx.device.clone(),
            RenderMode::RenderPass(render_pass),
            OverlayOptions { srgb_framebuffer: srgb, ..Default::default() },
        )
        .map_err(|e| {
            // SAFETY: unused.
            unsafe {
                ctx.device.destroy_command_pool(pool, None);
                ctx.device.destroy_render_pass(render_pass, None);
            }
            destroy_surface(overlay_err(e))
        })?;
        let mut presenter = Self {
            acquire: Some(Semaphore::new(&ctx)?),
            ctx,
            surface_fn,
            swapchain_fn,
            surface,
            format,
            color_space,
            present_mode,
            render_pass,
            pool,
            overlay: ManuallyDrop::new(overlay),
            chain: None,
            view: None,
            view_size: (0, 0),
            under: None,
            _window: window,
        };
        presenter.resize(size)?;
        Ok(presenter)
    }

    /// The device, for `Renderer::with_context`.
    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }

    /// The swapchain's size in pixels (0 x 0 while the window is minimised).
    pub fn size(&self) -> (u32, u32) {
        self.chain.as_ref().map(|c| (c.extent.width, c.extent.height)).unwrap_or((0, 0))
    }

    /// The swapchain's format: the volume's image has it too.
    pub fn format(&self) -> vk::Format {
        self.format
    }

    fn pick_formats(
        surface_fn: &ash::khr::surface::Instance,
        ctx: &Context,
        surface: vk::SurfaceKHR,
        no_vsync: bool,
    ) -> Result<(vk::Format, vk::ColorSpaceKHR, vk::PresentModeKHR)> {
        // SAFETY: plain queries.
        let (formats, modes) = unsafe {
            (
                surface_fn.get_physical_device_surface_formats(ctx.physical, surface),
                surface_fn.get_physical_device_surface_present_modes(ctx.physical, surface),
            )
        };
        let formats = formats.map_err(Error::vk("vkGetPhysicalDeviceSurfaceFormatsKHR"))?;
        let modes = modes.map_err(Error::vk("vkGetPhysicalDeviceSurfacePresentModesKHR"))?;
        // sRGB first: the device encodes, so the volume and the overlay blend in linear light.
        let rank = |f: &vk::SurfaceFormatKHR| match f.format {
            vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB => 0,
            vk::Format::B8G8R8A8_UNORM | vk::Format::R8G8B8A8_UNORM => 1,
            _ => 2,
        };
        let chosen = formats
            .iter()
            .filter(|f| f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR && rank(f) < 2)
            .min_by_key(|f| rank(f))
            .ok_or_else(|| Error::Unsupported(format!("no 8-bit RGBA or BGRA swapchain format among {formats:?}")))?;
        let wanted = [vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE];
        let mode = if no_vsync { wanted.into_iter().find(|m| modes.contains(m)) } else { None };
        Ok((chosen.format, chosen.color_space, mode.unwrap_or(vk::PresentModeKHR::FIFO)))
    }

    /// The overlay's pass: it keeps the volume's pixels (LOAD) and leaves the image ready to be
    /// read back or presented.
    fn render_pass(ctx: &Context, format: vk::Format) -> Result<vk::RenderPass> {
        let attachments = [vk::AttachmentDescription::default()
            .format(format)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE)
            .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
            .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .final_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)];
        let refs = [vk::AttachmentReference::default().attachment(0).layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
        let subpasses = [vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&refs)];
        let color = vk::AccessFlags::COLOR_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_WRITE;
        let dependencies = [
            vk::SubpassDependency::default()
                .src_subpass(vk::SUBPASS_EXTERNAL)
                .dst_subpass(0)
                .src_stage_mask(vk::PipelineStageFlags::TRANSFER)
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
                .dst_access_mask(color),
            vk::SubpassDependency::default()
                .src_subpass(0)
                .dst_subpass(vk::SUBPASS_EXTERNAL)
                .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
                .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
                .dst_access_mask(vk::AccessFlags::TRANSFER_READ),
        ];
        let info = vk::RenderPassCreateInfo::default()
            .attachments(&attachments)
            .subpasses(&subpasses)
            .dependencies(&dependencies);
        // SAFETY: valid device; the arrays outlive the call.
        unsafe { ctx.device.create_render_pass(&info, None) }.map_err(Error::vk("vkCreateRenderPass"))
    }

    /// A new swapchain for the window's new size (after `WindowEvent::Resized`); a zero size
    /// (minimised) keeps none until the next.
    pub fn resize(&mut self, size: (u32, u32)) -> Result<()> {
        let old = self.chain.take();
        let made = self.make_chain(size, old.as_ref().map(|c| c.raw).unwrap_or_default());
        if let Some(old) = old {
            self.destroy_chain(old);
        }
        self.chain = made?;
        Ok(())
    }

    fn make_chain(&self, size: (u32, u32), old: vk::SwapchainKHR) -> Result<Option<Chain>> {
        let ctx = &self.ctx;
        // SAFETY: plain query.
        let caps = unsafe { self.surface_fn.get_physical_device_surface_capabilities(ctx.physical, self.surface) }
            .map_err(Error::vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR"))?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: size.0.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size.1.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            return Ok(None);
        }
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(Error::Unsupported(format!(
                "the window's swapchain images cannot be copied into and read ({:?})",
                caps.supported_usage_flags
            )));
        }
        let count = if caps.max_image_count == 0 {
            caps.min_image_count + 1
        } else {
            (caps.min_image_count + 1).min(caps.max_image_count)
        };
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format)
            .image_color_space(self.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(self.present_mode)
            .clipped(true)
            .old_swapchain(old);
        // SAFETY: the surface is valid; `old` (if any) is retired by this call.
        let raw =
            unsafe { self.swapchain_fn.create_swapchain(&info, None) }.map_err(Error::vk("vkCreateSwapchainKHR"))?;
        let mut chain =
            Chain { raw, images: Vec::new(), views: Vec::new(), framebuffers: Vec::new(), done: Vec::new(), extent };
        match self.fill_chain(&mut chain) {
            Ok(()) => Ok(Some(chain)),
            Err(e) => {
                self.destroy_chain(chain);
                Err(e)
            }
        }
    }

    fn fill_chain(&self, chain: &mut Chain) -> Result<()> {
        let device = &self.ctx.device;
        // SAFETY: a swapchain of this device.
        chain.images = unsafe { self.swapchain_fn.get_swapchain_images(chain.raw) }
            .map_err(Error::vk("vkGetSwapchainImagesKHR"))?;
        for &image in &chain.images {
            let info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(self.format)
                .subresource_range(color_range());
            // SAFETY: the swapchain's image; the view is destroyed with the chain.
            let view = unsafe { device.create_image_view(&info, None) }.map_err(Error::vk("vkCreateImageView"))?;
            chain.views.push(view);
            let views = [view];
            let fb = vk::FramebufferCreateInfo::default()
                .render_pass(self.render_pass)
                .attachments(&views)
                .width(chain.extent.width)
                .height(chain.extent.height)
                .layers(1);
            // SAFETY: as above.
            let fb = unsafe { device.create_framebuffer(&fb, None) }.map_err(Error::vk("vkCreateFramebuffer"))?;
            chain.framebuffers.push(fb);
            chain.done.push(Semaphore::new(&self.ctx)?);
        }
        Ok(())
    }

    fn destroy_chain(&self, chain: Chain) {
        self.ctx.wait_idle();
        // SAFETY: the device is idle: no frame uses the chain's objects.
        unsafe {
            for fb in chain.framebuffers {
                self.ctx.device.destroy_framebuffer(fb, None);
            }
            for view in chain.views {
                self.ctx.device.destroy_image_view(view, None);
            }
            self.swapchain_fn.destroy_swapchain(chain.raw, None);
        }
    }

    /// One frame. `draw` renders the volume into the image it is given (`Renderer::render_to`; the
    /// image is `viewport`'s size and the swapchain's format) and returns; without it the last
    /// frame's image is shown again (the overlay alone changed). The image is copied into
    /// `viewport`, the rest of the window cleared to `clear` (linear RGBA), the overlay drawn over
    /// both, and the window presented. With no viewport (nothing loaded yet) the window is the
    /// clear colour and the overlay. `read_back` also returns the window's pixels.
    pub fn frame(
        &mut self,
        viewport: Option<Viewport>,
        clear: [f32; 4],
        draw: Option<DrawView<'_>>,
        overlay: &OverlayFrame<'_>,
        read_back: bool,
    ) -> Result<Presented> {
        let Some(chain) = &self.chain else { return Ok(Presented { shown: false, window_rgba: None }) };
        let extent = chain.extent;
        let fits = |v: &Viewport| {
            v.width > 0
                && v.height > 0
                && v.x.checked_add(v.width).is_some_and(|r| r <= extent.width)
                && v.y.checked_add(v.height).is_some_and(|b| b <= extent.height)
        };
        if let Some(viewport) = viewport.filter(|v| !fits(v)) {
            return Err(Error::InvalidArgument(format!(
                "viewport {viewport:?} is not inside the {} x {} window",
                extent.width, extent.height
            )));
        }
        let acquire = self.acquire.as_ref().expect("held until drop").raw();
        // SAFETY: the swapchain and semaphore are valid; the semaphore is unsignalled (the last
        // frame's submission waited on it and completed).
        let acquired = unsafe { self.swapchain_fn.acquire_next_image(chain.raw, u64::MAX, acquire, vk::Fence::null()) };
        let index = match acquired {
            Ok((i, _)) => i as usize,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(Presented { shown: false, window_rgba: None }),
            Err(e) => return Err(Error::vk("vkAcquireNextImageKHR")(e)),
        };
        let drawn = match viewport {
            Some(v) => self.draw_view((v.width, v.height), draw),
            None => Ok(()),
        };
        let chain = self.chain.as_ref().expect("checked above");
        let (image, done) = (chain.images[index], chain.done[index].raw());
        // The frame waits on the acquire and signals the present's semaphore.
        // SAFETY: the swapchain image has the usages the frame needs; the semaphores live until
        // the submission that uses them completes (submit_synced waits).
        let target = unsafe {
            HostTarget::new(
                image,
                self.format,
                (extent.width, extent.height),
                (vk::ImageLayout::UNDEFINED, vk::ImageLayout::PRESENT_SRC_KHR),
                &[acquire],
                &[done],
            )
        }?;
        if let Err(e) = drawn {
            // The acquire's semaphore is signalled: wait on it with an empty frame, then present
            // nothing (the image is released by the next acquire).
            self.ctx.submit_synced(Some(&target), |rec| {
                layout(rec.ctx, rec.cmd, image, vk::ImageLayout::UNDEFINED, vk::ImageLayout::PRESENT_SRC_KHR);
                Ok(())
            })?;
            self.present(index, done)?;
            return Err(e);
        }
        for (id, delta) in overlay.textures.set.iter().flat_map(|(id, ds)| ds.iter().map(move |d| (id, d))) {
            // The upload submits on the queue: held under the context's lock.
            let queue = self.ctx.queue.lock().map_err(|_| Error::Unsupported("queue lock poisoned".into()))?;
            self.overlay.set_texture(*queue, self.pool, *id, delta).map_err(overlay_err)?;
        }
        let bytes = extent.width as u64 * extent.height as u64 * 4;
        let back = if read_back {
            Some(Buffer::new(
                &self.ctx,
                "window readback",
                bytes,
                vk::BufferUsageFlags::TRANSFER_DST,
                Memory::Readback,
            )?)
        } else {
            None
        };
        let framebuffer = chain.framebuffers[index];
        let copy_view = viewport.zip(self.view.as_ref().map(|v| v.raw()));
        let render_pass = self.render_pass;
        let overlay_renderer = &mut self.overlay;
        self.ctx.submit_synced(Some(&target), |rec| {
            let (d, cmd) = (&rec.ctx.device, rec.cmd);
            layout(rec.ctx, cmd, image, vk::ImageLayout::UNDEFINED, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
            let range = [color_range()];
            let color = vk::ClearColorValue { float32: clear };
            // SAFETY: recording on this frame's command buffer; the image is in TRANSFER_DST.
            unsafe { d.cmd_clear_color_image(cmd, image, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &color, &range) };
            if let Some((viewport, view_image)) = copy_view {
                let copy = [vk::ImageCopy::default()
                    .src_subresource(color_layers())
                    .dst_subresource(color_layers())
                    .dst_offset(vk::Offset3D { x: viewport.x as i32, y: viewport.y as i32, z: 0 })
                    .extent(vk::Extent3D { width: viewport.width, height: viewport.height, depth: 1 })];
                // SAFETY: as above; the view is as render_to left it, ordered by the submission's
                // first barrier.
                unsafe {
                    transfer_barrier(d, cmd, image);
                    d.cmd_copy_image(
                        cmd,
                        view_image,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        image,
                        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                        &copy,
                    );
                }
            }
            layout(
                rec.ctx,
                cmd,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            );
            let begin = vk::RenderPassBeginInfo::default()
                .render_pass(render_pass)
                .framebuffer(framebuffer)
                .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent });
            // SAFETY: the framebuffer is this image's; the pass's dependencies order the copy.
            unsafe { d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE) };
            let drawn = overlay_renderer.cmd_draw(cmd, extent, overlay.pixels_per_point, overlay.primitives);
            // SAFETY: inside the pass begun above.
            unsafe { d.cmd_end_render_pass(cmd) };
            drawn.map_err(overlay_err)?;
            if let Some(back) = &back {
                let region = [vk::BufferImageCopy::default()
                    .image_subresource(color_layers())
                    .image_extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })];
                // SAFETY: the pass left the image in TRANSFER_SRC_OPTIMAL; the buffer holds it.
                unsafe {
                    d.cmd_copy_image_to_buffer(cmd, image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, back.raw, &region)
                };
            }
            layout(rec.ctx, cmd, image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, vk::ImageLayout::PRESENT_SRC_KHR);
            Ok(())
        })?;
        for id in &overlay.textures.free {
            self.overlay.free_texture(*id).map_err(overlay_err)?;
        }
        let window_rgba = match &back {
            // The window is opaque: its alpha says nothing.
            Some(b) => Some(rgba8(self.format, b.read()?, Some(255))),
            None => None,
        };
        let shown = self.present(index, done)?;
        Ok(Presented { shown, window_rgba })
    }

    /// The host's drawing under the volume of the next frame that draws the view: `rgba` (RGBA8,
    /// premultiplied, as the display shows it; opaque where nothing is drawn, as it stands in for
    /// the background) at `size`, the viewport's. That frame's draw gets a target composited over
    /// it (`HostTarget::over`): render with no background, and with the drawing's depth
    /// (`RenderOptions::depth`) so that the volume and the drawing hide what lies behind them.
    pub fn underlay(&mut self, size: (u32, u32), rgba: Vec<u8>) -> Result<()> {
        if rgba.len() as u64 != size.0 as u64 * size.1 as u64 * 4 {
            return Err(Error::InvalidArgument(format!(
                "an underlay of {} bytes for {} x {} pixels",
                rgba.len(),
                size.0,
                size.1
            )));
        }
        self.under = Some((rgba, size));
        Ok(())
    }

    /// The volume's image at `size`, drawn by `draw` (or the last one, when the size is the same).
    fn draw_view(&mut self, size: (u32, u32), draw: Option<DrawView<'_>>) -> Result<()> {
        match draw {
            Some(draw) => draw(&self.view_target(size)?),
            None if self.under.is_some() => {
                Err(Error::InvalidArgument("an underlay needs a frame drawn over it".into()))
            }
            None if self.view.is_none() || self.view_size != size => {
                Err(Error::InvalidArgument("a viewport of a new size needs a frame drawn".into()))
            }
            None => Ok(()),
        }
    }

    /// The volume's image at `size` as a frame's destination, over the `underlay` given before
    /// if any, for a host that renders into it outside `frame` (as `render_to_with_progress`
    /// does, presenting frames of its own meanwhile); the next `frame` without a draw shows it.
    pub fn view_target(&mut self, size: (u32, u32)) -> Result<HostTarget> {
        if self.view.is_none() || self.view_size != size {
            self.view = Some(TargetImage::new(&self.ctx, target_format(self.format)?, size.0, size.1)?);
            self.view_size = size;
        }
        let view = self.view.as_ref().expect("made above");
        let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        match self.under.take() {
            Some((_, at)) if at != size => Err(Error::InvalidArgument(format!(
                "an underlay of {} x {} for a {} x {} view",
                at.0, at.1, size.0, size.1
            ))),
            Some((rgba, _)) => view.over(&rgba8(self.format, &rgba, None), src),
            None => view.target(vk::ImageLayout::UNDEFINED, src),
        }
    }

    /// The volume's image of the last frame as the display shows it: RGBA8, `viewport`'s size.
    pub fn read_view(&self) -> Result<Vec<u8>> {
        let view = self.view.as_ref().ok_or_else(|| Error::InvalidArgument("no frame drawn yet".into()))?;
        let target = view.target(vk::ImageLayout::TRANSFER_SRC_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)?;
        Ok(rgba8(self.format, &self.ctx.read_target(&target)?, None))
    }

    /// Present image `index` once `done` signals; false when the swapchain is out of date.
    fn present(&self, index: usize, done: vk::Semaphore) -> Result<bool> {
        let chain = self.chain.as_ref().expect("a frame's chain");
        let (swapchains, indices, waits) = ([chain.raw], [index as u32], [done]);
        let info =
            vk::PresentInfoKHR::default().wait_semaphores(&waits).swapchains(&swapchains).image_indices(&indices);
        let queue = self.ctx.queue.lock().map_err(|_| Error::Unsupported("queue lock poisoned".into()))?;
        // SAFETY: the queue is held under the context's lock; the image was acquired and its frame
        // submitted.
        match unsafe { self.swapchain_fn.queue_present(*queue, &info) } {
            Ok(false) => Ok(true),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(e) => Err(Error::vk("vkQueuePresentKHR")(e)),
        }
    }
}

impl Drop for Presenter {
    fn drop(&mut self) {
        self.ctx.wait_idle();
        self.view = None;
        self.acquire = None;
        if let Some(chain) = self.chain.take() {
            self.destroy_chain(chain);
        }
        // SAFETY: the device is idle; the overlay, pool, pass and surface are ours and unused.
        unsafe {
            ManuallyDrop::drop(&mut self.overlay);
            self.ctx.device.destroy_command_pool(self.pool, None);
            self.ctx.device.destroy_render_pass(self.render_pass, None);
            self.surface_fn.destroy_surface(self.surface, None);
        }
    }
}

/// 8-bit texels of `format` as RGBA, with `alpha` in place of theirs when given (and RGBA as
/// texels of `format`: the swizzle is its own inverse).
fn rgba8(format: vk::Format, texels: &[u8], alpha: Option<u8>) -> Vec<u8> {
    let bgra = matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM);
    texels
        .chunks_exact(4)
        .flat_map(|t| {
            let a = alpha.unwrap_or(t[3]);
            if bgra {
                [t[2], t[1], t[0], a]
            } else {
                [t[0], t[1], t[2], a]
            }
        })
        .collect()
}

fn color_layers() -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 1,
    }
}

/// A layout change of a swapchain image that orders all earlier work before all later work.
fn layout(ctx: &Context, cmd: vk::CommandBuffer, image: vk::Image, from: vk::ImageLayout, to: vk::ImageLayout) {
    let all = super::submit::ENGINE_STAGES;
    let barrier = [vk::ImageMemoryBarrier::default()
        .src_access_mask(layout_access(from, all, vk::AccessFlags::MEMORY_WRITE))
        .dst_access_mask(layout_access(to, all, vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE))
        .old_layout(from)
        .new_layout(to)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(color_range())];
    // SAFETY: recording on a command buffer of this device.
    unsafe { ctx.device.cmd_pipeline_barrier(cmd, all, all, vk::DependencyFlags::empty(), &[], &[], &barrier) };
}

/// The clear before the copy into the same image: both write it.
fn transfer_barrier(device: &ash::Device, cmd: vk::CommandBuffer, image: vk::Image) {
    let barrier = [vk::ImageMemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
        .dst_access_mask(vk::AccessFlags::TRANSFER_WRITE)
        .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(color_range())];
    let t = vk::PipelineStageFlags::TRANSFER;
    // SAFETY: recording on a command buffer of this device.
    unsafe { device.cmd_pipeline_barrier(cmd, t, t, vk::DependencyFlags::empty(), &[], &[], &barrier) };
}
