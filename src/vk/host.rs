//! A host's image as a frame's destination (`Renderer::render_to`): the image, its layouts and the
//! semaphores that order the frame with the host's work; an image voxsplat owns for hosts (and
//! tests) without one; semaphores; and reading any of them back.
use super::submit::layout_access;
use super::{Buffer, Context, Image, Memory, Recorder};
use crate::error::{Error, Result};
use crate::image::TargetFormat;
use crate::options::DepthFormat;
use ash::vk;
use std::sync::Arc;

/// The Vulkan format of a target format.
pub fn vk_format(format: TargetFormat) -> vk::Format {
    match format {
        TargetFormat::Bgra8Srgb => vk::Format::B8G8R8A8_SRGB,
        TargetFormat::Bgra8Unorm => vk::Format::B8G8R8A8_UNORM,
        TargetFormat::Rgba8Srgb => vk::Format::R8G8B8A8_SRGB,
        TargetFormat::Rgba8Unorm => vk::Format::R8G8B8A8_UNORM,
        TargetFormat::Rgba16Float => vk::Format::R16G16B16A16_SFLOAT,
    }
}

/// The target format of a Vulkan format, or a typed error naming the ones voxsplat writes.
pub fn target_format(format: vk::Format) -> Result<TargetFormat> {
    TargetFormat::ALL.into_iter().find(|&f| vk_format(f) == format).ok_or_else(|| {
        Error::Unsupported(format!(
            "render_to writes B8G8R8A8 or R8G8B8A8 (SRGB or UNORM) and R16G16B16A16_SFLOAT images, not {format:?}"
        ))
    })
}

/// Where a frame goes: a host's 2D image (one layer, one mip level), the layout it is in when the
/// frame starts and the one to leave it in, the semaphores the frame waits on before it writes the
/// image and those it signals when done.
#[derive(Clone, Debug)]
pub struct HostTarget {
    pub(crate) image: vk::Image,
    pub(crate) format: TargetFormat,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) old_layout: vk::ImageLayout,
    pub(crate) new_layout: vk::ImageLayout,
    pub(crate) wait: Vec<vk::Semaphore>,
    pub(crate) signal: Vec<vk::Semaphore>,
    pub(crate) depth: Option<HostDepth>,
    /// Composite the frame over what the image holds when the frame starts (`HostTarget::over`).
    pub(crate) over: bool,
}

/// The host's depth image a frame reads (`HostTarget::with_depth`).
#[derive(Clone, Debug)]
pub(crate) struct HostDepth {
    pub(crate) image: vk::Image,
    pub(crate) format: DepthFormat,
    pub(crate) layout: vk::ImageLayout,
    pub(crate) projection: glam::Mat4,
}

/// The depth format of a Vulkan format, or a typed error naming the ones voxsplat reads.
pub fn depth_format(format: vk::Format) -> Result<DepthFormat> {
    match format {
        vk::Format::D32_SFLOAT => Ok(DepthFormat::D32),
        vk::Format::D24_UNORM_S8_UINT => Ok(DepthFormat::D24S8),
        other => Err(Error::Unsupported(format!(
            "render_to reads D32_SFLOAT or D24_UNORM_S8_UINT depth images, not {other:?}"
        ))),
    }
}

/// The Vulkan format of a depth format.
pub fn vk_depth_format(format: DepthFormat) -> vk::Format {
    match format {
        DepthFormat::D32 => vk::Format::D32_SFLOAT,
        DepthFormat::D24S8 => vk::Format::D24_UNORM_S8_UINT,
    }
}

/// The aspects a barrier on a depth image of `format` names (a combined format: both).
fn depth_range(format: DepthFormat) -> vk::ImageSubresourceRange {
    let aspect_mask = match format {
        DepthFormat::D32 => vk::ImageAspectFlags::DEPTH,
        DepthFormat::D24S8 => vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
    };
    vk::ImageSubresourceRange { aspect_mask, ..color_range() }
}

impl HostTarget {
    /// Describe a host's image. `old_layout` may be `UNDEFINED` (the frame overwrites it all, as
    /// after a swapchain acquire); `new_layout` is, for example, `PRESENT_SRC_KHR` or
    /// `SHADER_READ_ONLY_OPTIMAL`, and not `UNDEFINED`.
    ///
    /// # Safety
    ///
    /// `image` is a valid 2D image of `format` and `width` x `height` on the device voxsplat's
    /// context uses, created with `TRANSFER_DST` usage (and `TRANSFER_SRC` to read it back), in
    /// `old_layout` when each frame starts; the semaphores are valid binary semaphores of that
    /// device, each `wait` one signalled or pending a signal when the frame is submitted, each
    /// `signal` one unsignalled with no wait pending. All of them stay alive until the frame's
    /// `render_to` returns (it waits for the frame's completion).
    pub unsafe fn new(
        image: vk::Image,
        format: vk::Format,
        (width, height): (u32, u32),
        (old_layout, new_layout): (vk::ImageLayout, vk::ImageLayout),
        wait: &[vk::Semaphore],
        signal: &[vk::Semaphore],
    ) -> Result<Self> {
        let format = target_format(format)?;
        if new_layout == vk::ImageLayout::UNDEFINED || new_layout == vk::ImageLayout::PREINITIALIZED {
            return Err(Error::InvalidArgument(format!("a target cannot be left in layout {new_layout:?}")));
        }
        if width == 0 || height == 0 {
            return Err(Error::InvalidArgument(format!("a target of {width} x {height} pixels")));
        }
        Ok(Self {
            image,
            format,
            width,
            height,
            old_layout,
            new_layout,
            wait: wait.to_vec(),
            signal: signal.to_vec(),
            depth: None,
            over: false,
        })
    }

    /// The same target with the host's depth image: splats behind the host's geometry add nothing
    /// to a pixel (as `RenderOptions::depth`, read on the device). `projection` is the host's
    /// (its eye space the camera's view; near, far and reversed depth its own).
    ///
    /// # Safety
    ///
    /// `image` is a valid 2D image of `format` (D32_SFLOAT or D24_UNORM_S8_UINT) and the target's
    /// size on voxsplat's device, created with `TRANSFER_SRC` usage, in `layout` when the frame
    /// starts (the frame leaves it there) and holding the host's depth: written by work submitted
    /// earlier to the renderer's queue, or complete. It stays alive until `render_to` returns.
    pub unsafe fn with_depth(
        mut self,
        image: vk::Image,
        format: vk::Format,
        layout: vk::ImageLayout,
        projection: glam::Mat4,
    ) -> Result<Self> {
        let format = depth_format(format)?;
        if layout == vk::ImageLayout::UNDEFINED || layout == vk::ImageLayout::PREINITIALIZED {
            return Err(Error::InvalidArgument(format!("a depth image in layout {layout:?} holds no depth")));
        }
        let det = projection.determinant();
        if !(projection.is_finite() && det.is_finite() && det != 0.0) {
            return Err(Error::InvalidArgument("the depth image's projection must be finite and invertible".into()));
        }
        self.depth = Some(HostDepth { image, format, layout, projection });
        Ok(self)
    }

    /// The same target, the frame composited over what the image holds when the frame starts (the
    /// host's own drawing: a mesh, a background) instead of replacing it: its texels, read as
    /// premultiplied display values (8-bit texels as stored, half floats encoded from linear), take
    /// the place of `RenderOptions::background` pixel by pixel. With the host's
    /// depth image (`with_depth`) meshes and the volume then intermix: the volume hides what lies
    /// behind it by its opacity, and geometry in front of it hides the volume.
    ///
    /// # Safety
    ///
    /// As `new`, and the image was created with `TRANSFER_SRC` usage and holds the host's drawing
    /// in `old_layout` (not `UNDEFINED`) when the frame starts: written by work submitted earlier
    /// to the renderer's queue, or complete, or ordered by a `wait` semaphore.
    pub unsafe fn over(mut self) -> Result<Self> {
        if matches!(self.old_layout, vk::ImageLayout::UNDEFINED | vk::ImageLayout::PREINITIALIZED) {
            return Err(Error::InvalidArgument(format!(
                "a target in layout {:?} holds nothing to draw over: give the layout the host's drawing left",
                self.old_layout
            )));
        }
        self.over = true;
        Ok(self)
    }

    /// Whether the frame is composited over the image's contents (`over`).
    pub fn is_over(&self) -> bool {
        self.over
    }

    /// The depth image's format and projection, if the target has one.
    pub fn depth(&self) -> Option<(DepthFormat, glam::Mat4)> {
        self.depth.as_ref().map(|d| (d.format, d.projection))
    }

    /// Its size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Its format.
    pub fn format(&self) -> TargetFormat {
        self.format
    }

    /// The layout the frame leaves it in.
    pub fn layout(&self) -> vk::ImageLayout {
        self.new_layout
    }
}

/// An image voxsplat owns that frames can be rendered into (`Renderer::render_to`) and read back:
/// for hosts that sample a texture rather than present a swapchain, and for tests.
pub struct TargetImage {
    ctx: Arc<Context>,
    image: Image,
    format: TargetFormat,
}

impl TargetImage {
    /// A `width` x `height` image of `format`, usable as a colour attachment, a sampled texture and
    /// a transfer source and destination.
    pub fn new(ctx: &Arc<Context>, format: TargetFormat, width: u32, height: u32) -> Result<Self> {
        use vk::ImageUsageFlags as IU;
        let usage = IU::TRANSFER_DST | IU::TRANSFER_SRC | IU::SAMPLED | IU::COLOR_ATTACHMENT;
        let image = Image::new(ctx, "render_to target", (width, height, 1), vk_format(format), usage, false)?;
        Ok(Self { ctx: ctx.clone(), image, format })
    }

    /// Fill the image with `texels` (the host's drawing: row by row from the top, in the image's
    /// format's bytes, as `Context::read_target` gives them back) and return it as a frame's
    /// destination composited over them (`HostTarget::over`), left in `new_layout`. The copy is
    /// complete when this returns.
    pub fn over(&self, texels: &[u8], new_layout: vk::ImageLayout) -> Result<HostTarget> {
        let (w, h) = (self.image.width, self.image.height);
        let want = w as usize * h as usize * self.format.texel_bytes();
        if texels.len() != want {
            return Err(Error::InvalidArgument(format!(
                "{} bytes of drawing for a {w} x {h} image of {want} bytes ({:?})",
                texels.len(),
                self.format
            )));
        }
        let staging = Buffer::with_data(&self.ctx, "target texels", texels, vk::BufferUsageFlags::TRANSFER_SRC)?;
        let (dst, src) = (vk::ImageLayout::TRANSFER_DST_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        self.ctx.submit(|rec| {
            host_barrier(rec, self.image.raw, (vk::ImageLayout::UNDEFINED, dst));
            rec.copy_buffer_to_image(&staging, &self.image);
            host_barrier(rec, self.image.raw, (dst, src));
            Ok(())
        })?;
        let target = self.target(src, new_layout)?;
        // SAFETY: voxsplat made the image with TRANSFER_SRC usage; the submission above left the
        // drawing in TRANSFER_SRC_OPTIMAL, the target's old layout, and is complete.
        unsafe { target.over() }
    }

    /// The raw handle, for a host that samples it.
    pub fn raw(&self) -> vk::Image {
        self.image.raw
    }

    /// This image as a frame's destination, from `old_layout` (`UNDEFINED` the first time) to
    /// `new_layout`, without semaphores (the frame is complete when `render_to` returns).
    pub fn target(&self, old_layout: vk::ImageLayout, new_layout: vk::ImageLayout) -> Result<HostTarget> {
        let (w, h) = (self.image.width, self.image.height);
        // SAFETY: voxsplat made the image with the needed usage; no semaphores.
        unsafe { HostTarget::new(self.image.raw, vk_format(self.format), (w, h), (old_layout, new_layout), &[], &[]) }
    }
}

/// A depth image voxsplat owns (`D32_SFLOAT` or `D24_UNORM_S8_UINT`), cleared to one depth: the
/// depth of a plane facing the camera, for hosts without their own and for tests.
pub struct DepthImage {
    image: Image,
    format: DepthFormat,
}

impl DepthImage {
    /// A `width` x `height` depth image of `format`, usable as a depth attachment and a transfer
    /// source and destination, cleared to `depth` and left in `TRANSFER_SRC_OPTIMAL`.
    pub fn new(ctx: &Arc<Context>, format: DepthFormat, (width, height): (u32, u32), depth: f32) -> Result<Self> {
        use vk::ImageUsageFlags as IU;
        let usage = IU::TRANSFER_DST | IU::TRANSFER_SRC | IU::DEPTH_STENCIL_ATTACHMENT;
        let image = Image::new_depth(ctx, "host depth", (width, height), vk_depth_format(format), usage)?;
        let range = [depth_range(format)];
        ctx.submit(|rec| {
            let to = |from, to| barrier_on(rec, image.raw, (from, to), range[0]);
            to(vk::ImageLayout::UNDEFINED, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
            let value = vk::ClearDepthStencilValue { depth, stencil: 0 };
            // SAFETY: the image is in TRANSFER_DST_OPTIMAL, made with TRANSFER_DST usage.
            unsafe {
                rec.ctx.device.cmd_clear_depth_stencil_image(
                    rec.cmd,
                    image.raw,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &value,
                    &range,
                )
            };
            to(vk::ImageLayout::TRANSFER_DST_OPTIMAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            Ok(())
        })?;
        Ok(Self { image, format })
    }

    /// The raw handle.
    pub fn raw(&self) -> vk::Image {
        self.image.raw
    }

    /// `target` reading this image (in `TRANSFER_SRC_OPTIMAL`) as the host's depth, drawn with
    /// `projection`.
    pub fn attach(&self, target: HostTarget, projection: glam::Mat4) -> Result<HostTarget> {
        if (self.image.width, self.image.height) != target.size() {
            return Err(Error::InvalidArgument(format!(
                "a {} x {} depth image for a {} x {} target",
                self.image.width, self.image.height, target.width, target.height
            )));
        }
        let layout = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        // SAFETY: voxsplat made the image with TRANSFER_SRC usage, of the target's size, and left
        // it in `layout`, holding the depth it was cleared to (that submission is complete).
        unsafe { target.with_depth(self.image.raw, vk_depth_format(self.format), layout, projection) }
    }
}

/// A binary semaphore, destroyed in Drop (after the device is idle).
pub struct Semaphore {
    ctx: Arc<Context>,
    raw: vk::Semaphore,
}

impl Semaphore {
    /// A new unsignalled semaphore.
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        // SAFETY: valid device.
        let raw = unsafe { ctx.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
            .map_err(Error::vk("vkCreateSemaphore"))?;
        Ok(Self { ctx: ctx.clone(), raw })
    }

    /// The raw handle, for `HostTarget::new` or a host's present.
    pub fn raw(&self) -> vk::Semaphore {
        self.raw
    }
}

impl Drop for Semaphore {
    fn drop(&mut self) {
        self.ctx.wait_idle();
        // SAFETY: the device is idle, so no submission uses it.
        unsafe { self.ctx.device.destroy_semaphore(self.raw, None) };
    }
}

pub(super) fn color_range() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

/// A layout change of a host's image; the semaphore waits and the submission's own barriers order
/// everything else, so every stage this submission records on both sides.
fn host_barrier(rec: &Recorder<'_>, image: vk::Image, layouts: (vk::ImageLayout, vk::ImageLayout)) {
    barrier_on(rec, image, layouts, color_range());
}

/// `host_barrier` over `range` (a depth image's aspects).
fn barrier_on(
    rec: &Recorder<'_>,
    image: vk::Image,
    layouts: (vk::ImageLayout, vk::ImageLayout),
    range: vk::ImageSubresourceRange,
) {
    let all = super::submit::ENGINE_STAGES;
    let b = [vk::ImageMemoryBarrier::default()
        .old_layout(layouts.0)
        .new_layout(layouts.1)
        .src_access_mask(layout_access(layouts.0, all, vk::AccessFlags::MEMORY_WRITE))
        .dst_access_mask(layout_access(layouts.1, all, vk::AccessFlags::MEMORY_READ | vk::AccessFlags::MEMORY_WRITE))
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(range)];
    // SAFETY: recording state; the image (the host's: its promise) is valid and in `layouts.0`.
    unsafe { rec.ctx.device.cmd_pipeline_barrier(rec.cmd, all, all, vk::DependencyFlags::empty(), &[], &[], &b) };
}

impl Recorder<'_> {
    /// Copy the depth aspect of the host's depth image (`HostTarget::with_depth`) into `buffer`
    /// (one 32-bit word per pixel: D32's float, or D24's depth in the low 24 bits), leaving the
    /// image in its layout.
    pub fn copy_host_depth(&self, to: &HostTarget, buffer: &Buffer) {
        let Some(d) = &to.depth else { return };
        let range = depth_range(d.format);
        let barrier = |from, into| barrier_on(self, d.image, (from, into), range);
        let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        if d.layout != src {
            barrier(d.layout, src);
        }
        let region = [vk::BufferImageCopy::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::DEPTH,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D { width: to.width, height: to.height, depth: 1 })];
        // SAFETY: the image is in TRANSFER_SRC_OPTIMAL with TRANSFER_SRC usage (the host's
        // promise); the buffer holds a word per pixel (the recording ensured it).
        unsafe { self.ctx.device.cmd_copy_image_to_buffer(self.cmd, d.image, src, buffer.raw, &region) };
        if d.layout != src {
            barrier(src, d.layout);
        }
    }

    /// Copy the host's image as it is when the frame starts (`HostTarget::over`) into `buffer`, its
    /// texels as stored (a word per pixel, two for a float format), leaving it in its old layout.
    pub fn copy_host_color(&self, to: &HostTarget, buffer: &Buffer) {
        let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        if to.old_layout != src {
            host_barrier(self, to.image, (to.old_layout, src));
        }
        self.copy_raw_to_buffer(to.image, (to.width, to.height), src, buffer);
        if to.old_layout != src {
            host_barrier(self, to.image, (src, to.old_layout));
        }
    }

    /// Blit `src` (in TRANSFER_SRC_OPTIMAL) into the host's image, which the blit converts to its
    /// format (sRGB encoding included), leaving it in its new layout. A smaller `src` (a render
    /// scale: `resample::scaled_camera`'s grid, as tall as the view and centred) is stretched
    /// with the linear filter over the columns the view covers, rounded to whole pixels.
    pub fn blit_to_host(&self, src: &Image, to: &HostTarget) {
        host_barrier(self, to.image, (to.old_layout, vk::ImageLayout::TRANSFER_DST_OPTIMAL));
        let layers = vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        };
        let corner = vk::Offset3D { x: to.width as i32, y: to.height as i32, z: 1 };
        let same = (src.width, src.height) == (to.width, to.height);
        let span = ((to.width as f64 * src.height as f64 / to.height as f64).round() as i32).clamp(1, src.width as i32);
        let x0 = (src.width as i32 - span) / 2;
        let region = [vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([
                vk::Offset3D { x: x0, y: 0, z: 0 },
                vk::Offset3D { x: x0 + span, y: src.height as i32, z: 1 },
            ])
            .dst_subresource(layers)
            .dst_offsets([vk::Offset3D::default(), corner])];
        let filter = if same { vk::Filter::NEAREST } else { vk::Filter::LINEAR };
        // SAFETY: both images alive for the submission and in the layouts named.
        unsafe {
            self.ctx.device.cmd_blit_image(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                to.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
                filter,
            )
        };
        host_barrier(self, to.image, (vk::ImageLayout::TRANSFER_DST_OPTIMAL, to.new_layout));
    }
}

impl Context {
    /// Whether frames can be blitted from RGBA32F into images of `format` (`scaled`: with the linear
    /// filter): refused with a typed error when the device lacks the formats' features.
    pub fn check_target(&self, format: TargetFormat, scaled: bool) -> Result<()> {
        let feature = |f: vk::Format| {
            // SAFETY: plain query on a valid physical device.
            unsafe { self.instance.get_physical_device_format_properties(self.physical, f) }.optimal_tiling_features
        };
        let mut needs = vk::FormatFeatureFlags::BLIT_SRC;
        if scaled {
            needs |= vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR;
        }
        let src = feature(vk::Format::R32G32B32A32_SFLOAT).contains(needs);
        let dst = feature(vk_format(format)).contains(vk::FormatFeatureFlags::BLIT_DST);
        if src && dst {
            Ok(())
        } else {
            Err(Error::Unsupported(format!(
                "{} cannot blit RGBA32F into {:?} images (BLIT_SRC{} {src}, BLIT_DST {dst})",
                self.device_name(),
                vk_format(format),
                if scaled { " with linear filtering" } else { "" }
            )))
        }
    }

    /// The texels of a target after a frame (in its new layout, which stays), row by row in the
    /// image's own format. The image needs `TRANSFER_SRC` usage.
    pub fn read_target(self: &Arc<Self>, target: &HostTarget) -> Result<Vec<u8>> {
        let bytes = target.width as u64 * target.height as u64 * target.format.texel_bytes() as u64;
        let back = Buffer::new(self, "target readback", bytes, vk::BufferUsageFlags::TRANSFER_DST, Memory::Readback)?;
        self.submit(|rec| {
            let src = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
            host_barrier(rec, target.image, (target.new_layout, src));
            rec.copy_raw_to_buffer(target.image, (target.width, target.height), src, &back);
            host_barrier(rec, target.image, (src, target.new_layout));
            Ok(())
        })?;
        Ok(back.read()?.to_vec())
    }
}
