//! Where blurred splats differ from the accumulation buffer (issue 26 item 5): frame 20 of the
//! rotating box and of the orthographic terrain, WBTF through graphics quads, each method against
//! 64 sub-frames, its squared error split by the truth's alpha (background below 0.01, edges,
//! inside above 0.99), and the mean alpha difference (coverage).
//! `cargo run --release -p voxsplat-lab --example blur_where`
use voxsplat::animate::{render_frame, Animation, Blur};
use voxsplat::{options::Raster, order::OrderKind, RenderOptions, Renderer, RendererOptions};
fn main() -> voxsplat::Result<()> {
    let mut r = Renderer::new(&RendererOptions::default())?;
    for name in ["rotating-box", "rotating-terrain-ortho"] {
        let anim = Animation::builtin(name)?;
        let set = voxsplat::scene::build(&anim.scene)?;
        let grid = *set.grid();
        r.set_scene(set)?;
        let mut o = RenderOptions::default();
        o.order = OrderKind::Wbtf;
        o.raster = Raster::Graphics;
        let truth = render_frame(&mut r, &anim, &grid, 20, Blur::Accum(64), &o)?;
        for b in ["splat", "splat:tapered", "accum:5"] {
            let img = render_frame(&mut r, &anim, &grid, 20, b.parse()?, &o)?;
            let mut bins = [(0.0f64, 0usize); 3];
            for (p, q) in img.pixels.iter().zip(&truth.pixels) {
                let k = if q[3] < 0.01 {
                    0
                } else if q[3] < 0.99 {
                    1
                } else {
                    2
                };
                let se: f64 = (0..4).map(|c| ((p[c] - q[c]) as f64).powi(2)).sum::<f64>() / 4.0;
                bins[k].0 += se;
                bins[k].1 += 1;
            }
            let n = img.pixels.len() as f64;
            print!("{name} {b}:");
            for (k, (se, c)) in bins.iter().enumerate() {
                print!(
                    " [{}] px {c} share of SE {:.2} rmse {:.4};",
                    ["bg", "edge", "inside"][k],
                    se / bins.iter().map(|b| b.0).sum::<f64>(),
                    (se / *c.max(&1) as f64).sqrt()
                );
            }
            let alpha_err: f64 =
                img.pixels.iter().zip(&truth.pixels).map(|(p, q)| (p[3] - q[3]) as f64).sum::<f64>() / n;
            println!(" mean alpha diff {alpha_err:.4}");
        }
    }
    Ok(())
}
