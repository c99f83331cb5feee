//! What drawing into a host's image saves (issue 27's target): `render()` (the frame read back to
//! the host as RGBA32F) against `render_to()` (the same frame converted and blitted into a
//! B8G8R8A8_SRGB image on the device, nothing read back). On the peer scene (peer128) and the
//! bonsai at 512², the default options over a black background; median wall time per frame of
//! seven rounds, the variants alternating in one process, and the present stage's own time.
//!
//! `cargo run --release -p voxsplat-lab --example render_to_cost`
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::TransferFunction;
use voxsplat::vk::ImageLayout as IL;
use voxsplat::{image::TargetFormat, scene, Camera, RenderOptions, Renderer, RendererOptions};

fn main() -> voxsplat::Result<()> {
    let mut options = RenderOptions::default();
    options.background = Some([0.0, 0.0, 0.0, 1.0]);
    println!("| scene | render() ms | render_to() ms | render_to / render |\n|---|---:|---:|---:|");
    for name in ["peer128", "bonsai"] {
        let mut r = Renderer::new(&RendererOptions::default())?;
        let cam = if name == "bonsai" {
            let store = BrickStore::load("../shared/data/bonsai/bonsai.nii.gz".as_ref(), &Default::default())?;
            let grid = store.grid()?;
            r.set_bricks(BrickScene::new(store, TransferFunction::preset("bonsai")?, None)?)?;
            Camera::framing(&grid, 512, 512)
        } else {
            let set = scene::build(name)?;
            let cam = voxsplat::scene::peer::camera(set.grid().dims[0], 512);
            r.set_scene(set)?;
            cam
        };
        let image = r.target_image(TargetFormat::Bgra8Srgb, 512, 512)?;
        let target = image.target(IL::UNDEFINED, IL::SHADER_READ_ONLY_OPTIMAL)?;
        let times = voxsplat_lab::bench::alternating_medians(2, 1, 7, |v| {
            let t = std::time::Instant::now();
            if v == 0 {
                r.render(&cam, &options)?;
            } else {
                r.render_to(&cam, &options, &target)?;
            }
            Ok(t.elapsed().as_secs_f64() * 1e3)
        })?;
        let present =
            |t: &[voxsplat::options::StageTime]| t.iter().filter(|s| s.stage == "present").map(|s| s.ms).sum::<f64>();
        let (a, b) = (r.render(&cam, &options)?.timings, r.render_to(&cam, &options, &target)?.timings);
        println!(
            "| {name} | {:.1} | {:.1} | {:.2}× | present stage {:.1} / {:.1} ms |",
            times[0],
            times[1],
            times[1] / times[0],
            present(&a),
            present(&b)
        );
    }
    Ok(())
}
