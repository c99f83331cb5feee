//! Criterion wall-time benchmark of whole frames, plus per-stage GPU medians from timestamps
//! printed as a table (the figures in docs/RESULTS.md). Bench bodies live in `voxsplat::bench`.
use criterion::{criterion_group, criterion_main, Criterion};
use voxsplat::bench::{default_cases, measure, table};
use voxsplat::{Camera, RenderOptions, Renderer, RendererOptions};

fn frames(c: &mut Criterion) {
    let mut renderer = Renderer::new(&RendererOptions::default()).expect("Vulkan device (run scripts/setup.sh)");
    eprintln!("device: {}", renderer.device_name());
    let mut rows = Vec::new();
    for case in default_cases() {
        rows.push(measure(&mut renderer, &case, 2, 9).expect("measure"));
    }
    eprintln!("\n{}", table(&rows));
    let mut group = c.benchmark_group("frame");
    group.sample_size(10);
    for case in default_cases() {
        let set = voxsplat::scene::build(case.scene).unwrap();
        let camera = Camera::framing(set.grid(), case.width, case.height);
        renderer.set_scene(set).unwrap();
        let mut opts = RenderOptions::default();
        opts.composite = case.composite;
        opts.kernel = case.kernel;
        group.bench_function(case.label(), |b| b.iter(|| renderer.render(&camera, &opts).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
