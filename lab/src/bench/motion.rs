//! Motion blur on the rotating box (chapter 4): each method against many sub-frames accumulated.
use super::*;

/// One motion-blur method on the rotating box (chapter 4).
#[derive(Clone, Debug)]
pub struct MotionRow {
    pub method: String,
    pub time_ms: f64,
    pub metrics: ImageMetrics,
    /// RMSE over the silhouette (truth alpha in (0.05, 0.95)) and over the interior (alpha ≥ 0.95).
    pub rmse_edge: f64,
    pub rmse_interior: f64,
    pub image: ImageF32,
}

/// The rotating box at one frame: still, blurred splats (per-splat and sheet), and 5-sub-frame
/// accumulation, timed (median of `frames`) and scored against 64-sub-frame accumulation.
pub fn motion_study(r: &mut Renderer, size: u32, frame: u32, frames: usize) -> Result<Vec<MotionRow>> {
    use voxsplat::animate::{render_frame_timed, Animation, Blur};
    let mut anim = Animation::builtin("rotating-box")?;
    anim.camera.width = size;
    anim.camera.height = size;
    let set = scene::build(&anim.scene)?;
    let grid = *set.grid();
    r.set_scene(set)?;
    let splat = crate::lab_options();
    let sheet = {
        let mut o = crate::lab_options();
        o.composite = Composite::Sheet;
        o
    };
    let truth = render_frame_timed(r, &anim, &grid, frame, Blur::Accum(64), &splat)?.0;
    let mut rows = Vec::new();
    for (name, blur, o) in [
        ("still", Blur::None, &splat),
        ("blurred splats", Blur::Splat(Default::default()), &splat),
        ("blurred splats sheet", Blur::Splat(Default::default()), &sheet),
        ("accum:5", Blur::Accum(5), &splat),
    ] {
        let _ = render_frame_timed(r, &anim, &grid, frame, blur, o)?;
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..frames.max(1) {
            let (img, ms) = render_frame_timed(r, &anim, &grid, frame, blur, o)?;
            times.push(ms);
            last = Some(img);
        }
        let img = last.expect("one frame");
        let alpha = |i: usize| truth.pixels[i][3];
        let rmse_edge = voxsplat::metrics::rmse_masked(&img, &truth, |i| alpha(i) > 0.05 && alpha(i) < 0.95);
        let rmse_interior = voxsplat::metrics::rmse_masked(&img, &truth, |i| alpha(i) >= 0.95);
        rows.push(MotionRow {
            method: name.into(),
            time_ms: median(&mut times),
            metrics: compare(&img, &truth)?,
            rmse_edge: rmse_edge.unwrap_or(f64::NAN),
            rmse_interior: rmse_interior.unwrap_or(f64::NAN),
            image: img,
        });
    }
    rows.push(MotionRow {
        method: "accum:64 (truth)".into(),
        time_ms: f64::NAN,
        metrics: compare(&truth, &truth)?,
        rmse_edge: 0.0,
        rmse_interior: 0.0,
        image: truth,
    });
    Ok(rows)
}

/// Chart rows for the motion study (scene "rotating-box").
pub fn motion_rows(rows: &[MotionRow], size: u32) -> Vec<Row> {
    rows.iter()
        .filter(|m| m.time_ms.is_finite())
        .map(|m| Row {
            scene: "rotating-box".into(),
            method: m.method.clone(),
            width: size,
            height: size,
            splats: 60 * 60 * 60 - 58 * 58 * 58,
            time_ms: m.time_ms,
            wall_ms: m.time_ms,
            stages: Vec::new(),
            metrics: m.metrics,
            violations: None,
        })
        .collect()
}

/// Write each method's frame and, for the blurred splats, the error against the truth (×4) as
/// `motion-*.png` in `dir`; returns (label, file name) pairs.
pub fn write_motion_images(rows: &[MotionRow], dir: &Path) -> Result<Vec<(String, String)>> {
    let mut out = Vec::new();
    let truth = rows.iter().find(|r| r.method.starts_with("accum:64")).map(|r| &r.image);
    for r in rows {
        let name = format!(
            "motion-{}.png",
            r.method.split([' ', '(', ')', ':']).filter(|s| !s.is_empty()).collect::<Vec<_>>().join("-")
        );
        voxsplat::output::write_image(&r.image, &dir.join(&name))?;
        out.push((r.method.clone(), name));
    }
    if let (Some(t), Some(b)) = (truth, rows.iter().find(|r| r.method == "blurred splats")) {
        let mut err = t.clone();
        for (e, (p, q)) in err.pixels.iter_mut().zip(b.image.pixels.iter().zip(&t.pixels)) {
            let d = (0..4).map(|c| (p[c] - q[c]).abs()).fold(0.0f32, f32::max);
            *e = [(4.0 * d).min(1.0), (4.0 * d).min(1.0) * 0.5, 0.0, 1.0];
        }
        voxsplat::output::write_image(&err, &dir.join("motion-error-blurred-splats.png"))?;
        out.push(("error of blurred splats ×4".into(), "motion-error-blurred-splats.png".into()));
    }
    Ok(out)
}

/// The motion-blur section of RESULTS.md with the chapter-4 targets.
pub fn motion_markdown(
    rows: &[MotionRow],
    size: u32,
    frame: u32,
    images: &[(String, String)],
    chart_dir: &str,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Motion blur (chapter 4)\n\nThe rotating 60³ box (`voxsplat animate --anim rotating-box`), frame {frame}, {size}², \
         orthographic, 6° per frame; error against 64-sub-frame accumulation, over the whole frame, the \
         silhouette (truth alpha in (0.05, 0.95)) and the interior (alpha ≥ 0.95).\n\n\
         | method | ms | RMSE | PSNR dB | SSIM luma | RMSE silhouette | RMSE interior |\n|---|---:|---:|---:|---:|---:|---:|"
    );
    for r in rows.iter().filter(|r| r.time_ms.is_finite()) {
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.4} | {:.2} | {:.4} | {:.4} | {:.4} |",
            r.method, r.time_ms, r.metrics.rmse, r.metrics.psnr, r.metrics.ssim_luma, r.rmse_edge, r.rmse_interior
        );
    }
    if !images.is_empty() {
        let heads: Vec<&str> = images.iter().map(|i| i.0.as_str()).collect();
        let _ = writeln!(s, "\n| {} |\n|{}", heads.join(" | "), "---|".repeat(images.len()));
        let cells: Vec<String> = images.iter().map(|i| format!("![]({})", link(chart_dir, &i.1))).collect();
        let _ = writeln!(s, "| {} |", cells.join(" | "));
    }
    let get = |n: &str| rows.iter().find(|r| r.method == n);
    if let (Some(still), Some(acc)) = (get("still"), get("accum:5")) {
        for name in ["blurred splats", "blurred splats sheet"] {
            let Some(b) = get(name) else { continue };
            let (vs_still, vs_acc) = (b.time_ms / still.time_ms, b.time_ms / acc.time_ms);
            let err = b.metrics.rmse / acc.metrics.rmse;
            let met = vs_still <= 1.3 && vs_acc <= 1.0 / 3.0 && err <= 1.0;
            let _ = writeln!(
                s,
                "\n- **{name}:** {vs_still:.2}× a still frame, {vs_acc:.2}× 5-sub-frame accumulation, error {err:.2}× accumulation's \
                 (target ≤ 1.3×, ≤ 0.33×, ≤ 1×): {}.",
                if met { "met" } else { "missed" }
            );
        }
    }
    s
}
