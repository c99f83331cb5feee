//! Chapter 3's anti-aliasing on the seed's other figures: the terrain seen in
//! perspective (Figs 3.7 and 5.3: the rmnp fly-over) and a dense volume seen orthographically at
//! more than one voxel per pixel (Fig. 3.8: stripes128, every splat beyond k), measured as the
//! grazing plane of Fig. 3.6 is: error against a supersampled truth brought down by a Lanczos-3
//! low-pass, aliasing energy, shimmer along a slow camera move, and time, for none, Swan and EWA.
use crate::bricked::frame_ms;
use std::fmt::Write as _;
use voxsplat::image::Downsample;
use voxsplat::truth::{supersampled_with, TruthOptions};
use voxsplat::{camera::Projection, image::ImageF32, options::Antialias, Camera, Renderer, RendererOptions, Result};

/// One mode on one figure's view.
pub struct AaSceneRow {
    pub figure: &'static str,
    /// Image width and height.
    pub size: (u32, u32),
    pub mode: Antialias,
    pub psnr: f64,
    pub aliasing: f64,
    pub shimmer: f64,
    pub median_ms: f64,
    /// Fraction of splats beyond k (`Camera::k` against their eye distance).
    pub beyond_k: f64,
}

/// The seed's image sizes: Fig. 3.7 (and 5.3) 260 x 179, Fig. 3.8 290 x 290.
pub const SEED_SIZES: [(u32, u32); 2] = [(260, 179), (290, 290)];

/// The figures' scenes and views at the seed's sizes or `size`² (the camera moves half a voxel per
/// frame for the shimmer: forward along the view in perspective, sideways in the orthographic view).
fn views(size: Option<u32>) -> Result<Vec<(&'static str, voxsplat::SplatSet, Camera, glam::Vec3)>> {
    let [(w0, h0), (w1, h1)] = size.map_or(SEED_SIZES, |s| [(s, s); 2]);
    let rmnp = voxsplat::scene::build("rmnp")?;
    let fly = Camera::flyover(rmnp.grid(), w0, h0);
    let fly_step = fly.forward() * 0.5 * rmnp.grid().kernel_spacing();
    let stripes = voxsplat::scene::build("stripes128")?;
    let g = stripes.grid();
    // 1.5 voxels per pixel: every splat beyond k, as in Fig. 3.8.
    let height = 1.5 * h1 as f32 * g.kernel_spacing();
    let ortho = Camera { projection: Projection::Orthographic { height }, ..Camera::framing(g, w1, h1) };
    let side = ortho.right() * 0.5 * g.kernel_spacing();
    Ok(vec![
        ("Figs 3.7, 5.3: rmnp fly-over", rmnp, fly, fly_step),
        ("Fig. 3.8: stripes128 orthographic", stripes, ortho, side),
    ])
}

/// Every mode on every view: `frames` timed renders each (median), a `dolly`-frame move for the
/// shimmer, against a `factor`× supersampled truth.
pub fn study(size: Option<u32>, factor: u32, dolly: usize, frames: usize) -> Result<Vec<AaSceneRow>> {
    let mut r = Renderer::new(&RendererOptions::default())?;
    let mut rows = Vec::new();
    for (figure, set, camera, step) in views(size)? {
        let truth = supersampled_with(&set, &camera, factor, Downsample::Lanczos3, &TruthOptions::default())?;
        let k = camera.k(set.grid().kernel_spacing());
        let beyond_k = k.map_or(1.0, |k| {
            let g = set.grid();
            let far =
                set.splats().iter().filter(|s| g.position([s.ijk[0], s.ijk[1], s.ijk[2]]).distance(camera.eye) > k);
            far.count() as f64 / set.len().max(1) as f64
        });
        r.set_scene(set)?;
        let modes = [Antialias::None, Antialias::Swan, Antialias::Ewa];
        let options = |mode| {
            let mut o = crate::lab_options();
            o.antialias = mode;
            o
        };
        // The modes alternate frame by frame (after a warm-up frame each).
        let medians = crate::bench::alternating_medians(modes.len(), 1, frames, |m| {
            frame_ms(&mut r, &camera, &options(modes[m]))
        })?;
        for (mode, median_ms) in modes.into_iter().zip(medians) {
            let o = options(mode);
            let image = r.render(&camera, &o)?.image;
            let moved: Vec<ImageF32> = (0..dolly)
                .map(|f| {
                    let c =
                        Camera { eye: camera.eye + step * f as f32, target: camera.target + step * f as f32, ..camera };
                    r.render(&c, &o).map(|x| x.image)
                })
                .collect::<Result<_>>()?;
            rows.push(AaSceneRow {
                figure,
                size: (camera.width, camera.height),
                mode,
                psnr: voxsplat::metrics::compare(&image, &truth)?.covered_psnr,
                aliasing: voxsplat::metrics::aliasing_energy(&image, &truth, |_| true).unwrap_or(f64::NAN),
                shimmer: voxsplat::metrics::shimmer(&moved, |_, _| true).unwrap_or(f64::NAN),
                median_ms,
                beyond_k,
            });
        }
    }
    Ok(rows)
}

/// The study's markdown section.
pub fn markdown(rows: &[AaSceneRow], factor: u32, dolly: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Anti-aliasing on the terrain and orthographic figures (Figs 3.7, 3.8, 5.3)\n\n`voxsplat-lab antialias`: \
         per-splat PBTF, Gaussian; error against the truth supersampled {factor}×{factor} and brought down by a \
         Lanczos-3 low-pass; aliasing energy over the frame (`metrics::aliasing_energy`); shimmer = mean frame-to-frame \
         RMSE along a {dolly}-frame move of half a voxel per frame (forward in the fly-over, sideways in the orthographic \
         view); median of the timed frames, the modes alternating frame by frame. PSNR over the covered pixels.\n\n| figure | image | splats beyond k | mode | PSNR dB | \
         aliasing energy | shimmer | median ms |\n|---|---|---:|---|---:|---:|---:|---:|"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {}×{} | {:.0} % | {} | {:.2} | {:.4} | {:.5} | {:.1} |",
            r.figure,
            r.size.0,
            r.size.1,
            r.beyond_k * 100.0,
            format!("{:?}", r.mode).to_lowercase(),
            r.psnr,
            r.aliasing,
            r.shimmer,
            r.median_ms
        );
    }
    s
}
