//! The viewer's own geometry, drawn as a host draws its meshes before voxsplat's frame (issue 46
//! item 5): the volume's bounding box and a slice plane across it, with depth. The host's colour
//! goes into the swapchain image and its depth into a D32 image; `render_to` then reads both
//! (`HostTarget::with_depth(..).over()`): splats behind the geometry are dropped per pixel and the
//! volume is composited over the rest, so the plane hides the half of the volume behind it and the
//! half in front shows over the plane.
//!
//! A host would draw these with its own graphics pipeline; here a few lines and two triangles are
//! rasterised on the CPU (`draw`) and uploaded each frame, which keeps the example free of a
//! second pipeline while exercising the same path: the images and the semaphore a real pass
//! would leave.
use std::sync::Arc;
use voxsplat::glam::{Vec3, Vec4};
use voxsplat::vk::ash::{self, vk};
use voxsplat::vk::{Context, Semaphore};
use voxsplat::volume::Grid;
use voxsplat::{Camera, Error, Result};

/// The bounding box's colour (display values).
pub const BOX_COLOR: [u8; 3] = [255, 200, 40];
/// The slice plane's colour: one flat colour, so a pixel the volume leaves alone keeps it exactly.
pub const PLANE_COLOR: [u8; 3] = [70, 80, 96];

/// The host's frame: display-valued RGBA8 texels (`bgra`: in BGRA order) and D32 depth, row 0 at
/// the top, for `cam`. The box is `grid`'s, its voxels' cells included; the plane lies at index
/// depth `slice` (0 to 1 along the grid's k axis) across it. Depth is cleared to 1 (the far plane).
pub fn draw(cam: &Camera, grid: &Grid, slice: f32, background: [f32; 4], bgra: bool) -> (Vec<u8>, Vec<f32>) {
    let (w, h) = (cam.width as usize, cam.height as usize);
    let bytes = |c: [u8; 3], a: u8| if bgra { [c[2], c[1], c[0], a] } else { [c[0], c[1], c[2], a] };
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    let bg = bytes(
        [q(background[0] * background[3]), q(background[1] * background[3]), q(background[2] * background[3])],
        q(background[3]),
    );
    let mut color: Vec<u8> = std::iter::repeat_n(bg, w * h).flatten().collect();
    let mut depth = vec![1.0f32; w * h];
    let vp = cam.view_proj();
    let d = grid.dims.map(|n| n as f32 - 0.5);
    let corner = |i: usize, k: f32| {
        grid.point(Vec3::new(if i & 1 == 0 { -0.5 } else { d[0] }, if i & 2 == 0 { -0.5 } else { d[1] }, k))
    };
    let k = -0.5 + slice.clamp(0.0, 1.0) * (d[2] + 0.5);
    let plane = [corner(0, k), corner(1, k), corner(3, k), corner(2, k)].map(|p| vp * p.extend(1.0));
    let mut put = |x: usize, y: usize, z: f32, c: [u8; 4]| {
        let at = y * w + x;
        if z >= 0.0 && z < depth[at] {
            depth[at] = z;
            color[4 * at..4 * at + 4].copy_from_slice(&c);
        }
    };
    // The plane: its polygon cut at the near plane (clip z >= 0), as a fan of triangles.
    let poly = clip_near(&plane);
    for i in 1..poly.len().saturating_sub(1) {
        let tri = [poly[0], poly[i], poly[i + 1]].map(|c| screen(c, w, h));
        triangle(tri, w, h, |x, y, z| put(x, y, z, bytes(PLANE_COLOR, 255)));
    }
    // The box's twelve edges, two pixels wide.
    let lo = -0.5;
    let box_corner = |i: usize| vp * corner(i & 3, if i & 4 == 0 { lo } else { d[2] }).extend(1.0);
    for (a, b) in [(0, 1), (1, 3), (3, 2), (2, 0), (4, 5), (5, 7), (7, 6), (6, 4), (0, 4), (1, 5), (2, 6), (3, 7)] {
        let Some((a, b)) = clip_segment(box_corner(a), box_corner(b)) else { continue };
        let (a, b) = (screen(a, w, h), screen(b, w, h));
        let steps = ((b - a).truncate().length() * 2.0).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let p = a.lerp(b, s as f32 / steps as f32);
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                let (x, y) = ((p.x - 0.5 + dx).floor(), (p.y - 0.5 + dy).floor());
                if x >= 0.0 && y >= 0.0 && (x as usize) < w && (y as usize) < h {
                    // Slightly nearer than the plane it lies on, so the plane's own edges show.
                    put(x as usize, y as usize, p.z - 1e-5, bytes(BOX_COLOR, 255));
                }
            }
        }
    }
    (color, depth)
}

/// A clip-space point in pixels (x, y; pixel centres at .5) and its depth.
fn screen(c: Vec4, w: usize, h: usize) -> Vec3 {
    let n = c.truncate() / c.w;
    Vec3::new((n.x * 0.5 + 0.5) * w as f32, (n.y * 0.5 + 0.5) * h as f32, n.z)
}

/// The part of a clip-space polygon in front of the near plane (z >= 0).
fn clip_near(poly: &[Vec4]) -> Vec<Vec4> {
    let mut out = Vec::new();
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        if a.z >= 0.0 {
            out.push(a);
        }
        if (a.z >= 0.0) != (b.z >= 0.0) {
            out.push(a.lerp(b, a.z / (a.z - b.z)));
        }
    }
    out
}

/// The part of a clip-space segment in front of the near plane.
fn clip_segment(a: Vec4, b: Vec4) -> Option<(Vec4, Vec4)> {
    match (a.z >= 0.0, b.z >= 0.0) {
        (true, true) => Some((a, b)),
        (false, false) => None,
        (true, false) => Some((a, a.lerp(b, a.z / (a.z - b.z)))),
        (false, true) => Some((b.lerp(a, b.z / (b.z - a.z)), b)),
    }
}

/// The pixels whose centres a screen triangle covers, with its depth there (depth is affine in
/// screen space over a plane).
fn triangle(t: [Vec3; 3], w: usize, h: usize, mut put: impl FnMut(usize, usize, f32)) {
    let edge = |a: Vec3, b: Vec3, x: f32, y: f32| (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
    let area = edge(t[0], t[1], t[2].x, t[2].y);
    if area.abs() < 1e-12 {
        return;
    }
    let x0 = t.iter().map(|p| p.x).fold(f32::MAX, f32::min).floor().max(0.0) as usize;
    let x1 = (t.iter().map(|p| p.x).fold(f32::MIN, f32::max).ceil().max(0.0) as usize).min(w);
    let y0 = t.iter().map(|p| p.y).fold(f32::MAX, f32::min).floor().max(0.0) as usize;
    let y1 = (t.iter().map(|p| p.y).fold(f32::MIN, f32::max).ceil().max(0.0) as usize).min(h);
    for y in y0..y1 {
        for x in x0..x1 {
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let b = [edge(t[1], t[2], px, py), edge(t[2], t[0], px, py), edge(t[0], t[1], px, py)].map(|e| e / area);
            if b.iter().all(|&v| v >= 0.0) {
                put(x, y, b[0] * t[0].z + b[1] * t[1].z + b[2] * t[2].z);
            }
        }
    }
}

/// The images and commands that carry the host's frame to the device: a D32 depth image, a
/// host-visible staging buffer for both, and a command buffer that copies them in after the
/// swapchain's acquire and signals `drawn`, which `render_to` waits on.
pub struct MeshPass {
    device: ash::Device,
    pub size: (u32, u32),
    depth: vk::Image,
    depth_memory: vk::DeviceMemory,
    staging: vk::Buffer,
    staging_memory: vk::DeviceMemory,
    mapped: *mut u8,
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    pub drawn: Semaphore,
}

fn vk_err(what: &'static str) -> impl Fn(vk::Result) -> Error {
    move |e| Error::Unsupported(format!("{what}: {e}"))
}

impl MeshPass {
    /// # Safety
    ///
    /// `instance`, `physical` and `device` are the host's, the objects `ctx` adopted; `family` is
    /// the queue family voxsplat submits to.
    pub unsafe fn new(
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        device: &ash::Device,
        family: u32,
        ctx: &Arc<Context>,
        size: (u32, u32),
    ) -> Result<Self> {
        let memory = unsafe { instance.get_physical_device_memory_properties(physical) };
        let pick = |bits: u32, flags: vk::MemoryPropertyFlags| {
            (0..memory.memory_type_count)
                .find(|&i| bits & (1 << i) != 0 && memory.memory_types[i as usize].property_flags.contains(flags))
                .ok_or_else(|| Error::Unsupported(format!("no memory type with {flags:?}")))
        };
        let extent = vk::Extent3D { width: size.0, height: size.1, depth: 1 };
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(vk::Format::D32_SFLOAT)
            .extent(extent)
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::TRANSFER_SRC)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let depth = unsafe { device.create_image(&info, None) }.map_err(vk_err("vkCreateImage"))?;
        let req = unsafe { device.get_image_memory_requirements(depth) };
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(pick(req.memory_type_bits, vk::MemoryPropertyFlags::DEVICE_LOCAL)?);
        let depth_memory = unsafe { device.allocate_memory(&alloc, None) }.map_err(vk_err("vkAllocateMemory"))?;
        unsafe { device.bind_image_memory(depth, depth_memory, 0) }.map_err(vk_err("vkBindImageMemory"))?;
        let bytes = size.0 as u64 * size.1 as u64 * 8;
        let info = vk::BufferCreateInfo::default().size(bytes).usage(vk::BufferUsageFlags::TRANSFER_SRC);
        let staging = unsafe { device.create_buffer(&info, None) }.map_err(vk_err("vkCreateBuffer"))?;
        let req = unsafe { device.get_buffer_memory_requirements(staging) };
        let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(pick(req.memory_type_bits, host)?);
        let staging_memory = unsafe { device.allocate_memory(&alloc, None) }.map_err(vk_err("vkAllocateMemory"))?;
        unsafe { device.bind_buffer_memory(staging, staging_memory, 0) }.map_err(vk_err("vkBindBufferMemory"))?;
        let mapped = unsafe { device.map_memory(staging_memory, 0, bytes, vk::MemoryMapFlags::empty()) }
            .map_err(vk_err("vkMapMemory"))? as *mut u8;
        let info = vk::CommandPoolCreateInfo::default().queue_family_index(family);
        let pool = unsafe { device.create_command_pool(&info, None) }.map_err(vk_err("vkCreateCommandPool"))?;
        let info = vk::CommandBufferAllocateInfo::default().command_pool(pool).command_buffer_count(1);
        let cmd = unsafe { device.allocate_command_buffers(&info) }.map_err(vk_err("vkAllocateCommandBuffers"))?[0];
        Ok(Self {
            device: device.clone(),
            size,
            depth,
            depth_memory,
            staging,
            staging_memory,
            mapped,
            pool,
            cmd,
            drawn: Semaphore::new(ctx)?,
        })
    }

    /// The depth image (D32_SFLOAT), in TRANSFER_SRC_OPTIMAL once `submit` has run.
    pub fn depth_image(&self) -> vk::Image {
        self.depth
    }

    /// Copy the host's frame (`draw`) into `image` (the acquired swapchain image) and the depth
    /// image, after `acquired`; both are left in TRANSFER_SRC_OPTIMAL and `drawn` is signalled.
    ///
    /// # Safety
    ///
    /// `image` is the host's image of `self.size` with TRANSFER_DST usage; the work of the last
    /// `submit` is complete (the frame that waited on `drawn` returned); `queue` is used by this
    /// thread only.
    pub unsafe fn submit(
        &self,
        queue: vk::Queue,
        image: vk::Image,
        acquired: vk::Semaphore,
        color: &[u8],
        depth: &[f32],
    ) -> Result<()> {
        let pixels = self.size.0 as usize * self.size.1 as usize;
        assert!(color.len() == 4 * pixels && depth.len() == pixels, "the host's frame fits the pass");
        let d = self.device.clone();
        unsafe {
            std::ptr::copy_nonoverlapping(color.as_ptr(), self.mapped, 4 * pixels);
            std::ptr::copy_nonoverlapping(depth.as_ptr() as *const u8, self.mapped.add(4 * pixels), 4 * pixels);
            d.reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty())
                .map_err(vk_err("vkResetCommandPool"))?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(self.cmd, &begin).map_err(vk_err("vkBeginCommandBuffer"))?;
            let extent = vk::Extent3D { width: self.size.0, height: self.size.1, depth: 1 };
            for (img, aspect, offset) in
                [(image, vk::ImageAspectFlags::COLOR, 0), (self.depth, vk::ImageAspectFlags::DEPTH, 4 * pixels as u64)]
            {
                let range = vk::ImageSubresourceRange {
                    aspect_mask: aspect,
                    level_count: 1,
                    layer_count: 1,
                    ..Default::default()
                };
                let barrier = |from, to, src, dst| {
                    vk::ImageMemoryBarrier::default()
                        .old_layout(from)
                        .new_layout(to)
                        .src_access_mask(src)
                        .dst_access_mask(dst)
                        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .image(img)
                        .subresource_range(range)
                };
                let all = vk::PipelineStageFlags::ALL_COMMANDS;
                let to_dst = [barrier(
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::AccessFlags::empty(),
                    vk::AccessFlags::TRANSFER_WRITE,
                )];
                d.cmd_pipeline_barrier(
                    self.cmd,
                    all,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &to_dst,
                );
                let region = [vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(vk::ImageSubresourceLayers {
                        aspect_mask: aspect,
                        mip_level: 0,
                        base_array_layer: 0,
                        layer_count: 1,
                    })
                    .image_extent(extent)];
                d.cmd_copy_buffer_to_image(self.cmd, self.staging, img, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &region);
                let to_src = [barrier(
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    vk::AccessFlags::TRANSFER_WRITE,
                    vk::AccessFlags::TRANSFER_READ,
                )];
                d.cmd_pipeline_barrier(
                    self.cmd,
                    vk::PipelineStageFlags::TRANSFER,
                    all,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &to_src,
                );
            }
            d.end_command_buffer(self.cmd).map_err(vk_err("vkEndCommandBuffer"))?;
            let (waits, stages, cmds, signals) =
                ([acquired], [vk::PipelineStageFlags::TRANSFER], [self.cmd], [self.drawn.raw()]);
            let submit = [vk::SubmitInfo::default()
                .wait_semaphores(&waits)
                .wait_dst_stage_mask(&stages)
                .command_buffers(&cmds)
                .signal_semaphores(&signals)];
            d.queue_submit(queue, &submit, vk::Fence::null()).map_err(vk_err("vkQueueSubmit"))?;
        }
        Ok(())
    }
}

impl Drop for MeshPass {
    fn drop(&mut self) {
        // SAFETY: the host's device; idle first, so nothing uses these objects.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.pool, None);
            self.device.unmap_memory(self.staging_memory);
            self.device.destroy_buffer(self.staging, None);
            self.device.free_memory(self.staging_memory, None);
            self.device.destroy_image(self.depth, None);
            self.device.free_memory(self.depth_memory, None);
        }
    }
}
