use voxsplat::*;
fn main() {
    for name in ["cube60", "plane", "cube40-attenuated"] {
        let set = scene::build(name).unwrap();
        let cam = Camera::framing(set.grid(), 128, 128);
        let t0 = std::time::Instant::now();
        let truth = truth::volumetric_summation(&set, &cam, &truth::TruthOptions::default()).unwrap();
        let tt = t0.elapsed().as_secs_f64();
        let mut r = Renderer::new(&RendererOptions::default()).unwrap();
        r.set_scene(set.clone()).unwrap();
        for comp in [Composite::Splat, Composite::Sheet] {
            let mut o = RenderOptions::default();
            o.composite = comp;
            let img = r.render(&cam, &o).unwrap().image;
            let m = metrics::compare(&img, &truth).unwrap();
            println!(
                "{name} {comp:?}: psnr {:.2} ssim {:.4} max {:.3} (truth {tt:.2}s)",
                m.psnr, m.ssim_luma, m.max_abs
            );
        }
        output::write_image(&truth, format!("out/truth-{name}.png").as_ref()).unwrap();
    }
}
