//! The bisect switch: a frame whose stages up to a named one run on the device and the rest on the
//! CPU mirrors (or the reverse), everything the first engine wrote handed to the second. Where the
//! stages before the switch give both engines the same words, the split frame is the other
//! backend's frame bit for bit; elsewhere it lies within the mirror tolerance.
use super::common;
use crate::output::diff_rgba8;
use crate::stages::StageId;
use crate::{scene, Bisect, Camera, Composite, Error, ImageF32, Lod, Raster, RenderOptions, Renderer};
use common::assert_clean;

fn options(composite: Composite, raster: Raster) -> RenderOptions {
    let mut o = RenderOptions::default();
    o.composite = composite;
    o.raster = raster;
    // Small batches: several of them.
    o.sheet_budget_bytes = 160 * 128 * 16 * 5;
    o
}

/// (split frame, all-GPU frame, all-CPU frame).
fn frames(gpu: &mut Renderer, cpu: &mut Renderer, cam: &Camera, o: &RenderOptions, split: Bisect) -> [ImageF32; 3] {
    gpu.set_bisect(Some(split)).unwrap();
    let s = gpu.render(cam, o).unwrap().image;
    gpu.set_bisect(None).unwrap();
    let g = gpu.render(cam, o).unwrap().image;
    let c = cpu.render(cam, o).unwrap().image;
    assert!(s.pixels.iter().filter(|p| p[3] > 0.5).count() > 1000, "{split:?}: something drawn");
    [s, g, c]
}

fn identical(a: &ImageF32, b: &ImageF32) -> bool {
    a.pixels.iter().zip(&b.pixels).all(|(p, q)| p.map(f32::to_bits) == q.map(f32::to_bits))
}

fn renderers(name: &str) -> (Renderer, Renderer, Camera) {
    let set = scene::build(name).unwrap();
    let cam = Camera::framing(set.grid(), 160, 128);
    let (mut gpu, mut cpu) = (common::gpu(), common::cpu());
    gpu.set_scene(set.clone()).unwrap();
    cpu.set_scene(set).unwrap();
    (gpu, cpu, cam)
}

#[test]
fn the_order_stages_hand_over_bit_for_bit() {
    // The GPU and CPU PBTF orders are the same sequence (tests/gpu.rs): switching right after
    // them gives exactly the other engine's frame.
    let (mut gpu, mut cpu, cam) = renderers("cube40-attenuated");
    let o = options(Composite::Splat, Raster::Graphics);
    let [s, _, c] = frames(&mut gpu, &mut cpu, &cam, &o, Bisect::GpuUntil(StageId::SplatParams));
    assert!(identical(&s, &c), "GPU order + CPU mirrors = the CPU frame");
    let [s, g, _] = frames(&mut gpu, &mut cpu, &cam, &o, Bisect::CpuUntil(StageId::SplatParams));
    assert!(identical(&s, &g), "CPU order + GPU stages = the GPU frame");
    assert_clean(&gpu);
}

#[test]
fn every_mode_splits_at_its_raster_stage_within_the_mirror_tolerance() {
    let (mut gpu, mut cpu, cam) = renderers("cube40-attenuated");
    let cases = [
        (Composite::Splat, Raster::Compute, StageId::TileComposite),
        (Composite::Splat, Raster::Compute, StageId::TileCount),
        (Composite::Sheet, Raster::Graphics, StageId::Footprint),
        (Composite::Slab, Raster::Points, StageId::SheetTiles),
        (Composite::Sheet, Raster::Compute, StageId::Composite),
    ];
    for (composite, raster, at) in cases {
        let o = options(composite, raster);
        for split in [Bisect::GpuUntil(at), Bisect::CpuUntil(at)] {
            let [s, g, c] = frames(&mut gpu, &mut cpu, &cam, &o, split);
            // The split frame's stages after the switch ran on one engine: it is that engine's frame
            // but for the words handed over, which the mirrors match within their tolerance.
            let after = if matches!(split, Bisect::GpuUntil(_)) { &c } else { &g };
            let (mean, max) = diff_rgba8(&s, after).unwrap();
            eprintln!("{composite:?} {raster:?} {split:?}: mean |diff| {mean:.4}/255, max {max}/255");
            assert!(mean <= 1.0, "{composite:?} {raster:?} {split:?}: mean {mean}");
            common::assert_mirrors(&g, &c, &format!("{composite:?} {raster:?}: the backends"));
        }
    }
    assert_clean(&gpu);
}

#[test]
fn a_switch_that_would_move_the_summation_layers_is_refused() {
    let (mut gpu, _, cam) = renderers("cube40");
    let o = options(Composite::Sheet, Raster::Graphics);
    gpu.set_bisect(Some(Bisect::GpuUntil(StageId::Composite))).unwrap();
    match gpu.render(&cam, &o) {
        Err(Error::Unsupported(m)) => assert!(m.contains("composite") && m.contains("Sums"), "{m}"),
        other => panic!("expected a typed refusal, got {:?}", other.map(|r| r.timings)),
    }
    assert_clean(&gpu);
}

#[test]
fn bisect_names_are_parsed_and_checked() {
    let b: Bisect = "gpu-until:tile_composite".parse().unwrap();
    assert_eq!(b, Bisect::GpuUntil(StageId::TileComposite));
    let b: Bisect = "cpu-until:order_scan".parse().unwrap();
    assert_eq!(b, Bisect::CpuUntil(StageId::OrderScan));
    let err = "gpu-until:nope".parse::<Bisect>().unwrap_err().to_string();
    assert!(err.contains("unknown stage 'nope'") && err.contains("splat_params"), "{err}");
    assert!("sideways:order_scan".parse::<Bisect>().is_err());
    let mut cpu = common::cpu();
    assert!(cpu.set_bisect(Some(b)).is_err(), "the CPU backend has no device to split with");
}

/// A bricked volume splits at every brick stage both ways (the device's buffers, grown by powers
/// of two, handed to the mirrors and back): right after `brick_cull` or `brick_order` the rest is
/// the other backend's frame bit for bit; the split frames stay within the mirror tolerance.
#[test]
fn bricked_volumes_split_at_the_brick_stages() {
    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/stent/stent.nrrd");
    let vol = crate::loaders::load_volume(stent.as_ref(), &Default::default()).unwrap();
    let tf = crate::classify::TransferFunction::preset("ct").unwrap();
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 96);
    let (mut gpu, mut cpu) = (common::gpu(), common::cpu());
    gpu.set_volume(&vol, &tf, None).unwrap();
    cpu.set_volume(&vol, &tf, None).unwrap();
    // Full detail, then levels of detail (the default: the pyramid, built in floating point by
    // the engine that runs first, makes the later stages' inputs differ in the last bits).
    for (lod, stage) in [Lod::Off, Lod::Auto].into_iter().flat_map(|l| {
        [StageId::BrickCull, StageId::BrickOrder, StageId::BrickQuads, StageId::TileCount].map(|s| (l, s))
    }) {
        let mut o = RenderOptions::default();
        (o.raster, o.lod) = (Raster::Compute, lod);
        for split in [Bisect::GpuUntil(stage), Bisect::CpuUntil(stage)] {
            gpu.set_bisect(Some(split)).unwrap();
            let s = gpu.render(&cam, &o).unwrap().image;
            gpu.set_bisect(None).unwrap();
            let g = gpu.render(&cam, &o).unwrap().image;
            let c = cpu.render(&cam, &o).unwrap().image;
            assert!(s.pixels.iter().any(|p| p[3] > 0.1), "{split:?}: something drawn");
            let most = |a: &ImageF32, b: &ImageF32| {
                a.pixels
                    .iter()
                    .zip(&b.pixels)
                    .flat_map(|(p, q)| (0..4).map(move |i| (p[i] - q[i]).abs()))
                    .fold(0.0, f32::max)
            };
            assert!(most(&s, &g) <= 2e-3 && most(&s, &c) <= 2e-3, "{split:?}: {} / {}", most(&s, &g), most(&s, &c));
            // The stages before brick_quads compute integers alike: the rest is one backend's.
            if lod == Lod::Off && matches!(stage, StageId::BrickCull | StageId::BrickOrder) {
                let rest = if matches!(split, Bisect::GpuUntil(_)) { &c } else { &g };
                assert!(identical(&s, rest), "{split:?}: the other backend's frame bit for bit");
            }
        }
    }
    assert_clean(&gpu);
}
