//! Criterion wall-time benchmark of whole frames for the methods of the quick matrix; the full
//! matrix with errors, roofline and scaling is `voxsplat-lab matrix` (bodies in `voxsplat::bench`).
use criterion::{criterion_group, criterion_main, Criterion};
use voxsplat::{Renderer, RendererOptions};
use voxsplat_lab::bench::{bench_camera, time_method, MatrixOptions};

fn frames(c: &mut Criterion) {
    let mut renderer = Renderer::new(&RendererOptions::default()).expect("Vulkan device (run scripts/setup.sh)");
    let m = MatrixOptions::quick();
    let mut group = c.benchmark_group("frame");
    group.sample_size(10);
    for name in ["cube60", "plane"] {
        let set = voxsplat::scene::build(name).unwrap();
        let camera = bench_camera(set.grid(), 512, 512);
        renderer.set_scene(set).unwrap();
        for method in &m.methods {
            group.bench_function(format!("{name} {}", method.label()), |b| {
                b.iter(|| time_method(&mut renderer, method, &camera, 0, 1).unwrap())
            });
        }
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
