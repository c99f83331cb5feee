//! Every device-dependent choice, run against recorded device profiles (lavapipe's, and a discrete
//! NVIDIA one from its public limits) so the hardware branch runs in CI too, and the record of
//! lavapipe checked against the device at hand.
use super::common;
use crate::device::{DeviceKind, DeviceProfile, Timing};
use crate::raster::{choose, Device};
use crate::{scene, Camera, Composite, Error, Raster, RenderOptions};

fn profile(name: &str) -> DeviceProfile {
    let path = format!("{}/tests/data/devices/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// The raster `auto` picks for `scene` framed at `size`² with `composite`.
fn auto(p: &DeviceProfile, scene_name: &str, size: u32, composite: Composite) -> crate::Result<Raster> {
    let set = scene::build(scene_name).unwrap();
    let cam = Camera::framing(set.grid(), size, size);
    let mut o = RenderOptions::default();
    o.composite = composite;
    choose(&set, &cam, &o, Device::of(&p.choices())).map(|c| c.raster)
}

#[test]
fn lavapipe_draws_small_footprints_by_compute_and_times_stages_on_the_host() {
    let p = profile("lavapipe");
    let c = p.choices();
    assert_eq!((c.unusable.as_deref(), c.cpu, c.timing), (None, true, Timing::Host));
    assert!(c.subgroup_shuffle && c.int64_atomics && c.graphics_raster, "{:?}", c.fallbacks);
    assert_eq!((c.default_budget, c.max_budget), (1 << 30, u64::MAX), "a CPU device's memory is the host's");
    // cube60 at 128² draws footprints of a few pixels: the tile compositor and the sums.
    assert_eq!(auto(&p, "cube60", 128, Composite::Splat).unwrap(), Raster::Compute);
    assert_eq!(auto(&p, "cube60", 128, Composite::Sheet).unwrap(), Raster::Compute);
    // At 1024² they pass 15 px: point sprites, which lavapipe draws up to its point size.
    assert_eq!(auto(&p, "cube60", 1024, Composite::Splat).unwrap(), Raster::Points);
}

#[test]
fn a_discrete_nvidia_gpu_draws_quads_and_times_stages_by_timestamps() {
    let p = profile("nvidia-h100");
    assert_eq!(p.kind, DeviceKind::Discrete);
    let c = p.choices();
    assert_eq!(c.unusable, None);
    assert!(!c.cpu && c.subgroup_shuffle && c.int64_atomics && c.graphics_raster);
    assert_eq!(c.timing, Timing::Timestamps { period_ns: 1.0, mask: u64::MAX });
    assert!(c.fallbacks.is_empty(), "{:?}", c.fallbacks);
    assert_eq!(c.point_size_max, 2047.9375);
    // Half the 80 GiB heap by default; no more than the heap on request.
    assert_eq!((c.default_budget, c.max_budget), (40 << 30, 80 << 30));
    for size in [128, 1024] {
        for composite in [Composite::Splat, Composite::Sheet, Composite::Slab] {
            assert_eq!(auto(&p, "cube60", size, composite).unwrap(), Raster::Graphics, "{size} {composite:?}");
        }
    }
}

#[test]
fn each_missing_feature_takes_its_fallback() {
    let base = profile("nvidia-h100");
    let with = |f: &dyn Fn(&mut DeviceProfile)| {
        let mut p = base.clone();
        f(&mut p);
        p
    };
    // No timestamps on the queue: the host's clock.
    let p = with(&|p| p.timestamp_valid_bits = 0);
    assert_eq!(p.choices().timing, Timing::Host);
    assert_eq!(p.choices().fallbacks.len(), 1);
    // 36-bit timestamps wrap: differences are taken within the mask.
    let p = with(&|p| (p.timestamp_valid_bits, p.timestamp_period) = (36, 83.333));
    assert_eq!(p.choices().timing, Timing::Timestamps { period_ns: 83.333f32 as f64, mask: (1 << 36) - 1 });
    // Subgroups narrower than the compositor's lanes, or without shuffles: the shared-memory build.
    assert!(!with(&|p| p.subgroup_size = 4).choices().subgroup_shuffle);
    assert!(!with(&|p| p.subgroup_shuffle_arithmetic = false).choices().subgroup_shuffle);
    assert!(with(&|p| p.subgroup_size = 64).choices().subgroup_shuffle);
    // No 64-bit atomics: one channel per atomic in the sheet sums.
    assert!(!with(&|p| p.int64_atomics = false).choices().int64_atomics);
    // No largePoints: sprites of one pixel, and --raster points refused where footprints are wider.
    let p = with(&|p| p.large_points = false);
    assert_eq!(p.choices().point_size_max, 1.0);
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 512, 512);
    let mut o = RenderOptions::default();
    o.raster = Raster::Points;
    assert!(matches!(choose(&set, &cam, &o, Device::of(&p.choices())), Err(Error::InvalidArgument(_))));
    // RGBA32F targets that do not blend: auto draws by compute, an explicit graphics raster is refused.
    let p = with(&|p| p.rgba32f_blend = false);
    assert_eq!(auto(&p, "cube60", 512, Composite::Splat).unwrap(), Raster::Compute);
    assert_eq!(auto(&p, "cube60", 512, Composite::Sheet).unwrap(), Raster::Compute);
    o.raster = Raster::Graphics;
    assert!(matches!(choose(&set, &cam, &o, Device::of(&p.choices())), Err(Error::Unsupported(_))));
    // What voxsplat cannot run on at all.
    assert!(with(&|p| p.api_version = [1, 1, 0]).choices().unusable.unwrap().contains("1.2"));
    assert!(with(&|p| p.shader_output_layer = false).choices().unusable.unwrap().contains("shaderOutputLayer"));
    assert!(with(&|p| p.graphics_compute_queue = false).choices().unusable.is_some());
    // A small GPU keeps the 1 GiB default; a budget never passes the heap.
    let c = with(&|p| p.device_local_bytes = 512 << 20).choices();
    assert_eq!((c.default_budget, c.max_budget), (512 << 20, 512 << 20));
    // The ranking among several devices.
    assert!(base.choices().rank > profile("lavapipe").choices().rank);
}

/// The record of lavapipe stays true: the device at hand, when it is lavapipe, reports the same
/// choices (its heap and point size depend on the machine and the Mesa release, and are not
/// compared), and a renderer on it takes a budget past the heap lavapipe reports (its memory is
/// the host's).
#[test]
fn the_lavapipe_record_matches_the_device_at_hand() {
    let mut r = common::gpu();
    let live = r.context().unwrap().profile().clone();
    if live.kind != DeviceKind::Cpu {
        eprintln!("not lavapipe ({}): the record is not compared", live.name);
        return;
    }
    let rec = profile("lavapipe");
    let (a, b) = (live.choices(), rec.choices());
    assert_eq!(
        (a.cpu, a.timing, a.subgroup_shuffle, a.int64_atomics, a.graphics_raster, a.default_budget),
        (b.cpu, b.timing, b.subgroup_shuffle, b.int64_atomics, b.graphics_raster, b.default_budget)
    );
    assert_eq!(
        (live.subgroup_size, live.large_points, live.max_storage_range),
        (rec.subgroup_size, rec.large_points, rec.max_storage_range)
    );
    assert_eq!(a.max_budget, u64::MAX);
    r.set_gpu_budget(live.device_local_bytes * 2).unwrap();
    common::assert_clean(&r);
}
