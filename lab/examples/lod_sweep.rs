//! The levels-of-detail sweep behind docs/log/2026-11-24-levels-of-detail-targets.md: one bricked volume
//! at 512² (the framing view), full detail and each `pixels,error` cut, PSNR against a truth image
//! (e.g. `voxsplat render --volume F --raycast 0.25 --cpu`), then median frame times of three rounds
//! with the variants alternating in one process.
//!
//! `cargo run --release -p voxsplat-lab --example lod_sweep -- FILE TF TRUTH.exr 1,0.1 2,1e30 ...`
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::TransferFunction;
use voxsplat::{
    options::Lod, options::Raster, order::Direction, Camera, Error, RenderOptions, Renderer, RendererOptions,
};

fn main() -> voxsplat::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = || Error::InvalidArgument("usage: lod_sweep FILE TF TRUTH.exr PIXELS,ERROR...".into());
    let [path, tf, truth, cuts @ ..] = args.as_slice() else { return Err(usage()) };
    let mut variants = vec![None];
    for c in cuts {
        let v: Vec<f32> = c.split(',').map(|x| x.parse().map_err(|_| usage())).collect::<voxsplat::Result<_>>()?;
        let [pixels, error] = v[..] else { return Err(usage()) };
        variants.push(Some((pixels, error)));
    }
    let truth = voxsplat::output::read_image(truth.as_ref())?;
    let store = BrickStore::load(path.as_ref(), &Default::default())?;
    let cam = Camera::framing(&store.grid()?, 512, 512);
    let mut r = Renderer::new(&RendererOptions::default())?;
    r.set_bricks(BrickScene::new(store, TransferFunction::preset(tf)?, None)?)?;
    let options = |v: &Option<(f32, f32)>| {
        let mut o = RenderOptions::default();
        (o.raster, o.direction) = (Raster::Compute, Some(Direction::FrontToBack));
        if let Some((pixels, error)) = *v {
            (o.lod, o.lod_pixels, o.lod_error) = (Lod::Auto, pixels, error);
        }
        o
    };
    let mut psnr = Vec::new();
    for v in &variants {
        psnr.push(voxsplat::metrics::compare(&r.render(&cam, &options(v))?.image, &truth)?.psnr);
    }
    let times = voxsplat_lab::bench::alternating_medians(variants.len(), 0, 3, |v| {
        voxsplat_lab::bricked::frame_ms(&mut r, &cam, &options(&variants[v]))
    })?;
    println!("| cut (pixels, error) | PSNR dB | median ms | × full detail |\n|---|---:|---:|---:|");
    for ((v, p), t) in variants.iter().zip(&psnr).zip(&times) {
        let bound = |x: f32| if x >= 1e29 { "off".to_string() } else { x.to_string() };
        let label = v.map_or("full detail".to_string(), |(px, e)| {
            format!("{} px, {}", bound(px), bound(e)).replace("off px", "off")
        });
        println!("| {label} | {p:.2} | {t:.0} | {:.2} |", t / times[0]);
    }
    Ok(())
}
