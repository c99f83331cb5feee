//! The matrix's CSV and SVG charts: time against error per scene, its Pareto front.
use super::*;

pub(crate) fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |e| Error::Io { path: path.display().to_string(), source: e }
}

pub fn write_csv(rows: &[Row], path: &Path) -> Result<()> {
    let mut s = String::from(
        "scene,method,width,height,splats,time_ms,wall_ms,order_ms,splat_params_ms,footprint_ms,composite_ms,raycast_ms,rmse,psnr_db,ssim_luma,ssim_alpha,max_abs,violations\n",
    );
    for r in rows {
        let st = |n: &str| r.stages.iter().find(|(k, _)| *k == n).map(|(_, v)| format!("{v:.4}")).unwrap_or_default();
        let order = if st("order").is_empty() { st("order_cpu") } else { st("order") };
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.4},{:.4},{},{},{},{},{},{:.6e},{:.3},{:.6},{:.6},{:.6},{}",
            r.scene,
            r.method,
            r.width,
            r.height,
            r.splats,
            r.time_ms,
            r.wall_ms,
            order,
            st("splat_params"),
            st("footprint"),
            st("composite"),
            st("raycast"),
            r.metrics.rmse,
            r.metrics.psnr,
            r.metrics.ssim_luma,
            r.metrics.ssim_alpha,
            r.metrics.max_abs,
            r.violations.map(|v| v.to_string()).unwrap_or_default()
        );
    }
    std::fs::write(path, s).map_err(io_err(path))
}

/// Indices of the points on the Pareto front (no other point is both faster and more accurate),
/// sorted by time.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> =
        (0..points.len()).filter(|&i| points[i].0.is_finite() && points[i].1.is_finite()).collect();
    idx.sort_by(|&a, &b| points[a].0.partial_cmp(&points[b].0).unwrap_or(std::cmp::Ordering::Equal));
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for i in idx {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

pub(crate) fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
    Error::Image { path: path.display().to_string(), message: e.to_string() }
}

/// Time (log x) against error (y) for one scene, one labelled point per method, Pareto front drawn.
pub fn chart_svg(rows: &[Row], scene: &str, path: &Path) -> Result<()> {
    let points: Vec<(String, f64, f64)> =
        rows.iter().filter(|r| r.scene == scene).map(|r| (r.method.clone(), r.time_ms, r.metrics.rmse)).collect();
    scatter_svg(&points, &format!("{scene}: time vs error (RMSE against the truth)"), "RMSE", path)
}

/// Labelled points, time per frame (log x) against `y_desc`, with the Pareto front (lower is better).
pub fn scatter_svg(points: &[(String, f64, f64)], title: &str, y_desc: &str, path: &Path) -> Result<()> {
    scatter(points, title, y_desc, false, path)
}

/// `scatter_svg` for a measure where higher is better (PSNR).
pub fn scatter_svg_higher(points: &[(String, f64, f64)], title: &str, y_desc: &str, path: &Path) -> Result<()> {
    scatter(points, title, y_desc, true, path)
}

pub(crate) fn scatter(
    points: &[(String, f64, f64)],
    title: &str,
    y_desc: &str,
    higher: bool,
    path: &Path,
) -> Result<()> {
    use plotters::prelude::*;
    let pts: Vec<(f64, f64)> = points.iter().map(|p| (p.1.max(1e-3), p.2)).collect();
    let (xmin, xmax) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let ymax = pts.iter().filter(|p| p.1.is_finite()).fold(0.0f64, |a, p| a.max(p.1));
    let ymin = if higher { pts.iter().filter(|p| p.1.is_finite()).fold(ymax, |a, p| a.min(p.1)) * 0.9 } else { 0.0 };
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((xmin * 0.7..xmax * 1.4).log_scale(), ymin..ymax * 1.15 + 1e-6)
        .map_err(|e| plot_err(path, e))?;
    chart.configure_mesh().x_desc("time per frame, ms (log)").y_desc(y_desc).draw().map_err(|e| plot_err(path, e))?;
    let sign = if higher { -1.0 } else { 1.0 };
    let signed: Vec<(f64, f64)> = pts.iter().map(|&(x, y)| (x, sign * y)).collect();
    let front: Vec<(f64, f64)> = pareto_front(&signed).into_iter().map(|i| pts[i]).collect();
    chart.draw_series(LineSeries::new(front, RED.stroke_width(2))).map_err(|e| plot_err(path, e))?;
    // The levels-of-detail curve (error swept), joined in order of its error bound.
    let curve: Vec<(f64, f64)> =
        points.iter().zip(&pts).filter(|(p, _)| p.0.starts_with(LOD_CURVE)).map(|(_, &xy)| xy).collect();
    if curve.len() > 1 {
        let green = RGBColor(0, 150, 60);
        chart
            .draw_series(LineSeries::new(curve, green.stroke_width(2)))
            .map_err(|e| plot_err(path, e))?
            .label("levels of detail, error bound swept")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], green.stroke_width(2)));
        chart.configure_series_labels().border_style(BLACK).draw().map_err(|e| plot_err(path, e))?;
    }
    chart
        .draw_series(points.iter().zip(&pts).map(|(p, &(x, y))| {
            EmptyElement::at((x, y))
                + Circle::new((0, 0), 4, BLUE.filled())
                + Text::new(p.0.clone(), (6, -12), ("sans-serif", 12))
        }))
        .map_err(|e| plot_err(path, e))?;
    root.present().map_err(|e| plot_err(path, e))?;
    Ok(())
}
