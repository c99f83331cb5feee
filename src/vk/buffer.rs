//! Buffers that free their allocation and destroy themselves in Drop.
use super::Context;
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// Where a buffer lives: written by the host every frame, read back by the host, or GPU only.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Memory {
    /// Host-visible, written by the host.
    Upload,
    /// Host-visible, read back by the host.
    Readback,
    /// Device-local.
    Device,
}

/// A Vulkan buffer and its memory.
pub struct Buffer {
    ctx: Arc<Context>,
    pub(crate) raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
}

fn allocation_error(name: &str, e: gpu_allocator::AllocationError) -> Error {
    match e {
        gpu_allocator::AllocationError::OutOfMemory => Error::OutOfMemory(name.to_string()),
        other => Error::Unsupported(format!("allocating {name}: {other}")),
    }
}

impl Buffer {
    /// A buffer of at least `size` bytes (zero is rounded up to 16: Vulkan forbids empty buffers).
    pub fn new(ctx: &Arc<Context>, name: &str, size: u64, usage: vk::BufferUsageFlags, memory: Memory) -> Result<Self> {
        let size = size.max(16);
        let info = vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let raw = unsafe { ctx.device.create_buffer(&info, None) }.map_err(Error::vk("vkCreateBuffer"))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let location = match memory {
            Memory::Upload => MemoryLocation::CpuToGpu,
            Memory::Readback => MemoryLocation::GpuToCpu,
            Memory::Device => MemoryLocation::GpuOnly,
        };
        let allocation = ctx.allocator.lock().map_err(|_| Error::Unsupported("allocator poisoned".into()))?.allocate(
            &AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            },
        );
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: unbound, unused buffer.
                unsafe { ctx.device.destroy_buffer(raw, None) };
                return Err(allocation_error(name, e));
            }
        };
        // SAFETY: memory and offset come from the allocator for these requirements.
        if let Err(e) = unsafe { ctx.device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) } {
            let _ = ctx.allocator.lock().map(|mut a| a.free(allocation));
            // SAFETY: unused buffer.
            unsafe { ctx.device.destroy_buffer(raw, None) };
            return Err(Error::vk("vkBindBufferMemory")(e));
        }
        Ok(Self { ctx: ctx.clone(), raw, allocation: Some(allocation), size })
    }

    /// A host-visible buffer holding `data`.
    pub fn with_data(ctx: &Arc<Context>, name: &str, data: &[u8], usage: vk::BufferUsageFlags) -> Result<Self> {
        let mut b = Self::new(ctx, name, data.len() as u64, usage, Memory::Upload)?;
        b.write(data)?;
        Ok(b)
    }

    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// Copy `data` to the start of a host-visible buffer.
    pub fn write(&mut self, data: &[u8]) -> Result<()> {
        self.write_at(0, data)
    }

    /// Copy `data` into a host-visible buffer from byte `offset` on (the device must not be using
    /// the bytes: the caller waits for it).
    pub fn write_at(&mut self, offset: u64, data: &[u8]) -> Result<()> {
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| Error::Unsupported("buffer is not host visible".into()))?;
        let end = offset.checked_add(data.len() as u64).filter(|&e| e <= slice.len() as u64).ok_or_else(|| {
            Error::InvalidArgument(format!("{} bytes at {offset} into a {}-byte buffer", data.len(), slice.len()))
        })?;
        slice[offset as usize..end as usize].copy_from_slice(data);
        Ok(())
    }

    /// The contents of a host-visible buffer.
    pub fn read(&self) -> Result<&[u8]> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .ok_or_else(|| Error::Unsupported("buffer is not host visible".into()))
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // The buffer goes before its memory: freeing memory still bound to a live buffer is legal
        // but leaves a dangling binding, which best-practices validation reports.
        // SAFETY: the owner waits for the GPU before dropping resources (Renderer waits idle).
        unsafe { self.ctx.device.destroy_buffer(self.raw, None) };
        if let Some(a) = self.allocation.take() {
            if let Ok(mut alloc) = self.ctx.allocator.lock() {
                let _ = alloc.free(a);
            }
        }
    }
}
