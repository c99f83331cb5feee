//! Anti-aliasing on the grazing checkerboard view (chapter 3): each mode against the supersampled
//! truth, beyond the k line.
use super::*;

/// One anti-aliasing mode on the grazing checkerboard view (chapter 3).
#[derive(Clone, Debug)]
pub struct AaRow {
    /// The method's label (`Method::label`).
    pub method: String,
    /// The anti-aliasing mode of a splat method; `None` for the bricked levels of detail.
    pub mode: Option<Antialias>,
    pub time_ms: f64,
    pub rmse_before: f64,
    pub rmse_beyond: f64,
    pub pixels_beyond: usize,
    /// Mean frame-to-frame RMSE over the beyond-k pixels along the dolly (see docs/MODEL.md).
    pub shimmer: f64,
    /// Aliasing energy beyond k (`metrics::aliasing_energy`).
    pub aliasing: f64,
    pub metrics: ImageMetrics,
}

/// The levels-of-detail curve's error bounds in the anti-aliasing study.
pub(crate) const AA_LOD_ERRORS: [f32; 3] = [0.03, 0.3, 1.0];
/// The pixel bounds swept (error test off) in the anti-aliasing study.
pub(crate) const AA_LOD_PIXELS: [f32; 3] = [2.0, 4.0, 8.0];

/// The plane at the grazing view: error against a `factor`× supersampled truth before and beyond
/// k, shimmer along a `dolly` frame camera dolly, and time, for every anti-aliasing mode.
pub fn antialias_study(
    r: &mut Renderer,
    size: u32,
    factor: u32,
    dolly: usize,
    frames: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<AaRow>> {
    let set = scene::build("plane")?;
    let camera = Camera::grazing(set.grid(), size, size);
    progress("anti-aliasing: supersampled truth");
    let lanczos = voxsplat::image::Downsample::Lanczos3;
    let truth = voxsplat::truth::supersampled_with(&set, &camera, factor, lanczos, &TruthOptions::default())?;
    let regions = voxsplat::aa::k_regions(&set, &camera);
    r.set_scene(set.clone())?;
    let (order, composite, kernel, raster) = (OrderKind::Pbtf, Composite::Splat, Kernel::Gaussian, Raster::Graphics);
    let mut methods: Vec<Method> = [Antialias::None, Antialias::Swan, Antialias::Ewa]
        .into_iter()
        .map(|aa| Method::Splat { order, composite, kernel, aa, raster })
        .collect();
    // Levels of detail: the prefiltered cells (issue 24), from the plane as bricks.
    methods.extend(bricked_methods(&AA_LOD_ERRORS));
    // Coarser than a pixel: the isotropic cells trade shimmer for blur along the unforeshortened axis.
    methods.extend(AA_LOD_PIXELS.iter().map(|&px| Method::Bricked { lod: Some((px, LOD_ANY_ERROR)) }));
    let mut rows = Vec::new();
    let mut bricked = false;
    for m in methods {
        progress(&format!("anti-aliasing: {}", m.label()));
        hold_scene_for(r, &set, &m, &mut bricked)?;
        let t = time_method(r, &m, &camera, 1, frames)?;
        let before = voxsplat::metrics::rmse_masked(&t.image, &truth, |i| regions[i] == 1).unwrap_or(f64::NAN);
        let beyond = voxsplat::metrics::rmse_masked(&t.image, &truth, |i| regions[i] == 2).unwrap_or(f64::NAN);
        // Dolly: the camera moves forward half a voxel per frame, parallel to the sheet.
        let step = glam::Vec3::new(0.0, 0.5 * set.grid().spacing[1], 0.0);
        let mut frames_img = Vec::with_capacity(dolly);
        let mut regions_f = Vec::with_capacity(dolly);
        for f in 0..dolly {
            let cam = Camera { eye: camera.eye + step * f as f32, target: camera.target + step * f as f32, ..camera };
            frames_img.push(render_method(r, &m, &cam)?.image);
            regions_f.push(voxsplat::aa::k_regions(&set, &cam));
        }
        let shimmer = voxsplat::metrics::shimmer(&frames_img, |t, i| regions_f[t][i] == 2).unwrap_or(f64::NAN);
        let aliasing = voxsplat::metrics::aliasing_energy(&t.image, &truth, |i| regions[i] == 2).unwrap_or(f64::NAN);
        rows.push(AaRow {
            method: m.label(),
            mode: m.antialias(),
            time_ms: t.time_ms,
            rmse_before: before,
            rmse_beyond: beyond,
            pixels_beyond: regions.iter().filter(|&&x| x == 2).count(),
            shimmer,
            aliasing,
            metrics: compare(&t.image, &truth)?,
        });
    }
    Ok(rows)
}

/// Chart rows for the anti-aliasing modes (scene "plane-grazing").
pub fn antialias_rows(rows: &[AaRow], size: u32) -> Vec<Row> {
    rows.iter()
        .map(|r| Row {
            scene: "plane-grazing".into(),
            method: r.method.clone(),
            width: size,
            height: size,
            splats: 498 * 398,
            time_ms: r.time_ms,
            wall_ms: r.time_ms,
            stages: Vec::new(),
            metrics: r.metrics,
            violations: None,
        })
        .collect()
}

/// The anti-aliasing section of RESULTS.md, with the chapter-3 targets.
pub fn antialias_markdown(rows: &[AaRow], size: u32, factor: u32, dolly: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Anti-aliasing (chapter 3)\n\nThe checkerboard plane, grazing view (`--view grazing`), {size}², PBTF per-splat, Gaussian; \
         error against the truth supersampled {factor}×{factor} and brought down by a Lanczos-3 low-pass at the pixels' \
         Nyquist frequency; aliasing energy beyond k = the render's luma power in excess of the reference's, summed over \
         frequencies, over the reference's (`metrics::aliasing_energy`); shimmer = mean frame-to-frame RMSE over the \
         beyond-k pixels along a {dolly}-frame dolly (half a voxel per frame). The bricked rows draw the plane as a \
         palette volume through the tile compositor; `lod Npx` = levels of detail with cells up to N pixels and no \
         error bound, `lod error E` = the error bound E with no pixel bound.\n"
    );
    let _ = writeln!(
        s,
        "| method | ms | PSNR before k | PSNR beyond k | aliasing energy beyond k | beyond-k pixels | shimmer | whole-frame PSNR |\n|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {:.2} | {:.4} | {} | {:.5} | {:.2} |",
            r.method,
            r.time_ms,
            voxsplat::metrics::psnr(r.rmse_before),
            voxsplat::metrics::psnr(r.rmse_beyond),
            r.aliasing,
            r.pixels_beyond,
            r.shimmer,
            r.metrics.psnr
        );
    }
    let find = |m: Antialias| rows.iter().find(|r| r.mode == Some(m));
    if let Some(none) = find(Antialias::None) {
        for m in [Antialias::Swan, Antialias::Ewa] {
            let Some(x) = find(m) else { continue };
            let db = voxsplat::metrics::psnr(x.rmse_beyond) - voxsplat::metrics::psnr(none.rmse_beyond);
            let sh = x.shimmer / none.shimmer;
            let tr = x.time_ms / none.time_ms;
            let met = db >= 6.0 && sh <= 0.5 && tr < 1.5;
            let _ = writeln!(
                s,
                "\n- **{m:?} vs none beyond k:** {db:+.2} dB, shimmer × {sh:.2}, time × {tr:.2} (target: ≥ +6 dB, ≤ × 0.5, < × 1.5{}): {}.",
                if m == Antialias::Ewa { ", applied to Swan; EWA measured beside it" } else { "" },
                if met { "met" } else { "missed" }
            );
        }
        for x in rows.iter().filter(|r| r.mode.is_none() && r.method.contains("lod")) {
            let db = voxsplat::metrics::psnr(x.rmse_beyond) - voxsplat::metrics::psnr(none.rmse_beyond);
            let sh = x.shimmer / none.shimmer;
            let met = db >= 3.0 && sh <= 0.5;
            let _ = writeln!(
                s,
                "- **{} vs none beyond k:** {db:+.2} dB, shimmer × {sh:.2}, aliasing energy × {:.2}, time × {:.2} (the \
                 target: ≥ +3 dB, ≤ × 0.5): {}.",
                x.method,
                x.aliasing / none.aliasing,
                x.time_ms / none.time_ms,
                if met { "met" } else { "missed" }
            );
        }
    }
    s
}
