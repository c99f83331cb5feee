//! A device's `DeviceProfile` (crate::device), read from Vulkan: the one place its properties,
//! features, format support and memory heaps are queried.
use crate::device::{DeviceKind, DeviceProfile};
use ash::vk;

/// The first queue family with graphics and compute.
pub(crate) fn queue_family(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Option<u32> {
    // SAFETY: `pd` is a valid handle from `instance`.
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let want = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
    families.iter().position(|f| f.queue_flags.contains(want)).map(|f| f as u32)
}

/// `pd`'s profile with its queue family `family` (for timestamps). `enabled`: the optional
/// features (`largePoints`, 64-bit atomics) as the device was created with them; `None` while
/// devices are still being compared, as supported.
pub(crate) fn read(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    family: Option<u32>,
    enabled: Option<(bool, bool)>,
) -> DeviceProfile {
    // SAFETY: plain queries on a valid physical device; every chain lives on the stack for its call.
    let (props, families, memory) = unsafe {
        (
            instance.get_physical_device_properties(pd),
            instance.get_physical_device_queue_family_properties(pd),
            instance.get_physical_device_memory_properties(pd),
        )
    };
    let v12 = vk::api_version_major(props.api_version) > 1 || vk::api_version_minor(props.api_version) >= 2;
    let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
    if v12 {
        props2 = props2.push_next(&mut driver);
    }
    // SAFETY: as above; the driver properties are chained only on a Vulkan 1.2 device.
    unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default();
    if v12 {
        f2 = f2.push_next(&mut f12);
    }
    // SAFETY: as above.
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    let core = f2.features;
    // SAFETY: as above.
    let rgba32f = unsafe { instance.get_physical_device_format_properties(pd, vk::Format::R32G32B32A32_SFLOAT) }
        .optimal_tiling_features;
    let supported_points = core.large_points == vk::TRUE;
    let supported_int64 = core.shader_int64 == vk::TRUE && f12.shader_buffer_int64_atomics == vk::TRUE;
    let (large_points, int64_atomics) = enabled.unwrap_or((supported_points, supported_int64));
    let text = |s: Option<&std::ffi::CStr>| s.map(|c| c.to_string_lossy().into_owned()).unwrap_or_default();
    let name = text(props.device_name_as_c_str().ok());
    let driver = if v12 {
        let (n, i) = (text(driver.driver_name_as_c_str().ok()), text(driver.driver_info_as_c_str().ok()));
        if i.is_empty() {
            n
        } else {
            format!("{n} {i}")
        }
    } else {
        format!("driver version {:#x}", props.driver_version)
    };
    let l = props.limits;
    let ops = vk::SubgroupFeatureFlags::SHUFFLE | vk::SubgroupFeatureFlags::ARITHMETIC;
    let heaps = &memory.memory_heaps[..memory.memory_heap_count.min(vk::MAX_MEMORY_HEAPS as u32) as usize];
    let device_local =
        heaps.iter().filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL)).map(|h| h.size).max().unwrap_or(0);
    DeviceProfile {
        name,
        kind: match props.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => DeviceKind::Discrete,
            vk::PhysicalDeviceType::INTEGRATED_GPU => DeviceKind::Integrated,
            vk::PhysicalDeviceType::VIRTUAL_GPU => DeviceKind::Virtual,
            vk::PhysicalDeviceType::CPU => DeviceKind::Cpu,
            _ => DeviceKind::Other,
        },
        vendor_id: props.vendor_id,
        api_version: [
            vk::api_version_major(props.api_version),
            vk::api_version_minor(props.api_version),
            vk::api_version_patch(props.api_version),
        ],
        driver,
        shader_output_layer: f12.shader_output_layer == vk::TRUE,
        graphics_compute_queue: family.is_some(),
        large_points,
        point_size_range: l.point_size_range,
        int64_atomics,
        timestamp_period: l.timestamp_period,
        timestamp_valid_bits: family.and_then(|f| families.get(f as usize)).map_or(0, |f| f.timestamp_valid_bits),
        subgroup_size: subgroup.subgroup_size,
        subgroup_shuffle_arithmetic: subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE)
            && subgroup.supported_operations.contains(ops),
        max_image_side: l.max_image_dimension2_d.min(l.max_framebuffer_width).min(l.max_framebuffer_height),
        max_layers: l.max_image_array_layers.min(l.max_framebuffer_layers),
        max_storage_range: l.max_storage_buffer_range as u64,
        rgba32f_blend: rgba32f.contains(vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND),
        device_local_bytes: device_local,
    }
}
