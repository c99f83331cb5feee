//! The raster-rate sweep of `voxsplat-lab matrix`: splats per second of every raster variant
//! against footprint size, each with its error against the truth, beside the raster roofline.
//!
//! Scene: one sheet of n x n voxels (a checkerboard at opacity 0.3) seen head-on through an
//! orthographic camera scaled so every footprint quad is exactly `size` pixels wide (the Gaussian's
//! support is 4 voxel spacings across). Orthographic, so point sprites are exact too and every
//! variant draws the same picture: equal error is checked, not assumed.
use crate::bench::{median, rastered, time_method};
use std::fmt::Write as _;
use std::path::Path;
use voxsplat::image::ImageF32;
use voxsplat::metrics::compare;
use voxsplat::options::Composite;
use voxsplat::options::Raster;
use voxsplat::scene::{rate_camera, rate_scene};
use voxsplat::truth::{volumetric_summation, Reconstruction, TruthOptions};
use voxsplat::{kernel::Kernel, Renderer};
use voxsplat::{Error, Result};

/// The variants the sweep times: per-splat compositing and the sheet buffer, each through quads,
/// point sprites and compute.
pub const RATE_VARIANTS: [(Composite, Raster); 6] = [
    (Composite::Splat, Raster::Graphics),
    (Composite::Splat, Raster::Points),
    (Composite::Splat, Raster::Compute),
    (Composite::Sheet, Raster::Graphics),
    (Composite::Sheet, Raster::Points),
    (Composite::Sheet, Raster::Compute),
];

/// One variant at one footprint size.
#[derive(Clone, Debug)]
pub struct RatePoint {
    pub composite: Composite,
    pub raster: Raster,
    /// Footprint quad side in pixels.
    pub size_px: f32,
    pub splats: usize,
    /// Median of the stages after `splat_params` (binning, footprints, compositing), ms.
    pub raster_ms: f64,
    pub splats_per_s: f64,
    /// RMSE against the volumetric-summation truth.
    pub rmse: f64,
    /// Speed over the quads with the same compositing: the median over rounds of the quads' time
    /// over this variant's time in the same round (a paired ratio: both timed within about a
    /// second, so a slow spell of the shared machine lands on both).
    pub vs_quads: f64,
    /// Smallest and largest of those per-round ratios.
    pub vs_quads_range: (f64, f64),
}

impl RatePoint {
    pub fn label(&self) -> String {
        let c = match self.composite {
            Composite::Splat => "splat",
            Composite::Sheet => "sheet",
            Composite::Slab => "slab",
        };
        format!("{c} {}", self.raster)
    }
}

/// Rounds of the sweep at each size. A round takes a warm-up frame of every variant, then its
/// frames one per variant in turn (forward in even rounds, backward in odd ones, so neither of a
/// pair is always timed first): the variants' frames interleave, so a slow spell of the shared
/// machine (they last seconds) lands on all of them alike. A variant's time in a round is the
/// median of its frames; its time at a size is the median over rounds.
pub const RATE_ROUNDS: usize = 5;
const _: () = assert!(RATE_ROUNDS > 0);

/// Time every variant of `RATE_VARIANTS` at each footprint size on an `n` x `n` sheet
/// (`RATE_ROUNDS` rounds of `frames` frames per variant after a warm-up, the variants' frames
/// interleaved).
pub fn raster_rates(
    r: &mut Renderer,
    n: u32,
    sizes: &[f32],
    frames: usize,
    mut progress: impl FnMut(&str),
) -> Result<Vec<RatePoint>> {
    let set = rate_scene(n)?;
    let splats = set.len();
    let grid = *set.grid();
    r.set_scene(set.clone())?;
    let mut out = Vec::new();
    for &size in sizes {
        let camera = rate_camera(&grid, size)?;
        progress(&format!("raster rates: {size} px footprints ({}² image)", camera.width));
        let truth = volumetric_summation(
            &set,
            &camera,
            &TruthOptions { reconstruction: Reconstruction::Kernel(Kernel::Gaussian), ..Default::default() },
        )?;
        // Per variant: its raster time in each round and its last image.
        let mut runs: Vec<(Vec<f64>, Option<ImageF32>)> = RATE_VARIANTS.iter().map(|_| (Vec::new(), None)).collect();
        for round in 0..RATE_ROUNDS {
            let mut turn: Vec<usize> = (0..RATE_VARIANTS.len()).collect();
            if round % 2 == 1 {
                turn.reverse();
            }
            // Frame 0 of each variant is its warm-up.
            let mut times: Vec<Vec<f64>> = RATE_VARIANTS.iter().map(|_| Vec::new()).collect();
            for frame in 0..=frames.max(1) {
                for &v in &turn {
                    let (composite, raster) = RATE_VARIANTS[v];
                    let t = time_method(r, &rastered(composite, raster), &camera, 0, 1)?;
                    let before: f64 =
                        t.stages.iter().filter(|s| matches!(s.0, "order" | "splat_params")).map(|s| s.1).sum();
                    if frame > 0 {
                        times[v].push(t.time_ms - before);
                    }
                    runs[v].1 = Some(t.image);
                }
            }
            for (v, t) in times.iter_mut().enumerate() {
                runs[v].0.push(median(t));
            }
        }
        for (v, &(composite, raster)) in RATE_VARIANTS.iter().enumerate() {
            let quads = RATE_VARIANTS.iter().position(|&(c, r)| c == composite && r == Raster::Graphics);
            let mut paired: Vec<f64> = match quads {
                Some(q) => runs[q].0.iter().zip(&runs[v].0).map(|(g, t)| g / t).collect(),
                None => vec![f64::NAN],
            };
            let range = paired.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
            let raster_ms = median(&mut runs[v].0);
            out.push(RatePoint {
                composite,
                raster,
                size_px: size,
                splats,
                raster_ms,
                splats_per_s: splats as f64 / (raster_ms * 1e-3),
                rmse: compare(runs[v].1.as_ref().expect("RATE_ROUNDS > 0"), &truth)?.rmse,
                vs_quads: median(&mut paired),
                vs_quads_range: range,
            });
        }
    }
    Ok(out)
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |e| Error::Io { path: path.display().to_string(), source: e }
}

pub fn write_rates_csv(points: &[RatePoint], path: &Path) -> Result<()> {
    std::fs::write(path, rates_csv(points)).map_err(io_err(path))
}

/// The sweep as CSV text.
pub fn rates_csv(points: &[RatePoint]) -> String {
    let mut s = String::from("variant,size_px,splats,raster_ms,splats_per_s,rmse,vs_quads\n");
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{},{:.4},{:.0},{:.6},{:.4}",
            p.label(),
            p.size_px,
            p.splats,
            p.raster_ms,
            p.splats_per_s,
            p.rmse,
            p.vs_quads
        );
    }
    s
}

/// Splat rate against footprint size, one line per variant (log-log).
pub fn rates_svg(points: &[RatePoint], path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| Error::Io {
        path: path.display().to_string(),
        source: std::io::Error::other(e.to_string()),
    };
    let root = SVGBackend::new(path, (760, 460)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (x0, x1) =
        points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.size_px as f64), b.max(p.size_px as f64)));
    let (y0, y1) =
        points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.splats_per_s), b.max(p.splats_per_s)));
    if !x0.is_finite() || !y0.is_finite() || y0 <= 0.0 {
        return Err(Error::InvalidArgument("no raster rates to chart".into()));
    }
    let mut chart = ChartBuilder::on(&root)
        .caption("splat rate vs footprint size (lavapipe)", ("sans-serif", 18))
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((x0 * 0.8..x1 * 1.25).log_scale(), (y0 * 0.7..y1 * 1.4).log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("footprint quad side (px)")
        .y_desc("splats per second")
        .draw()
        .map_err(|e| err(&e))?;
    let colours = [BLUE, GREEN, RED, CYAN, MAGENTA, BLACK];
    for ((composite, raster), colour) in RATE_VARIANTS.iter().zip(colours) {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.composite == *composite && p.raster == *raster)
            .map(|p| (p.size_px as f64, p.splats_per_s))
            .collect();
        let Some(first) = points.iter().find(|p| p.composite == *composite && p.raster == *raster) else {
            continue;
        };
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(first.label())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2)));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled()))).map_err(|e| err(&e))?;
    }
    chart.configure_series_labels().border_style(BLACK).background_style(WHITE.mix(0.8)).draw().map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// The markdown section: rates, errors and the compute/quad ratios at each size, with the raster
/// roofline (`quads_per_s` of `bench::roofline` at the same sizes, when measured).
pub fn rates_markdown(points: &[RatePoint], roofline: &[(u32, f64)], chart: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## Raster variants\n\n![splat rate vs footprint]({chart})\n");
    let _ = writeln!(
        s,
        "One sheet of {} voxels, head-on and orthographic, footprint quads exactly N px wide; rate = splats \
         over the time of the stages after `splat_params` (median of {RATE_ROUNDS} rounds; a round takes a \
         warm-up frame of each variant, then its frames one per variant in turn, forward then backward, \
         and its time for a variant is the median of that variant's frames); RMSE against the \
         volumetric-summation truth; *vs quads* = the median over rounds of the quads' time over the \
         variant's in the same round (smallest–largest round in brackets). Roofline: additive quads \
         with the cheapest shaders (`roofline.vert/.frag`).\n",
        points.first().map(|p| p.splats).unwrap_or(0)
    );
    let _ = writeln!(
        s,
        "| variant | px | ms | Msplats/s | RMSE | vs quads (same compositing) |\n|---|---:|---:|---:|---:|---|"
    );
    for p in points {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.3} | {:.5} | {:.2}x ({:.2}–{:.2}) |",
            p.label(),
            p.size_px,
            p.raster_ms,
            p.splats_per_s / 1e6,
            p.rmse,
            p.vs_quads,
            p.vs_quads_range.0,
            p.vs_quads_range.1
        );
    }
    if !roofline.is_empty() {
        let cells: Vec<String> = roofline.iter().map(|(px, q)| format!("{px} px: {:.2} M quads/s", q / 1e6)).collect();
        let _ = writeln!(s, "\nRaster roofline (this run): {}.", cells.join("; "));
    }
    // The target: compute at >= 2.5x the quads' splat rate for footprints of 7 px or less.
    let mut lines = Vec::new();
    for composite in [Composite::Splat, Composite::Sheet] {
        let mut ratios = Vec::new();
        for p in points.iter().filter(|p| p.composite == composite && p.raster == Raster::Compute && p.size_px <= 7.0) {
            if let Some(q) = points
                .iter()
                .find(|q| q.composite == composite && q.raster == Raster::Graphics && q.size_px == p.size_px)
            {
                ratios.push((p.size_px, p.vs_quads, p.vs_quads_range, p.rmse / q.rmse.max(1e-12)));
            }
        }
        if ratios.is_empty() {
            continue;
        }
        let mut r: Vec<f64> = ratios.iter().map(|x| x.1).collect();
        let worst = r.iter().cloned().fold(f64::INFINITY, f64::min);
        let cells: Vec<String> = ratios
            .iter()
            .map(|(px, k, (lo, hi), e)| format!("{px} px {k:.2}x ({lo:.2}–{hi:.2}; error ratio {e:.3})"))
            .collect();
        lines.push(format!(
            "{}: {} — worst {:.2}x, median {:.2}x: {}",
            if composite == Composite::Splat { "per-splat (tile compositor)" } else { "sheet (fixed-point sums)" },
            cells.join(", "),
            worst,
            median(&mut r),
            if worst >= 2.5 { "met" } else { "missed" }
        ));
    }
    let _ = writeln!(s, "\n**Target: compute ≥ 2.5x the instanced quads' splat rate at ≤ 7 px, equal error.**");
    for l in lines {
        let _ = writeln!(s, "- {l}");
    }
    s
}
