//! Benchmark bodies shared by `benches/render.rs` and `voxsplat-lab matrix`: the method matrix (time
//! from GPU timestamps, error against the truth), the roofline, and scaling; CSV, SVG charts and
//! docs/RESULTS.md. Medians over frames after warm-up.
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;
use voxsplat::camera::Camera;
use voxsplat::image::ImageF32;
use voxsplat::metrics::{compare, ImageMetrics};
use voxsplat::options::Raster;
use voxsplat::options::RaycastOptions;
use voxsplat::options::{Antialias, Composite, Rendered};
use voxsplat::order::{count_violations, visibility_order};
use voxsplat::truth::{volumetric_summation, Reconstruction, TruthOptions};
use voxsplat::volume::{Grid, SplatSet};
use voxsplat::{kernel::Kernel, order::Direction, order::OrderKind, scene, Renderer};
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
            Method::Bricked { lod: Some((px, e)) } if *e >= LOD_ANY_ERROR => format!("bricked lod {px}px compute"),
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
pub const LOD_UNBOUNDED: f32 = voxsplat::options::MAX_LOD_PIXELS;
/// `lod_error` that lets every level pass the error test: levels chosen by their size alone.
pub const LOD_ANY_ERROR: f32 = voxsplat::options::MAX_LOD_ERROR;
/// Label prefix of the levels-of-detail curve (error swept, pixels unbounded) on the charts.
pub const LOD_CURVE: &str = "bricked lod error";

/// The bricked path at full detail, levels of detail at their defaults and with the error test
/// off (mip-splats: every cell within a pixel), and the levels-of-detail curve: the error bound
/// swept with the pixel test off.
pub fn bricked_methods(errors: &[f32]) -> Vec<Method> {
    let mut m = vec![
        Method::Bricked { lod: None },
        Method::Bricked { lod: Some((1.0, voxsplat::options::DEFAULT_LOD_ERROR)) },
        Method::Bricked { lod: Some((1.0, LOD_ANY_ERROR)) },
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
            // Two frames: CI checks the rows and their errors, not the times (which the full
            // matrix measures); 5 had made `lab matrix --quick` 204 s, its CLI test the suite's
            // longest.
            warmup: 1,
            frames: 2,
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

pub use voxsplat_cli::measure::median;

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
                let mut o = crate::lab_options();
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
            let mut o = crate::lab_options();
            (o.raster, o.render_scale, o.lod) = (Raster::Compute, render_scale, voxsplat::options::Lod::Off);
            if let Some((pixels, error)) = *lod {
                (o.lod, o.lod_pixels, o.lod_error) = (voxsplat::options::Lod::Auto, pixels, error);
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

mod antialias;
mod bricks_chart;
mod charts;
mod motion;
mod report;
mod roofline;
pub use antialias::{antialias_markdown, antialias_rows, antialias_study, AaRow};
pub use bricks_chart::{bricks_panel, read_scaling_csv, scaling_chart};
pub use charts::{chart_svg, pareto_front, scatter_svg, scatter_svg_higher, write_csv};
pub(crate) use charts::{io_err, plot_err};
pub use motion::{motion_markdown, motion_rows, motion_study, write_motion_images, MotionRow};
pub use report::{link, matrix_markdown, results_markdown, Detail, Report};
pub use roofline::{
    footprint_fragments, roofline, scaling, scaling_svg, synthetic_cube, write_scaling_csv, CompositeRoofline,
    RooflinePoint, ScalePoint, SCALING_RASTERS,
};
