//! The bricked volumes' scaling beside VTK (`scripts/bricks-vtk.sh`'s CSV): its own chart
//! (`voxsplat-lab bricks --chart`) and a panel of the matrix's scaling chart.
use super::*;

/// Rows `voxels,vtk_ms,voxsplat_ms` of the bricked-volume scaling CSV (`scripts/bricks-vtk.sh`),
/// after a header line.
pub fn read_scaling_csv(csv: &Path) -> Result<Vec<(f64, f64, f64)>> {
    let text = std::fs::read_to_string(csv).map_err(|e| Error::Io { path: csv.display().to_string(), source: e })?;
    let bad = |l: &str| Error::InvalidArgument(format!("{}: bad row '{l}' (voxels,vtk_ms,voxsplat_ms)", csv.display()));
    let mut rows = Vec::new();
    for l in text.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let v: Vec<f64> =
            l.split(',').map(|x| x.trim().parse::<f64>()).collect::<std::result::Result<_, _>>().map_err(|_| bad(l))?;
        if v.len() != 3 || v.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(bad(l));
        }
        rows.push((v[0], v[1], v[2]));
    }
    if rows.is_empty() {
        return Err(Error::InvalidArgument(format!("{}: no rows", csv.display())));
    }
    Ok(rows)
}

/// Frame time against voxels on log axes, VTK's fixed-point caster and voxsplat's bricked GPU path
/// on the same files, into `area` (its own chart, and the third panel of the matrix's scaling.svg).
pub fn bricks_panel(
    area: &plotters::drawing::DrawingArea<plotters::prelude::SVGBackend<'_>, plotters::coord::Shift>,
    rows: &[(f64, f64, f64)],
    caption: &str,
    out: &Path,
) -> Result<()> {
    use plotters::prelude::*;
    let plot = |e: &dyn std::fmt::Display| Error::Unsupported(format!("{}: {e}", out.display()));
    let (x0, x1) = rows.iter().fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(r.0), b.max(r.0)));
    let (y0, y1) = rows.iter().fold((f64::INFINITY, 0.0f64), |(a, b), r| (a.min(r.1.min(r.2)), b.max(r.1.max(r.2))));
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(56)
        .build_cartesian_2d((x0 * 0.7..x1 * 1.4).log_scale(), (y0 * 0.7..y1 * 1.4).log_scale())
        .map_err(|e| plot(&e))?;
    chart.configure_mesh().x_desc("voxels in the file").y_desc("median ms per frame").draw().map_err(|e| plot(&e))?;
    for (name, colour, pick) in [("VTK fixed point", RED, 0usize), ("voxsplat bricked (1 GiB budget)", BLUE, 1)] {
        let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.0, if pick == 0 { r.1 } else { r.2 })).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
            .map_err(|e| plot(&e))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
        chart.draw_series(pts.into_iter().map(|p| Circle::new(p, 4, colour.filled()))).map_err(|e| plot(&e))?;
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()
        .map_err(|e| plot(&e))?;
    Ok(())
}

/// The bricked-volume scaling chart (`voxsplat-lab bricks --chart`) from `read_scaling_csv`'s file.
pub fn scaling_chart(csv: &Path, out: &Path) -> Result<()> {
    use plotters::prelude::*;
    let rows = read_scaling_csv(csv)?;
    let plot = |e: &dyn std::fmt::Display| Error::Unsupported(format!("{}: {e}", out.display()));
    let root = SVGBackend::new(out, (700, 440)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot(&e))?;
    bricks_panel(&root, &rows, "bricked volumes against VTK's fixed-point caster, 512x512", out)?;
    root.present().map_err(|e| plot(&e))?;
    Ok(())
}
