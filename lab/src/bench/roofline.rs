//! The device's roofline (fragments per second at fixed footprint sizes) and the scaling series
//! in splats and pixels, with their CSV and chart.
use super::*;

/// One point of the roofline.
#[derive(Clone, Debug)]
pub struct RooflinePoint {
    pub size_px: u32,
    pub quads: u32,
    pub ms: f64,
    pub fragments_per_s: f64,
    pub quads_per_s: f64,
}

/// The compositing roofline at a layer count.
#[derive(Clone, Debug)]
pub struct CompositeRoofline {
    pub layers: u32,
    pub roofline_ms: f64,
    pub composite_ms: f64,
    pub roofline_bytes_per_s: f64,
}

/// Best-case raster rate of additive quads of each size, and the compositing roofline.
pub fn roofline(
    r: &mut Renderer,
    width: u32,
    height: u32,
    sizes: &[u32],
    fragments: u64,
    frames: usize,
) -> Result<(Vec<RooflinePoint>, CompositeRoofline)> {
    let mut pts = Vec::new();
    for &size in sizes {
        let quads = (fragments / (size as u64 * size as u64)).max(1) as u32;
        let _ = voxsplat::low_level::roofline_quads(r, width, height, size, quads)?;
        let mut t: Vec<f64> = (0..frames.max(1))
            .map(|_| voxsplat::low_level::roofline_quads(r, width, height, size, quads))
            .collect::<Result<_>>()?;
        let ms = median(&mut t);
        let frags = quads as f64 * (size * size) as f64;
        pts.push(RooflinePoint {
            size_px: size,
            quads,
            ms,
            fragments_per_s: frags / (ms * 1e-3),
            quads_per_s: quads as f64 / (ms * 1e-3),
        });
    }
    let layers = 32;
    let _ = voxsplat::low_level::roofline_composite(r, width, height, layers)?;
    let mut a = Vec::new();
    let mut b = Vec::new();
    for _ in 0..frames.max(1) {
        let (x, y) = voxsplat::low_level::roofline_composite(r, width, height, layers)?;
        a.push(x);
        b.push(y);
    }
    let (roofline_ms, composite_ms) = (median(&mut a), median(&mut b));
    let bytes = (layers as f64 + 2.0) * width as f64 * height as f64 * 16.0;
    Ok((
        pts,
        CompositeRoofline { layers, roofline_ms, composite_ms, roofline_bytes_per_s: bytes / (roofline_ms * 1e-3) },
    ))
}

/// Fragments the footprint pass of a frame touches: the quads' pixel areas (clipped to the image).
pub fn footprint_fragments(set: &SplatSet, camera: &Camera, kernel: Kernel) -> Result<(f64, f64)> {
    let mut r = Renderer::new(&{
        let mut o = voxsplat::RendererOptions::default();
        o.backend = voxsplat::Backend::Cpu;
        o
    })?;
    r.set_scene(set.clone())?;
    let params = voxsplat::low_level::splat_params(&mut r, camera, kernel, voxsplat::options::Antialias::None)?;
    let cap = camera.width as f64 * camera.height as f64;
    let mut total = 0.0;
    let mut sizes = Vec::new();
    for p in params.iter().filter(|p| p.center[3] != 0.0) {
        let side = 2.0 * p.screen[2] as f64;
        total += (side * side).min(cap);
        sizes.push(side);
    }
    Ok((total, median(&mut sizes)))
}

/// A dense cube of side `n` with a colour gradient and low opacity: n^3 splats.
pub fn synthetic_cube(n: u32) -> Result<SplatSet> {
    let grid = Grid::centered([n, n, n], [1.0; 3])?;
    let f = 1.0 / n as f32;
    SplatSet::from_fn(grid, |i, j, k| Some([i as f32 * f, j as f32 * f, k as f32 * f, 0.02]))
}

/// One scaling measurement.
#[derive(Clone, Debug)]
pub struct ScalePoint {
    pub what: &'static str,
    /// The footprint stage's raster variant (PBTF per-splat compositing).
    pub raster: Raster,
    pub splats: usize,
    pub width: u32,
    pub time_ms: f64,
    pub order_ms: f64,
    pub gpu_bytes: u64,
}

/// Every raster variant in the scaling curves.
pub const SCALING_RASTERS: [Raster; 3] = [Raster::Graphics, Raster::Points, Raster::Compute];

/// Time against splat count (dense cubes of the given sides) and against image side (cube60),
/// PBTF per-splat compositing through every raster variant.
pub fn scaling(
    r: &mut Renderer,
    cube_sides: &[u32],
    image_sides: &[u32],
    frames: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<ScalePoint>> {
    let mut out = Vec::new();
    let gpu_bytes = |r: &Renderer| r.context().map(|c| c.allocation_report().1).unwrap_or(0);
    let measure = |r: &mut Renderer, what, splats, camera: &Camera, out: &mut Vec<ScalePoint>| -> Result<()> {
        for raster in SCALING_RASTERS {
            let t = time_method(r, &rastered(Composite::Splat, raster), camera, 1, frames)?;
            let order_ms = t.stages.iter().find(|s| s.0 == "order").map(|s| s.1).unwrap_or(f64::NAN);
            let (time_ms, width, gpu_bytes) = (t.time_ms, camera.width, gpu_bytes(r));
            out.push(ScalePoint { what, raster, splats, width, time_ms, order_ms, gpu_bytes });
        }
        Ok(())
    };
    for &n in cube_sides {
        progress(&format!("scaling: {}^3 splats", n));
        let set = synthetic_cube(n)?;
        let splats = set.len();
        let camera = bench_camera(set.grid(), 512, 512);
        r.set_scene(set)?;
        measure(r, "splats", splats, &camera, &mut out)?;
    }
    let set = scene::build("cube60")?;
    let splats = set.len();
    let grid = *set.grid();
    r.set_scene(set)?;
    for &side in image_sides {
        progress(&format!("scaling: {side}^2 image"));
        measure(r, "image", splats, &bench_camera(&grid, side, side), &mut out)?;
    }
    Ok(out)
}

pub fn write_scaling_csv(points: &[ScalePoint], path: &Path) -> Result<()> {
    let mut s = String::from("series,raster,splats,image_side,time_ms,order_ms,gpu_bytes,gpu_bytes_per_splat\n");
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},{},{:.4},{:.4},{},{:.1}",
            p.what,
            p.raster,
            p.splats,
            p.width,
            p.time_ms,
            p.order_ms,
            p.gpu_bytes,
            p.gpu_bytes as f64 / p.splats.max(1) as f64
        );
    }
    std::fs::write(path, s).map_err(io_err(path))
}

/// Log-log time against size for both scaling series and, with `bricks` (rows of
/// `read_scaling_csv`), a third panel: bricked volumes up to 10⁹ voxels beside
/// VTK's fixed-point caster on the same files.
pub fn scaling_svg(points: &[ScalePoint], bricks: Option<&[(f64, f64, f64)]>, path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let panels = 2 + bricks.is_some() as usize;
    let root = SVGBackend::new(path, (450 * panels as u32, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let halves = root.split_evenly((1, panels));
    if let (Some(rows), Some(area)) = (bricks, halves.get(2)) {
        bricks_panel(area, rows, "bricked volumes vs VTK fixed point, 512^2", path)?;
    }
    let colours = [BLUE, GREEN, RED];
    for (area, what) in halves.iter().zip(["splats", "image"]) {
        let series = |raster: Raster| -> Vec<(f64, f64)> {
            points
                .iter()
                .filter(|p| p.what == what && p.raster == raster)
                .map(|p| {
                    let x = if what == "splats" { p.splats as f64 } else { (p.width as f64).powi(2) };
                    (x, p.time_ms.max(1e-3))
                })
                .collect()
        };
        let all: Vec<(f64, f64)> = SCALING_RASTERS.iter().flat_map(|&r| series(r)).collect();
        if all.is_empty() {
            continue;
        }
        let (x0, x1) = all.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
        let (y0, y1) = all.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
        let mut chart = ChartBuilder::on(area)
            .caption(
                if what == "splats" { "time vs splats (PBTF, 512^2)" } else { "time vs pixels (cube60)" },
                ("sans-serif", 16),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d((x0 * 0.7..x1 * 1.4).log_scale(), (y0 * 0.7..y1 * 1.4).log_scale())
            .map_err(|e| plot_err(path, e))?;
        chart
            .configure_mesh()
            .x_desc(if what == "splats" { "splats" } else { "pixels" })
            .y_desc("ms per frame")
            .draw()
            .map_err(|e| plot_err(path, e))?;
        for (raster, colour) in SCALING_RASTERS.iter().zip(colours) {
            let pts = series(*raster);
            chart
                .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
                .map_err(|e| plot_err(path, e))?
                .label(raster.name())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(|e| plot_err(path, e))?;
        }
        chart
            .configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE.mix(0.8))
            .draw()
            .map_err(|e| plot_err(path, e))?;
    }
    root.present().map_err(|e| plot_err(path, e))?;
    Ok(())
}
