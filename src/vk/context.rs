//! Instance, device, queue and allocator: created headless, or adopted from a host program.
use super::debug::{callback, DebugState};
use crate::device::{DeviceChoices, DeviceProfile};
use crate::error::{Error, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::CStr;
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Options for [`Context::new`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable `VK_LAYER_KHRONOS_validation` with synchronization validation; messages are counted.
    pub validation: bool,
    /// Pick the device whose name contains this string (case-insensitive).
    pub device_name: Option<String>,
}

struct Debug {
    loader: ash::ext::debug_utils::Instance,
    messenger: vk::DebugUtilsMessengerEXT,
}

/// A host program's Vulkan objects, handed to [`Context::from_host`].
#[derive(Clone)]
pub struct HostHandles {
    /// The Vulkan loader the host loaded.
    pub entry: ash::Entry,
    /// The host's instance.
    pub instance: ash::Instance,
    /// The physical device `device` was created on.
    pub physical: vk::PhysicalDevice,
    /// The host's device.
    pub device: ash::Device,
    /// A queue of `queue_family` with graphics and compute.
    pub queue: vk::Queue,
    /// The queue's family index.
    pub queue_family: u32,
    /// Whether `device` was created with the `largePoints` feature: point sprites wider than one
    /// pixel, which `auto` prefers on a CPU device. Without it voxsplat draws no wide sprites.
    pub large_points: bool,
    /// Whether `device` was created with `shaderInt64` and `shaderBufferInt64Atomics`: the compute
    /// sheet sums then add two channels per atomic (~1.3x faster on lavapipe), else one.
    pub int64_atomics: bool,
}

/// The Vulkan objects every resource needs. Resources hold an `Arc<Context>` so it outlives them.
pub struct Context {
    _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    pub(crate) physical: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    pub(crate) queue: Mutex<vk::Queue>,
    pub(crate) queue_family: u32,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    debug: Option<Debug>,
    debug_state: Box<DebugState>,
    owned: bool,
    /// What the device reports (the optional features as it was created with them).
    profile: DeviceProfile,
    /// Every choice made from `profile`.
    choices: DeviceChoices,
    /// `choices.subgroup_shuffle`, which a test may turn off.
    subgroup_shuffle: AtomicBool,
    /// Set once a call reports VK_ERROR_DEVICE_LOST: later submissions fail fast.
    pub(crate) lost: AtomicBool,
    /// Test-only fault for the next submission (a raw `vk::Result`, 0 = none).
    pub(crate) injected: AtomicI32,
}

impl Context {
    /// A headless context on the best device: discrete > integrated > virtual > CPU.
    pub fn new(options: &ContextOptions) -> Result<Arc<Self>> {
        Self::create(options, &[])
    }

    /// `new`, with a window system's surface extensions on the instance and `VK_KHR_swapchain` on
    /// the device when `surface` is not empty (the `Presenter`'s context).
    pub(crate) fn create(options: &ContextOptions, surface: &[*const std::ffi::c_char]) -> Result<Arc<Self>> {
        // SAFETY: loading the system Vulkan loader; it stays alive as long as `_entry`.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
        let debug_state = Box::<DebugState>::default();

        let mut layers = Vec::new();
        let mut extensions = Vec::new();
        if options.validation {
            // SAFETY: plain enumeration.
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .map_err(Error::vk("vkEnumerateInstanceLayerProperties"))?;
            let found =
                available.iter().any(|l| l.layer_name_as_c_str().map(|n| n == VALIDATION_LAYER).unwrap_or(false));
            if !found {
                return Err(Error::Unsupported(
                    "validation requested but VK_LAYER_KHRONOS_validation is not installed \
                     (Debian: apt-get install vulkan-validationlayers)"
                        .into(),
                ));
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        extensions.extend_from_slice(surface);
        let app = vk::ApplicationInfo::default()
            .application_name(c"voxsplat")
            .engine_name(c"voxsplat")
            .api_version(vk::make_api_version(0, 1, 2, 0));
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        let user_data = &*debug_state as *const DebugState as *mut std::ffi::c_void;
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(callback))
            .user_data(user_data);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if options.validation {
            info = info.push_next(&mut features).push_next(&mut messenger_info);
        }
        // SAFETY: all pointers in `info` outlive the call.
        let instance = unsafe { entry.create_instance(&info, None) }.map_err(Error::vk("vkCreateInstance"))?;

        let debug = if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            // The chained copy above only covers instance creation; the messenger itself needs a
            // create info with an empty pNext.
            let own_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(messenger_info.message_severity)
                .message_type(messenger_info.message_type)
                .pfn_user_callback(Some(callback))
                .user_data(user_data);
            // SAFETY: `debug_state` is boxed and outlives the messenger (destroyed in Drop first).
            match unsafe { loader.create_debug_utils_messenger(&own_info, None) } {
                Ok(messenger) => Some(Debug { loader, messenger }),
                Err(e) => {
                    // SAFETY: nothing else was created from this instance.
                    unsafe { instance.destroy_instance(None) };
                    return Err(Error::vk("vkCreateDebugUtilsMessengerEXT")(e));
                }
            }
        } else {
            None
        };

        let picked = Self::pick_device(&instance, options);
        let (physical, queue_family) = match picked {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: tear down what we created, in reverse order.
                unsafe {
                    if let Some(d) = &debug {
                        d.loader.destroy_debug_utils_messenger(d.messenger, None);
                    }
                    instance.destroy_instance(None);
                }
                return Err(e);
            }
        };

        let priorities = [1.0f32];
        let queues =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
        // Point sprites wider than one pixel (`--raster points`) and 64-bit buffer atomics (the
        // compute sheet sums) when the device has them.
        let mut has12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut has = vk::PhysicalDeviceFeatures2::default().push_next(&mut has12);
        // SAFETY: plain query on a valid physical device; the chain lives on the stack.
        unsafe { instance.get_physical_device_features2(physical, &mut has) };
        let supported = has.features;
        let int64_atomics = supported.shader_int64 == vk::TRUE && has12.shader_buffer_int64_atomics == vk::TRUE;
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .shader_output_layer(true)
            .shader_buffer_int64_atomics(int64_atomics);
        let core = vk::PhysicalDeviceFeatures::default()
            .large_points(supported.large_points == vk::TRUE)
            .shader_int64(int64_atomics);
        let swapchain = [ash::khr::swapchain::NAME.as_ptr()];
        let device_extensions: &[_] = if surface.is_empty() { &[] } else { &swapchain };
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_features(&core)
            .enabled_extension_names(device_extensions)
            .push_next(&mut f12);
        // SAFETY: `physical` came from this instance; features were checked in pick_device.
        let device = match unsafe { instance.create_device(physical, &device_info, None) } {
            Ok(d) => d,
            Err(e) => {
                // SAFETY: reverse-order teardown of what exists.
                unsafe {
                    if let Some(d) = &debug {
                        d.loader.destroy_debug_utils_messenger(d.messenger, None);
                    }
                    instance.destroy_instance(None);
                }
                return Err(Error::vk("vkCreateDevice")(e));
            }
        };
        // SAFETY: queue family and index were requested above.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let large_points = supported.large_points == vk::TRUE;
        let handles =
            HostHandles { entry, instance, physical, device, queue, queue_family, large_points, int64_atomics };
        Self::finish(handles, debug, debug_state, true)
    }

    /// Adopt a host program's instance, device and queue. The host keeps ownership: nothing is
    /// destroyed here. The device needs Vulkan 1.2 `shaderOutputLayer` enabled and a
    /// graphics+compute queue (the feature flags in `host` say what else was enabled).
    ///
    /// # Safety
    ///
    /// - `host.entry`, `instance`, `physical`, `device` and `queue` are valid, belong together
    ///   (the device was created from `physical` of `instance`, `queue` is queue 0 or another queue
    ///   of `queue_family` on `device`), and stay alive until every `Context` clone and every
    ///   renderer, buffer and image built on it are dropped.
    /// - `large_points` and `int64_atomics` are true only if the device was created with those
    ///   features enabled.
    /// - The host does not use `queue` from another thread while voxsplat records or submits on
    ///   it (Vulkan requires external synchronization of a queue), and does not destroy or reset
    ///   objects voxsplat created.
    pub unsafe fn from_host(host: HostHandles) -> Result<Arc<Self>> {
        Self::finish(host, None, Box::default(), false)
    }

    /// This context's Vulkan objects, for a host that wants to share them (for example to draw
    /// voxsplat's output into its own frame).
    pub fn handles(&self) -> HostHandles {
        HostHandles {
            entry: self._entry.clone(),
            instance: self.instance.clone(),
            physical: self.physical,
            device: self.device.clone(),
            queue: self.queue.lock().map(|q| *q).unwrap_or_default(),
            queue_family: self.queue_family,
            large_points: self.profile.large_points,
            int64_atomics: self.profile.int64_atomics,
        }
    }

    fn finish(
        handles: HostHandles,
        debug: Option<Debug>,
        debug_state: Box<DebugState>,
        owned: bool,
    ) -> Result<Arc<Self>> {
        let HostHandles { entry, instance, physical, device, queue, queue_family, large_points, int64_atomics } =
            handles;
        let profile =
            super::profile::read(&instance, physical, Some(queue_family), Some((large_points, int64_atomics)));
        let choices = profile.choices();
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                if owned {
                    // SAFETY: reverse-order teardown of what we own.
                    unsafe {
                        device.destroy_device(None);
                        if let Some(d) = &debug {
                            d.loader.destroy_debug_utils_messenger(d.messenger, None);
                        }
                        instance.destroy_instance(None);
                    }
                }
                return Err(Error::Unsupported(format!("gpu-allocator: {e}")));
            }
        };
        Ok(Arc::new(Self {
            _entry: entry,
            instance,
            physical,
            device,
            queue: Mutex::new(queue),
            queue_family,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            debug,
            debug_state,
            owned,
            subgroup_shuffle: AtomicBool::new(choices.subgroup_shuffle),
            profile,
            choices,
            lost: AtomicBool::new(false),
            injected: AtomicI32::new(0),
        }))
    }

    fn pick_device(instance: &ash::Instance, options: &ContextOptions) -> Result<(vk::PhysicalDevice, u32)> {
        // SAFETY: plain enumeration and queries.
        let devices =
            unsafe { instance.enumerate_physical_devices() }.map_err(Error::vk("vkEnumeratePhysicalDevices"))?;
        let mut best: Option<(u32, vk::PhysicalDevice, u32)> = None;
        let mut rejected = Vec::new();
        for pd in devices {
            let family = super::profile::queue_family(instance, pd);
            let profile = super::profile::read(instance, pd, family, None);
            if let Some(want) = &options.device_name {
                if !profile.name.to_lowercase().contains(&want.to_lowercase()) {
                    continue;
                }
            }
            let choices = profile.choices();
            let (Some(family), None) = (family, &choices.unusable) else {
                rejected.push(format!("{}: {}", profile.name, choices.unusable.unwrap_or_default()));
                continue;
            };
            if best.map(|b| choices.rank > b.0).unwrap_or(true) {
                best = Some((choices.rank, pd, family));
            }
        }
        best.map(|(_, pd, f)| (pd, f)).ok_or_else(|| {
            Error::Unsupported(format!(
                "no suitable Vulkan device{}{}",
                if rejected.is_empty() { "" } else { ": " },
                rejected.join("; ")
            ))
        })
    }

    /// The device's name as the driver reports it.
    pub fn device_name(&self) -> &str {
        &self.profile.name
    }

    /// What the device reports that voxsplat's choices depend on.
    pub fn profile(&self) -> &DeviceProfile {
        &self.profile
    }

    /// Every choice voxsplat makes from the device (`DeviceProfile::choices`).
    pub fn choices(&self) -> &DeviceChoices {
        &self.choices
    }

    /// Largest 2D image / framebuffer side and array layer count the device accepts.
    pub fn image_limits(&self) -> (u32, u32) {
        (self.choices.max_image_side, self.choices.max_layers)
    }

    /// Largest range of one storage-buffer binding (`maxStorageBufferRange`; 2^27 bytes on lavapipe).
    pub fn max_storage_range(&self) -> u64 {
        self.choices.max_storage_range
    }

    /// Widest point sprite the device draws, in pixels (1 without the `largePoints` feature, which
    /// a host says in `HostHandles::large_points`: then points wider than one pixel are refused).
    pub fn point_size_max(&self) -> f32 {
        self.choices.point_size_max
    }

    /// Whether 64-bit buffer atomics are enabled (`HostHandles::int64_atomics`).
    pub fn int64_atomics(&self) -> bool {
        self.choices.int64_atomics
    }

    /// Whether compute shaders have subgroup shuffles and arithmetic in subgroups that hold the tile
    /// compositor's workgroup: it then loads a batch of entries, one per lane, and passes them round
    /// (llvmpipe loads buffers lane by lane), and syncs its lanes with subgroup barriers.
    pub fn subgroup_shuffle(&self) -> bool {
        self.subgroup_shuffle.load(Ordering::Relaxed)
    }

    /// Test hook: renderers created on this context afterwards use the tile compositor's build
    /// without subgroup shuffles, as on a device that lacks them.
    pub(crate) fn disable_subgroup_shuffle(&self) {
        self.subgroup_shuffle.store(false, Ordering::Relaxed);
    }

    /// True for a CPU implementation such as lavapipe.
    pub fn is_cpu_device(&self) -> bool {
        self.choices.cpu
    }

    /// Validation messages seen so far (0 when validation is off).
    pub fn validation_count(&self) -> u64 {
        self.debug_state.count()
    }

    /// The first validation messages seen (up to 64).
    pub fn validation_messages(&self) -> Vec<String> {
        self.debug_state.messages()
    }

    /// gpu-allocator's view of live allocations: (allocation count, bytes).
    pub fn allocation_report(&self) -> (usize, u64) {
        match self.allocator.lock() {
            Ok(a) => {
                let r = a.generate_report();
                (r.allocations.len(), r.total_allocated_bytes)
            }
            Err(_) => (0, 0),
        }
    }

    /// gpu-allocator's live allocations as (name, bytes), sorted: what a leak hunt compares.
    pub fn allocation_details(&self) -> Vec<(String, u64)> {
        let mut v: Vec<(String, u64)> = match self.allocator.lock() {
            Ok(a) => a.generate_report().allocations.iter().map(|r| (r.name.clone(), r.size)).collect(),
            Err(_) => Vec::new(),
        };
        v.sort();
        v
    }

    pub(crate) fn wait_idle(&self) {
        // SAFETY: the device is valid until Drop.
        let _ = unsafe { self.device.device_wait_idle() };
    }

    /// Whether the device has been reported lost.
    pub fn is_lost(&self) -> bool {
        self.lost.load(Ordering::Acquire)
    }

    /// Test-only: the next submission completes on the device but reports `result` (for example
    /// `ERROR_DEVICE_LOST`, which a CPU device cannot be made to produce), so tests can follow the
    /// error path from the queue up to the caller and through Drop.
    pub(crate) fn inject_submit_fault(&self, result: vk::Result) {
        self.injected.store(result.as_raw(), Ordering::Release);
    }

    /// Test-only: makes an invalid call (a zero-sized buffer) so tests can prove the validation
    /// counter is live. Returns whether the call itself failed.
    pub(crate) fn provoke_validation_error(&self) -> bool {
        let info = vk::BufferCreateInfo::default()
            .size(0)
            .usage(vk::BufferUsageFlags::STORAGE_BUFFER)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: deliberately invalid size; the layer reports it. lavapipe still returns a handle,
        // which we destroy at once.
        match unsafe { self.device.create_buffer(&info, None) } {
            Ok(b) => {
                // SAFETY: the buffer is unused.
                unsafe { self.device.destroy_buffer(b, None) };
                false
            }
            Err(_) => true,
        }
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        self.wait_idle();
        // SAFETY: all resources hold an Arc<Context>, so none is alive now; the allocator goes
        // before the device (gpu-allocator's teardown order), then the messenger, then the instance.
        unsafe {
            ManuallyDrop::drop(&mut self.allocator);
            if self.owned {
                self.device.destroy_device(None);
                if let Some(d) = &self.debug {
                    d.loader.destroy_debug_utils_messenger(d.messenger, None);
                }
                self.instance.destroy_instance(None);
            }
        }
    }
}
