//! `voxsplat device`: a device's profile and the choices voxsplat makes from it, as text or TOML.
use std::fmt::Write as _;
use voxsplat::device::{DeviceProfile, Timing};
use voxsplat::{Error, Result};

/// The profile as TOML, as `tests/data/devices/` records it.
pub fn device_toml(p: &DeviceProfile) -> Result<String> {
    toml::to_string(p).map_err(|e| Error::InvalidArgument(format!("the device profile as TOML: {e}")))
}

/// What the device reports and what voxsplat does with it, for people.
pub fn describe_device(p: &DeviceProfile) -> String {
    let c = p.choices();
    let mut s = String::new();
    let yes = |b: bool| if b { "yes" } else { "no" };
    let _ = writeln!(s, "device:      {} ({:?}, vendor {:#06x})", p.name, p.kind, p.vendor_id);
    let _ = writeln!(s, "driver:      {}", p.driver);
    let _ = writeln!(s, "vulkan:      {}", p.api());
    let _ = writeln!(s, "memory:      {:.1} GiB device-local", p.device_local_bytes as f64 / (1u64 << 30) as f64);
    if let Some(why) = &c.unusable {
        let _ = writeln!(s, "usable:      no: {why}");
        return s;
    }
    let auto = if c.cpu {
        "compute for small footprints, point sprites or quads for larger ones (a CPU device pays per primitive)"
    } else if c.graphics_raster {
        "graphics quads (a hardware rasteriser)"
    } else {
        "compute (RGBA32F targets do not blend)"
    };
    let _ = writeln!(s, "raster auto: {auto}");
    let timing = match c.timing {
        Timing::Timestamps { period_ns, mask } => {
            format!("GPU timestamps, {period_ns} ns a tick, {} bits", 64 - mask.leading_zeros())
        }
        Timing::Host => "the host's clock around each stage's submission".into(),
    };
    let _ = writeln!(s, "timing:      {timing}");
    let _ = writeln!(
        s,
        "subgroups:   {} lanes; tile compositor {}",
        p.subgroup_size,
        if c.subgroup_shuffle { "with shuffles" } else { "through shared memory" }
    );
    let _ = writeln!(s, "sheet sums:  {}", if c.int64_atomics { "64-bit atomics" } else { "32-bit atomics" });
    let _ = writeln!(s, "points:      up to {} px (largePoints: {})", c.point_size_max, yes(p.large_points));
    let _ = writeln!(
        s,
        "limits:      images {} px a side, {} layers, storage bindings {} MiB",
        c.max_image_side,
        c.max_layers,
        c.max_storage_range >> 20
    );
    let most =
        if c.max_budget == u64::MAX { "the host's memory".to_string() } else { format!("{}", c.max_budget >> 20) };
    let _ =
        writeln!(s, "budget:      {} MiB a frame by default (--gpu-budget-mib up to {most})", c.default_budget >> 20);
    for f in &c.fallbacks {
        let _ = writeln!(s, "fallback:    {f}");
    }
    s
}
