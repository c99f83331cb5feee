//! What voxsplat reads from a Vulkan device, and every choice it makes from it, in one place.
//!
//! `vk::Context` fills a [`DeviceProfile`] from the device's properties, features and format
//! support; [`DeviceProfile::choices`] turns it into [`DeviceChoices`], which the rest of the
//! library reads: the raster path `auto` picks, the compositor's subgroup build, 64-bit sheet
//! sums, point sprites, how frames are timed, image and binding limits, the default device-memory
//! budget. Each missing feature has a fallback, named in `DeviceChoices::fallbacks`. The choices are
//! plain functions of the profile, so tests run them against recorded profiles
//! (`tests/data/devices/`: lavapipe's and a discrete NVIDIA one from its public limits) as well as
//! against the device at hand.
//!
//! ```
//! use voxsplat::{Backend, Renderer, RendererOptions};
//! // What voxsplat chose on the device it opened (`voxsplat info` prints it); none on the CPU.
//! let mut o = RendererOptions::default();
//! o.backend = Backend::Cpu;
//! let mut r = Renderer::new(&o)?;
//! assert!(r.context().is_none());
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::constants::{DEFAULT_GPU_BUDGET, RASTER_LANES};
use serde::{Deserialize, Serialize};

/// The kind of device, as Vulkan reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DeviceKind {
    /// A discrete GPU.
    Discrete,
    /// A GPU sharing the host's memory.
    Integrated,
    /// A GPU in a virtual machine.
    Virtual,
    /// A CPU implementation (lavapipe, SwiftShader).
    Cpu,
    /// Anything else.
    Other,
}

/// What a device reports that voxsplat's choices depend on. A device adopted from a host program
/// (`vk::Context::from_host`) reports the optional features as the host enabled them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceProfile {
    /// The device's name.
    pub name: String,
    /// Its kind.
    pub kind: DeviceKind,
    /// PCI vendor id (0x10de NVIDIA, 0x1002 AMD, 0x8086 Intel, 0x10005 Mesa's CPU drivers).
    pub vendor_id: u32,
    /// Vulkan version the device supports: major, minor, patch.
    pub api_version: [u32; 3],
    /// The driver's name and version text (`VkPhysicalDeviceDriverProperties`).
    pub driver: String,
    /// `shaderOutputLayer` (Vulkan 1.2): sheets write their layer from the vertex shader.
    pub shader_output_layer: bool,
    /// A queue family with graphics and compute.
    pub graphics_compute_queue: bool,
    /// `largePoints`: point sprites wider than a pixel.
    pub large_points: bool,
    /// `pointSizeRange`, in pixels.
    pub point_size_range: [f32; 2],
    /// `shaderInt64` and `shaderBufferInt64Atomics` both.
    pub int64_atomics: bool,
    /// Nanoseconds per timestamp tick (`timestampPeriod`).
    pub timestamp_period: f32,
    /// `timestampValidBits` of the queue voxsplat uses (0: no timestamps).
    pub timestamp_valid_bits: u32,
    /// Lanes in a compute subgroup (`subgroupSize`).
    pub subgroup_size: u32,
    /// Subgroup shuffles and arithmetic in compute shaders.
    pub subgroup_shuffle_arithmetic: bool,
    /// Largest 2-D image side, the framebuffer's width and height included.
    pub max_image_side: u32,
    /// Most array layers of an image and of a framebuffer.
    pub max_layers: u32,
    /// `maxStorageBufferRange`, in bytes.
    pub max_storage_range: u64,
    /// RGBA32F colour attachments blend (the graphics and point rasters' target format).
    pub rgba32f_blend: bool,
    /// Bytes of the largest device-local memory heap.
    pub device_local_bytes: u64,
}

/// How a frame's stages are timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Timing {
    /// GPU timestamps: nanoseconds a tick, and the mask of the bits a timestamp holds.
    Timestamps {
        /// Nanoseconds per tick.
        period_ns: f64,
        /// Bits that hold the count (it wraps past them).
        mask: u64,
    },
    /// Host clocks around each stage's own submission.
    Host,
}

/// What voxsplat does on a device: every device-dependent choice, and the fallbacks taken.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceChoices {
    /// Why the device cannot run voxsplat at all (`None`: it can).
    pub unusable: Option<String>,
    /// Preference among several devices: discrete > integrated > virtual > CPU > other.
    pub rank: u32,
    /// A primitive-bound rasteriser (a CPU device): `--raster auto` picks compute or point sprites
    /// for small footprints there, and the graphics pipeline on any other device.
    pub cpu: bool,
    /// How stages are timed.
    pub timing: Timing,
    /// The tile compositor's subgroup build: shuffles and arithmetic in subgroups of at least
    /// `RASTER_LANES` lanes (else its shared-memory build).
    pub subgroup_shuffle: bool,
    /// Sheet sums add two channels per 64-bit atomic (else one per 32-bit atomic).
    pub int64_atomics: bool,
    /// Widest point sprite in pixels (1 without `largePoints`).
    pub point_size_max: f32,
    /// The graphics and point-sprite rasters can draw (RGBA32F blending): else only compute.
    pub graphics_raster: bool,
    /// Largest image side and layer count (frames, sheets).
    pub max_image_side: u32,
    /// Most layers of a sheet image.
    pub max_layers: u32,
    /// Largest storage binding, in bytes.
    pub max_storage_range: u64,
    /// Device memory a frame may hold unless the caller says otherwise: 1 GiB on a
    /// CPU device (its memory is the host's, which holds the volume too), else half the largest
    /// device-local heap, never below the default.
    pub default_budget: u64,
    /// Largest budget a caller may set: the largest device-local heap on a GPU; unbounded on a CPU
    /// device, whose "device" memory is the host's (lavapipe reports a 2 GiB heap it does not
    /// enforce), where the host-memory budget applies instead.
    pub max_budget: u64,
    /// One line per fallback taken for a missing feature.
    pub fallbacks: Vec<String>,
}

impl DeviceKind {
    fn rank(self) -> u32 {
        match self {
            DeviceKind::Discrete => 4,
            DeviceKind::Integrated => 3,
            DeviceKind::Virtual => 2,
            DeviceKind::Cpu => 1,
            DeviceKind::Other => 0,
        }
    }
}

impl DeviceProfile {
    /// Every device-dependent choice, from this profile alone.
    pub fn choices(&self) -> DeviceChoices {
        let mut fallbacks = Vec::new();
        let mut unusable = Vec::new();
        if self.api_version[0] == 1 && self.api_version[1] < 2 {
            unusable.push("Vulkan 1.2 required".to_string());
        }
        if !self.shader_output_layer {
            unusable.push("shaderOutputLayer missing".to_string());
        }
        if !self.graphics_compute_queue {
            unusable.push("no graphics+compute queue".to_string());
        }
        let cpu = self.kind == DeviceKind::Cpu;
        // A CPU device's timestamps count the recording's host time, not each stage's: per-stage
        // submissions timed by the host's clock say more there.
        let timing = if cpu {
            Timing::Host
        } else if self.timestamp_valid_bits == 0 || self.timestamp_period <= 0.0 {
            fallbacks.push("no timestamps on the queue: stages timed by the host's clock".into());
            Timing::Host
        } else {
            let bits = self.timestamp_valid_bits.min(64);
            let mask = if bits == 64 { u64::MAX } else { (1u64 << bits) - 1 };
            Timing::Timestamps { period_ns: self.timestamp_period as f64, mask }
        };
        let subgroup_shuffle = self.subgroup_shuffle_arithmetic && self.subgroup_size >= RASTER_LANES;
        if !subgroup_shuffle {
            fallbacks.push(format!(
                "subgroups of {} lanes{}: the tile compositor shares pixels through shared memory",
                self.subgroup_size,
                if self.subgroup_shuffle_arithmetic { "" } else { " without shuffles and arithmetic" }
            ));
        }
        if !self.int64_atomics {
            fallbacks.push("no 64-bit buffer atomics: sheet sums add one channel per atomic".into());
        }
        let point_size_max = if self.large_points { self.point_size_range[1].max(1.0) } else { 1.0 };
        if !self.large_points {
            fallbacks.push("no largePoints: point sprites are never picked, and --raster points is refused".into());
        }
        if !self.rgba32f_blend {
            fallbacks.push("RGBA32F targets do not blend: footprints drawn by compute only".into());
        }
        let max_budget = if cpu { u64::MAX } else { self.device_local_bytes.max(1) };
        let default_budget =
            if cpu { DEFAULT_GPU_BUDGET } else { (self.device_local_bytes / 2).max(DEFAULT_GPU_BUDGET) }
                .min(max_budget);
        DeviceChoices {
            unusable: (!unusable.is_empty()).then(|| unusable.join("; ")),
            rank: self.kind.rank(),
            cpu,
            timing,
            subgroup_shuffle,
            int64_atomics: self.int64_atomics,
            point_size_max,
            graphics_raster: self.rgba32f_blend,
            max_image_side: self.max_image_side,
            max_layers: self.max_layers,
            max_storage_range: self.max_storage_range,
            default_budget,
            max_budget,
            fallbacks,
        }
    }

    /// The API version as text ("1.3.289").
    pub fn api(&self) -> String {
        format!("{}.{}.{}", self.api_version[0], self.api_version[1], self.api_version[2])
    }
}
