//! 2D images and image arrays with one view, freed in Drop.
use super::Context;
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// A Vulkan image, its memory and one view.
pub struct Image {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Image,
    pub(crate) view: vk::ImageView,
    allocation: Option<Allocation>,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) layers: u32,
    pub(crate) depth: u32,
}

impl Image {
    /// A device-local image; with `layers > 1` or `array` its view is a 2D array.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        (width, height, layers): (u32, u32, u32),
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        array: bool,
    ) -> Result<Self> {
        Self::create(ctx, name, (width, height, 1), layers, format, usage, array, false, vk::ImageAspectFlags::COLOR)
    }

    /// A device-local 2D depth image (its view of the depth aspect).
    pub fn new_depth(
        ctx: &Arc<Context>,
        name: &str,
        (width, height): (u32, u32),
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        Self::create(ctx, name, (width, height, 1), 1, format, usage, false, false, vk::ImageAspectFlags::DEPTH)
    }

    /// A device-local 3D image (one layer).
    pub fn new_3d(
        ctx: &Arc<Context>,
        name: &str,
        extent: (u32, u32, u32),
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        Self::create(ctx, name, extent, 1, format, usage, false, true, vk::ImageAspectFlags::COLOR)
    }

    #[allow(clippy::too_many_arguments)]
    fn create(
        ctx: &Arc<Context>,
        name: &str,
        (width, height, depth): (u32, u32, u32),
        layers: u32,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        array: bool,
        three_d: bool,
        aspect: vk::ImageAspectFlags,
    ) -> Result<Self> {
        let info = vk::ImageCreateInfo::default()
            .image_type(if three_d { vk::ImageType::TYPE_3D } else { vk::ImageType::TYPE_2D })
            .format(format)
            .extent(vk::Extent3D { width, height, depth })
            .mip_levels(1)
            .array_layers(layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_image(&info, None) }.map_err(Error::vk("vkCreateImage"))?;
        // SAFETY: `raw` was just created.
        let requirements = unsafe { ctx.device.get_image_memory_requirements(raw) };
        let allocation = ctx.allocator.lock().map_err(|_| Error::Unsupported("allocator poisoned".into()))?.allocate(
            &AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            },
        );
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: unused image.
                unsafe { ctx.device.destroy_image(raw, None) };
                return Err(match e {
                    gpu_allocator::AllocationError::OutOfMemory => Error::OutOfMemory(name.to_string()),
                    other => Error::Unsupported(format!("allocating {name}: {other}")),
                });
            }
        };
        let mut image = Self {
            ctx: ctx.clone(),
            raw,
            view: vk::ImageView::null(),
            allocation: Some(allocation),
            width,
            height,
            layers,
            depth,
        };
        let alloc = image.allocation.as_ref().expect("just set");
        // SAFETY: memory from the allocator for these requirements.
        unsafe { ctx.device.bind_image_memory(raw, alloc.memory(), alloc.offset()) }
            .map_err(Error::vk("vkBindImageMemory"))?;
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(if three_d {
                vk::ImageViewType::TYPE_3D
            } else if array || layers > 1 {
                vk::ImageViewType::TYPE_2D_ARRAY
            } else {
                vk::ImageViewType::TYPE_2D
            })
            .format(format)
            .subresource_range(vk::ImageSubresourceRange { aspect_mask: aspect, ..Self::range_of(layers) });
        // SAFETY: bound image, matching format.
        image.view =
            unsafe { ctx.device.create_image_view(&view_info, None) }.map_err(Error::vk("vkCreateImageView"))?;
        Ok(image)
    }

    pub(crate) fn range_of(layers: u32) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: layers,
        }
    }

    pub(crate) fn range(&self) -> vk::ImageSubresourceRange {
        Self::range_of(self.layers)
    }

    /// Width, height and depth (or layers).
    pub fn extent(&self) -> (u32, u32, u32) {
        (self.width, self.height, self.layers)
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: owners wait idle before dropping; view before image before memory.
        unsafe {
            if self.view != vk::ImageView::null() {
                self.ctx.device.destroy_image_view(self.view, None);
            }
            self.ctx.device.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            if let Ok(mut alloc) = self.ctx.allocator.lock() {
                let _ = alloc.free(a);
            }
        }
    }
}

/// A nearest-neighbour sampler (the footprint table is read with texelFetch).
pub struct Sampler {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Sampler,
}

impl Sampler {
    /// A nearest-neighbour, clamp-to-edge sampler.
    pub fn nearest(ctx: &Arc<Context>) -> Result<Self> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        // SAFETY: valid create info.
        let raw = unsafe { ctx.device.create_sampler(&info, None) }.map_err(Error::vk("vkCreateSampler"))?;
        Ok(Self { ctx: ctx.clone(), raw })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: unused once the owner waited idle.
        unsafe { self.ctx.device.destroy_sampler(self.raw, None) };
    }
}
