//! Criterion wall-time benchmark of whole frames through the library's public API, one per raster
//! variant and compositing mode on the 60³ cube. The full matrix with errors, roofline and scaling
//! is `voxsplat-lab matrix` (cli/src/bench.rs), and cli/benches/render.rs times its quick matrix.
use criterion::{criterion_group, criterion_main, Criterion};
use voxsplat::{options::Composite, options::Raster, scene, Camera, RenderOptions, Renderer, RendererOptions};

fn frames(c: &mut Criterion) {
    let mut renderer = Renderer::new(&RendererOptions::default()).expect("Vulkan device (run scripts/setup.sh)");
    let set = scene::build("cube60").unwrap();
    let camera = Camera::framing(set.grid(), 256, 256);
    renderer.set_scene(set).unwrap();
    let mut group = c.benchmark_group("frame");
    group.sample_size(10);
    for (composite, raster) in [
        (Composite::Splat, Raster::Graphics),
        (Composite::Splat, Raster::Points),
        (Composite::Splat, Raster::Compute),
        (Composite::Sheet, Raster::Graphics),
        (Composite::Sheet, Raster::Compute),
    ] {
        let mut o = RenderOptions::default();
        o.composite = composite;
        o.raster = raster;
        group.bench_function(format!("cube60 256 {composite:?} {raster:?}"), |b| {
            b.iter(|| renderer.render(&camera, &o).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
