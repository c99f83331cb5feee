//! Benchmark bodies shared by `benches/render.rs` and `voxsplat lab matrix`: the method matrix (time
//! from GPU timestamps, error against the truth), the roofline, and scaling; CSV, SVG charts and
//! docs/RESULTS.md. Medians over frames after warm-up.
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;
use voxsplat::camera::Camera;
use voxsplat::cpu::raycast::RaycastOptions;
use voxsplat::image::ImageF32;
use voxsplat::metrics::{compare, ImageMetrics};
use voxsplat::options::{Antialias, Composite, RenderOptions, Rendered};
use voxsplat::order::{count_violations, visibility_order};
use voxsplat::raster::Raster;
use voxsplat::truth::{volumetric_summation, Reconstruction, TruthOptions};
use voxsplat::volume::{Grid, SplatSet};
use voxsplat::{scene, Direction, Kernel, OrderKind, Renderer};
use voxsplat::{Error, Result};

/// One rendering method of the matrix.
#[derive(Clone, Debug, PartialEq)]
pub enum Method {
    Splat {
        order: OrderKind,
        composite: Composite,
        kernel: Kernel,
        aa: Antialias,
        raster: Raster,
    },
    Raycast {
        step: f32,
    },
    /// PBTF Gaussian splats through the tile compositor from the scene as a bricked volume
    /// (`BrickScene::from_palette`), with levels of detail when `lod` is (pixels, error).
    Bricked {
        lod: Option<(f32, f32)>,
    },
    /// A method drawn at a render scale (`RenderOptions::render_scale`) and resampled.
    Scaled {
        method: Box<Method>,
        scale: f32,
    },
}

fn aa_suffix(aa: Antialias) -> String {
    match aa {
        Antialias::None => String::new(),
        other => format!(" aa={other:?}"),
    }
}

/// Plain splats (no anti-aliasing) through the graphics pipeline.
pub fn splat(order: OrderKind, composite: Composite, kernel: Kernel) -> Method {
    Method::Splat { order, composite, kernel, aa: Antialias::None, raster: Raster::Graphics }
}

/// PBTF splats with the Gaussian through a raster variant.
pub fn rastered(composite: Composite, raster: Raster) -> Method {
    Method::Splat { order: OrderKind::Pbtf, composite, kernel: Kernel::Gaussian, aa: Antialias::None, raster }
}

fn raster_suffix(raster: Raster) -> String {
    match raster {
        Raster::Graphics => String::new(),
        other => format!(" {other}"),
    }
}

impl Method {
    pub fn label(&self) -> String {
        match self {
            Method::Splat { order, composite: Composite::Splat, kernel, aa, raster } => {
                format!("{order:?} splat {kernel:?}{}{}", aa_suffix(*aa), raster_suffix(*raster))
            }
            Method::Splat { composite: Composite::Sheet, kernel, aa, raster, .. } => {
                format!("sheet {kernel:?}{}{}", aa_suffix(*aa), raster_suffix(*raster))
            }
            Method::Splat { composite: Composite::Slab, kernel, aa, raster, .. } => {
                format!("slab {kernel:?}{}{}", aa_suffix(*aa), raster_suffix(*raster))
            }
            Method::Raycast { step } => format!("raycast {step}"),
            Method::Bricked { lod: None } => "bricked compute".into(),
            Method::Bricked { lod: Some((px, e)) } if *px >= LOD_UNBOUNDED => format!("{LOD_CURVE} {e} compute"),
            Method::Bricked { lod: Some((px, e)) } if *e >= LOD_UNBOUNDED => format!("bricked lod {px}px compute"),
            Method::Bricked { lod: Some((px, e)) } => format!("bricked lod {px}px error {e} compute"),
            Method::Scaled { method, scale } => format!("{} scale {scale}", method.label()),
        }
        .to_lowercase()
    }

    /// The anti-aliasing mode of a splat method (`None` for the others).
    fn antialias(&self) -> Option<Antialias> {
        match self {
            Method::Splat { aa, .. } => Some(*aa),
            _ => None,
        }
    }

    fn reconstruction(&self) -> Reconstruction {
        match self {
            Method::Splat { kernel, .. } => Reconstruction::Kernel(*kernel),
            Method::Bricked { .. } => Reconstruction::Kernel(Kernel::Gaussian),
            Method::Raycast { .. } => Reconstruction::Trilinear,
            Method::Scaled { method, .. } => method.reconstruction(),
        }
    }
}

/// `lod_pixels` that lets every level pass the pixel test: levels chosen by their error alone
/// (Laur and Hanrahan's cut).
pub const LOD_UNBOUNDED: f32 = 1e6;
/// Label prefix of the levels-of-detail curve (error swept, pixels unbounded) on the charts.
pub const LOD_CURVE: &str = "bricked lod error";

/// The bricked path at full detail, levels of detail at their defaults and with the error test
/// off (mip-splats: every cell within a pixel), and the levels-of-detail curve: the error bound
/// swept with the pixel test off.
pub fn bricked_methods(errors: &[f32]) -> Vec<Method> {
    let mut m = vec![
        Method::Bricked { lod: None },
        Method::Bricked { lod: Some((1.0, voxsplat::options::DEFAULT_LOD_ERROR)) },
        Method::Bricked { lod: Some((1.0, LOD_UNBOUNDED)) },
    ];
    m.extend(errors.iter().map(|&e| Method::Bricked { lod: Some((LOD_UNBOUNDED, e)) }));
    m
}

/// What `run_matrix` covers.
#[derive(Clone, Debug)]
pub struct MatrixOptions {
    pub scenes: Vec<&'static str>,
    pub methods: Vec<Method>,
    pub width: u32,
    pub height: u32,
    pub warmup: usize,
    pub frames: usize,
}

impl MatrixOptions {
    /// The full matrix: three scenes at 512x512, every order with both classic kernels, sheets,
    /// slabs, the raster variants, the narrow kernel (per-splat quads and points, sheets), three
    /// ray steps.
    pub fn full() -> Self {
        let mut methods = Vec::new();
        for kernel in [Kernel::Gaussian, Kernel::Cubic] {
            for order in [OrderKind::Btf, OrderKind::Wbtf, OrderKind::Pbtf, OrderKind::Sorted] {
                methods.push(splat(order, Composite::Splat, kernel));
            }
            methods.push(splat(OrderKind::Pbtf, Composite::Sheet, kernel));
            methods.push(splat(OrderKind::Pbtf, Composite::Slab, kernel));
        }
        // PBTF with Westover's nesting per octant (issue 26), a host order.
        methods.push(splat(OrderKind::PbtfOctant, Composite::Splat, Kernel::Gaussian));
        for composite in [Composite::Splat, Composite::Sheet, Composite::Slab] {
            for raster in [Raster::Points, Raster::Compute] {
                methods.push(rastered(composite, raster));
            }
        }
        // The narrow kernel: fewer fragments per splat, at the cost of ripple on flat sheets.
        let narrow = Kernel::Narrow;
        methods.push(splat(OrderKind::Pbtf, Composite::Splat, narrow));
        methods.push(splat(OrderKind::Pbtf, Composite::Sheet, narrow));
        methods.push(Method::Splat {
            order: OrderKind::Pbtf,
            composite: Composite::Splat,
            kernel: narrow,
            aa: Antialias::None,
            raster: Raster::Points,
        });
        for step in [1.0, 0.5, 0.25] {
            methods.push(Method::Raycast { step });
        }
        // Half the grid, resampled: pays where footprints span many pixels, blurs where they do not.
        methods.push(Method::Scaled { method: Box::new(rastered(Composite::Splat, Raster::Compute)), scale: 0.5 });
        methods.push(Method::Scaled { method: Box::new(Method::Raycast { step: 1.0 }), scale: 0.5 });
        methods.extend(bricked_methods(&[0.01, 0.03, 0.1, 0.3, 1.0]));
        Self {
            scenes: vec!["cube60", "cube40-attenuated", "plane"],
            methods,
            width: 512,
            height: 512,
            warmup: 2,
            frames: 7,
        }
    }

    /// A small matrix CI can afford.
    pub fn quick() -> Self {
        let g = Kernel::Gaussian;
        Self {
            scenes: vec!["cube40", "plane"],
            methods: vec![
                splat(OrderKind::Btf, Composite::Splat, g),
                splat(OrderKind::Pbtf, Composite::Splat, g),
                splat(OrderKind::Pbtf, Composite::Sheet, g),
                splat(OrderKind::Pbtf, Composite::Slab, g),
                rastered(Composite::Splat, Raster::Compute),
                rastered(Composite::Sheet, Raster::Compute),
                Method::Raycast { step: 1.0 },
                Method::Raycast { step: 0.5 },
                Method::Scaled { method: Box::new(rastered(Composite::Splat, Raster::Compute)), scale: 0.5 },
            ]
            .into_iter()
            .chain(bricked_methods(&[0.1]))
            .collect(),
            width: 128,
            height: 128,
            warmup: 1,
            frames: 5,
        }
    }
}

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct Row {
    pub scene: String,
    pub method: String,
    pub width: u32,
    pub height: u32,
    pub splats: usize,
    /// Median of the summed stage times (GPU timestamps; plus CPU order time where the order is
    /// computed on the CPU).
    pub time_ms: f64,
    pub wall_ms: f64,
    /// Median per stage.
    pub stages: Vec<(&'static str, f64)>,
    pub metrics: ImageMetrics,
    pub violations: Option<u64>,
}

/// The middle value (upper median); NaN when empty.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

/// Medians of `rounds` timings per variant, the `variants` alternating frame by frame after
/// `warmup` untimed rounds (times on these shared machines drift; alternating keeps the ratios
/// fair): `run(v)` draws variant `v` and returns its time in ms.
pub fn alternating_medians(
    variants: usize,
    warmup: usize,
    rounds: usize,
    mut run: impl FnMut(usize) -> Result<f64>,
) -> Result<Vec<f64>> {
    let mut times = vec![Vec::new(); variants];
    for round in 0..warmup + rounds.max(1) {
        for (v, t) in times.iter_mut().enumerate() {
            let ms = run(v)?;
            if round >= warmup {
                t.push(ms);
            }
        }
    }
    Ok(times.iter_mut().map(|t| median(t)).collect())
}

/// The camera every benchmark uses for a scene.
pub fn bench_camera(grid: &Grid, width: u32, height: u32) -> Camera {
    Camera::framing(grid, width, height)
}

fn render_method(r: &mut Renderer, m: &Method, camera: &Camera) -> Result<Rendered> {
    render_method_at(r, m, camera, 1.0)
}

fn render_method_at(r: &mut Renderer, m: &Method, camera: &Camera, render_scale: f32) -> Result<Rendered> {
    match m {
        Method::Splat { order, composite, kernel, aa, raster } => {
            let o = {
                let mut o = RenderOptions::default();
                o.order = *order;
                o.composite = *composite;
                o.kernel = *kernel;
                o.antialias = *aa;
                o.raster = *raster;
                o.render_scale = render_scale;
                o
            };
            r.render(camera, &o)
        }
        Method::Raycast { step } => {
            r.raycast(camera, &RaycastOptions { step: *step, render_scale, ..Default::default() })
        }
        Method::Bricked { lod } => {
            let mut o = RenderOptions::default();
            (o.raster, o.render_scale, o.lod) = (Raster::Compute, render_scale, voxsplat::Lod::Off);
            if let Some((pixels, error)) = *lod {
                (o.lod, o.lod_pixels, o.lod_error) = (voxsplat::Lod::Auto, pixels, error);
            }
            r.render(camera, &o)
        }
        Method::Scaled { method, scale } => render_method_at(r, method, camera, *scale),
    }
}

/// Medians of a timed method and its last image.
pub struct Timed {
    /// Median of the summed stage times.
    pub time_ms: f64,
    /// Median wall time of a whole frame.
    pub wall_ms: f64,
    pub stages: Vec<(&'static str, f64)>,
    pub image: ImageF32,
}

/// Time `frames` renders after `warmup`.
pub fn time_method(r: &mut Renderer, m: &Method, camera: &Camera, warmup: usize, frames: usize) -> Result<Timed> {
    let mut totals = Vec::new();
    let mut walls = Vec::new();
    let mut per_stage: Vec<(&'static str, Vec<f64>)> = Vec::new();
    let mut last = None;
    for f in 0..warmup + frames.max(1) {
        let t = Instant::now();
        let out = render_method(r, m, camera)?;
        let wall = t.elapsed().as_secs_f64() * 1e3;
        if f >= warmup {
            walls.push(wall);
            totals.push(out.timings.iter().map(|s| s.ms).sum::<f64>());
            for s in &out.timings {
                match per_stage.iter_mut().find(|(n, _)| *n == s.stage) {
                    Some((_, v)) => v.push(s.ms),
                    None => per_stage.push((s.stage, vec![s.ms])),
                }
            }
        }
        last = Some(out.image);
    }
    let stages = per_stage.into_iter().map(|(n, mut v)| (n, median(&mut v))).collect();
    Ok(Timed {
        time_ms: median(&mut totals),
        wall_ms: median(&mut walls),
        stages,
        image: last.expect("at least one frame"),
    })
}

/// Run the matrix; `progress(done, total, label)` is called before each configuration.
pub fn run_matrix(
    r: &mut Renderer,
    opts: &MatrixOptions,
    mut progress: impl FnMut(usize, usize, &str),
) -> Result<Vec<Row>> {
    let total = opts.scenes.len() * opts.methods.len();
    let mut rows = Vec::new();
    let mut done = 0;
    for &name in &opts.scenes {
        let set = scene::build(name)?;
        let camera = bench_camera(set.grid(), opts.width, opts.height);
        r.set_scene(set.clone())?;
        // Whether the renderer holds the scene as bricks (Method::Bricked) rather than splats.
        let mut bricked = false;
        let mut truths: Vec<(Reconstruction, ImageF32)> = Vec::new();
        for m in &opts.methods {
            progress(done, total, &format!("{name}: {}", m.label()));
            done += 1;
            let rec = m.reconstruction();
            if !truths.iter().any(|(k, _)| *k == rec) {
                let t =
                    volumetric_summation(&set, &camera, &TruthOptions { reconstruction: rec, ..Default::default() })?;
                truths.push((rec, t));
            }
            let truth = &truths.iter().find(|(k, _)| *k == rec).expect("computed").1;
            hold_scene_for(r, &set, m, &mut bricked)?;
            let Timed { time_ms, wall_ms, stages, image } = time_method(r, m, &camera, opts.warmup, opts.frames)?;
            let violations = match m {
                Method::Splat { order, composite: Composite::Splat, .. } => {
                    let o = visibility_order(&set, &camera, *order, Direction::BackToFront);
                    Some(count_violations(&set, &camera, &o, Direction::BackToFront)?)
                }
                _ => None,
            };
            rows.push(Row {
                scene: name.to_string(),
                method: m.label(),
                width: opts.width,
                height: opts.height,
                splats: set.len(),
                time_ms,
                wall_ms,
                stages,
                metrics: compare(&image, truth)?,
                violations,
            });
        }
    }
    progress(done, total, "done");
    Ok(rows)
}

/// Make `r` hold `set` as `m` draws it: as bricks (`BrickScene::from_palette`) for
/// `Method::Bricked`, else as splats; `bricked` says which it holds and is kept up to date.
fn hold_scene_for(r: &mut Renderer, set: &SplatSet, m: &Method, bricked: &mut bool) -> Result<()> {
    let wants_bricks = matches!(m, Method::Bricked { .. });
    if wants_bricks != *bricked {
        if wants_bricks {
            r.set_bricks(voxsplat::bricks::BrickScene::from_palette(set)?)?;
        } else {
            r.set_scene(set.clone())?;
        }
        *bricked = wants_bricks;
    }
    Ok(())
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
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

fn plot_err(path: &Path, e: impl std::fmt::Display) -> Error {
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

fn scatter(points: &[(String, f64, f64)], title: &str, y_desc: &str, higher: bool, path: &Path) -> Result<()> {
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
        let _ = r.roofline_quads(width, height, size, quads)?;
        let mut t: Vec<f64> =
            (0..frames.max(1)).map(|_| r.roofline_quads(width, height, size, quads)).collect::<Result<_>>()?;
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
    let _ = r.roofline_composite(width, height, layers)?;
    let mut a = Vec::new();
    let mut b = Vec::new();
    for _ in 0..frames.max(1) {
        let (x, y) = r.roofline_composite(width, height, layers)?;
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
    let params = r.splat_params(camera, kernel, voxsplat::Antialias::None)?;
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
/// `crate::bricked::read_scaling_csv`), a third panel: bricked volumes up to 10⁹ voxels beside
/// VTK's fixed-point caster on the same files.
pub fn scaling_svg(points: &[ScalePoint], bricks: Option<&[(f64, f64, f64)]>, path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let panels = 2 + bricks.is_some() as usize;
    let root = SVGBackend::new(path, (450 * panels as u32, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let halves = root.split_evenly((1, panels));
    if let (Some(rows), Some(area)) = (bricks, halves.get(2)) {
        crate::bricked::bricks_panel(area, rows, "bricked volumes vs VTK fixed point, 512^2", path)?;
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

/// Everything `results_markdown` reports.
pub struct Report<'a> {
    pub device: String,
    pub commit: String,
    pub command: String,
    pub rows: &'a [Row],
    pub roofline: Option<&'a (Vec<RooflinePoint>, CompositeRoofline)>,
    pub scaling: &'a [ScalePoint],
    /// Relative path from the markdown file to the charts.
    pub chart_dir: String,
    pub notes: Option<String>,
    /// The anti-aliasing section, already rendered.
    pub antialias: Option<String>,
}

/// A relative link to `file` in `dir` ("" = beside the page).
pub fn link(dir: &str, file: &str) -> String {
    if dir.is_empty() {
        file.to_string()
    } else {
        format!("{dir}/{file}")
    }
}

fn row<'a>(rows: &'a [Row], scene: &str, method: &str) -> Option<&'a Row> {
    rows.iter().find(|r| r.scene == scene && r.method == method)
}

fn stage(r: &Row, name: &str) -> Option<f64> {
    r.stages.iter().find(|s| s.0 == name).map(|s| s.1)
}

/// docs/RESULTS.md: device, commit, the table, the charts, and each target with its measured ratio.
pub fn results_markdown(rep: &Report<'_>) -> Result<String> {
    let mut s = String::new();
    let _ = writeln!(s, "# Results\n");
    let _ = writeln!(
        s,
        "Generated by `{}` at commit `{}` on **{}**. Times are medians after warm-up of each stage's \
         GPU time: timestamp queries on a GPU; on a CPU device (lavapipe) each stage is its own \
         submission timed fence to fence on the host, because lavapipe takes a timestamp when its \
         rasterizer next flushes, not when compute work ends. BTF/WBTF/sorted orders are computed on the \
         host and their time is included. Errors are against the volumetric-summation truth with each \
         method's own reconstruction kernel (docs/MODEL.md). Absolute times on shared machines are \
         noise: read the ratios.\n",
        rep.command, rep.commit, rep.device
    );
    let mut scenes: Vec<&str> = rep.rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    let _ = writeln!(s, "## Speed against accuracy\n");
    for sc in &scenes {
        let _ = writeln!(s, "![{sc}]({})\n", link(&rep.chart_dir, &format!("chart-{sc}.svg")));
    }
    let _ = writeln!(
        s,
        "| scene | method | splats | ms | order ms | params ms | footprint ms | composite ms | RMSE | PSNR dB | SSIM luma | violations |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    let f = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "-".into());
    for r in rep.rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {} | {} | {} | {} | {:.4} | {:.2} | {:.4} | {} |",
            r.scene,
            r.method,
            r.splats,
            r.time_ms,
            f(stage(r, "order").or(stage(r, "order_cpu"))),
            f(stage(r, "splat_params")),
            f(stage(r, "footprint").or(stage(r, "raycast"))),
            f(stage(r, "composite")),
            r.metrics.rmse,
            r.metrics.psnr,
            r.metrics.ssim_luma,
            r.violations.map(|v| v.to_string()).unwrap_or_else(|| "-".into())
        );
    }

    let _ = writeln!(s, "\n## Targets\n");
    // 1. Order stage share and linearity.
    let mut shares = Vec::new();
    for r in rep.rows.iter().filter(|r| r.method == "pbtf splat gaussian") {
        if let Some(o) = stage(r, "order") {
            shares.push(format!("{} {:.1} %", r.scene, 100.0 * o / r.time_ms));
        }
    }
    let per_splat: Vec<String> = rep
        .scaling
        .iter()
        .filter(|p| p.what == "splats" && p.raster == Raster::Graphics && p.order_ms.is_finite())
        .map(|p| format!("{} splats: {:.1} ns/splat", p.splats, p.order_ms * 1e6 / p.splats as f64))
        .collect();
    let _ = writeln!(
        s,
        "- **GPU order stage ≤ 5 % of a frame, linear time.** Share of the PBTF per-splat frame: {}. \
         Order time per splat across the scaling series: {}.",
        if shares.is_empty() { "not measured".into() } else { shares.join(", ") },
        if per_splat.is_empty() { "not measured".into() } else { per_splat.join("; ") }
    );
    // 2. Splat pass against the roofline.
    if let Some((pts, comp)) = rep.roofline {
        let mut lines = Vec::new();
        for sc in &scenes {
            let Some(r) = row(rep.rows, sc, "pbtf splat gaussian") else { continue };
            let (Some(fp), Ok(set)) = (stage(r, "footprint"), scene::build(sc)) else { continue };
            let cam = bench_camera(set.grid(), r.width, r.height);
            let (frags, side) = footprint_fragments(&set, &cam, Kernel::Gaussian)?;
            let rate = frags / (fp * 1e-3);
            let best = pts.iter().min_by(|a, b| {
                (a.size_px as f64 - side)
                    .abs()
                    .partial_cmp(&(b.size_px as f64 - side).abs())
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
            if let Some(b) = best {
                lines.push(format!(
                    "{sc}: median footprint {side:.1} px, {:.1} Mfrag/s = {:.0} % of the {} px roofline ({:.1} Mfrag/s)",
                    rate / 1e6,
                    100.0 * rate / b.fragments_per_s,
                    b.size_px,
                    b.fragments_per_s / 1e6
                ));
            }
        }
        let _ = writeln!(s, "- **Splat pass ≥ 60 % of the roofline's fragment rate.** {}.", lines.join("; "));
        let _ = writeln!(
            s,
            "- Compositing: `composite.comp` over {} layers takes {:.2} ms against {:.2} ms for the read-once roofline \
             ({:.2} GB/s): {:.0} % of the roofline's rate.",
            comp.layers,
            comp.composite_ms,
            comp.roofline_ms,
            comp.roofline_bytes_per_s / 1e9,
            100.0 * comp.roofline_ms / comp.composite_ms
        );
        let _ = writeln!(s, "\n| footprint px | quads | ms | M quads/s | M frag/s |\n|---:|---:|---:|---:|---:|");
        for p in pts {
            let _ = writeln!(
                s,
                "| {} | {} | {:.2} | {:.2} | {:.1} |",
                p.size_px,
                p.quads,
                p.ms,
                p.quads_per_s / 1e6,
                p.fragments_per_s / 1e6
            );
        }
        let _ = writeln!(s);
    }
    // 3. Sheet buffer against the ray caster.
    for sc in &scenes {
        let Some(sheet) = row(rep.rows, sc, "sheet gaussian") else { continue };
        // Full-size ray casts only: the target compares drawing methods at the same grid.
        let casts: Vec<&Row> = rep
            .rows
            .iter()
            .filter(|r| r.scene == *sc && r.method.starts_with("raycast") && !r.method.contains(" scale "))
            .collect();
        if casts.is_empty() {
            continue;
        }
        let reaching: Vec<&&Row> = casts.iter().filter(|r| r.metrics.rmse <= sheet.metrics.rmse).collect();
        let verdict = match reaching
            .iter()
            .min_by(|a, b| a.time_ms.partial_cmp(&b.time_ms).unwrap_or(std::cmp::Ordering::Equal))
        {
            Some(c) => {
                let ratio = sheet.time_ms / c.time_ms;
                format!(
                    "the fastest ray caster at least as accurate ({}, RMSE {:.4}) takes {:.2} ms; the sheet buffer (RMSE {:.4}) takes {:.2}× its time: target {}",
                    c.method, c.metrics.rmse, c.time_ms, sheet.metrics.rmse, ratio, if ratio <= 1.0 / 3.0 { "met" } else { "missed" }
                )
            }
            None => {
                let best = casts
                    .iter()
                    .min_by(|a, b| a.metrics.rmse.partial_cmp(&b.metrics.rmse).unwrap_or(std::cmp::Ordering::Equal))
                    .expect("non-empty");
                format!(
                    "no ray-caster step measured is as accurate as the sheet buffer (RMSE {:.4}; best ray caster {} at {:.4}); sheet time / that ray caster's = {:.2}",
                    sheet.metrics.rmse, best.method, best.metrics.rmse, sheet.time_ms / best.time_ms
                )
            }
        };
        let _ = writeln!(s, "- **Sheet buffer vs ray caster, {sc}:** {verdict}.");
    }
    if let Some(aa) = &rep.antialias {
        let _ = writeln!(s, "\n{aa}");
    }
    if !rep.scaling.is_empty() {
        let _ = writeln!(s, "\n## Scaling\n\n![scaling]({})\n", link(&rep.chart_dir, "scaling.svg"));
        let _ = writeln!(
            s,
            "| series | raster | splats | image | ms | order ms | GPU bytes | bytes/splat |\n|---|---|---:|---:|---:|---:|---:|---:|"
        );
        for p in rep.scaling {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {}² | {:.2} | {:.3} | {} | {:.0} |",
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
    }
    if let Some(n) = &rep.notes {
        let _ = writeln!(s, "\n{n}");
    }
    Ok(s)
}

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
const AA_LOD_ERRORS: [f32; 3] = [0.03, 0.3, 1.0];
/// The pixel bounds swept (error test off) in the anti-aliasing study.
const AA_LOD_PIXELS: [f32; 3] = [2.0, 4.0, 8.0];

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
    let lanczos = voxsplat::truth::Downsample::Lanczos3;
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
    methods.extend(AA_LOD_PIXELS.iter().map(|&px| Method::Bricked { lod: Some((px, LOD_UNBOUNDED)) }));
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
    let splat = RenderOptions::default();
    let sheet = {
        let mut o = RenderOptions::default();
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
