//! The thin ash layer: the only place with `unsafe`. One file per Vulkan concern.
//!
//! ```,no_run
//! use voxsplat::vk::{Context, ContextOptions};
//! // voxsplat's own Vulkan device; a host that has one passes its handles (`HostHandles`) instead.
//! let ctx = Context::new(&ContextOptions::default())?;
//! println!("{}", ctx.device_name());
//! # Ok::<(), voxsplat::Error>(())
//! ```
mod buffer;
mod context;
mod debug;
mod host;
mod image;
mod pipeline;
#[cfg(feature = "window")]
mod present;
mod profile;
mod submit;
mod timer;

pub use ash;
pub use ash::vk::{BufferUsageFlags, Format, ImageLayout, ImageUsageFlags, ShaderStageFlags};
pub use buffer::{Buffer, Memory};
pub use context::{Context, ContextOptions, HostHandles};
pub use host::{
    depth_format, target_format, vk_depth_format, vk_format, DepthImage, HostTarget, Semaphore, TargetImage,
};
pub use image::{Image, Sampler};
pub use pipeline::{Bind, Blend, DescriptorSet, Framebuffer, Layout, Pipeline, Primitive, RenderPass, Slot};
#[cfg(feature = "window")]
pub use present::{DrawView, OverlayFrame, PresentOptions, PresentWindow, Presented, Presenter, Viewport};
pub use submit::{Recorder, Stage};
pub use timer::Timer;
