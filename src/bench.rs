//! Benchmark bodies shared by `benches/render.rs` and `voxsplat bench`: per-stage GPU times from
//! timestamp queries (wall times on the CPU backend), medians over frames after warm-up.
use crate::camera::Camera;
use crate::error::Result;
use crate::pipeline::{Composite, RenderOptions};
use crate::{scene, Kernel, OrderKind, Renderer};
use std::time::Instant;

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct Case {
    pub scene: &'static str,
    pub composite: Composite,
    pub kernel: Kernel,
    pub order: OrderKind,
    pub width: u32,
    pub height: u32,
}

impl Case {
    pub fn label(&self) -> String {
        format!("{} {:?} {:?} {:?} {}x{}", self.scene, self.order, self.composite, self.kernel, self.width, self.height)
            .to_lowercase()
    }
}

/// The cases of `docs/RESULTS.md`: cube60 and the plane at 512x512, both compositing modes.
pub fn default_cases() -> Vec<Case> {
    let mut v = Vec::new();
    for scene in ["cube60", "plane"] {
        for composite in [Composite::Splat, Composite::Sheet] {
            v.push(Case {
                scene,
                composite,
                kernel: Kernel::Gaussian,
                order: OrderKind::Pbtf,
                width: 512,
                height: 512,
            });
        }
    }
    v
}

#[derive(Clone, Debug)]
pub struct Measurement {
    pub label: String,
    pub splats: usize,
    /// Median wall time of a whole frame (submit to readback).
    pub wall_ms: f64,
    /// Median per named stage.
    pub stages: Vec<(&'static str, f64)>,
    /// Splats divided by the median of the summed stage times.
    pub splats_per_second: f64,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    if v.is_empty() {
        0.0
    } else {
        v[v.len() / 2]
    }
}

/// Render `case` `warmup + frames` times and take medians over the last `frames`.
pub fn measure(renderer: &mut Renderer, case: &Case, warmup: usize, frames: usize) -> Result<Measurement> {
    let set = scene::build(case.scene)?;
    let splats = set.len();
    let camera = Camera::framing(set.grid(), case.width, case.height);
    renderer.set_scene(set)?;
    let opts =
        RenderOptions { composite: case.composite, kernel: case.kernel, order: case.order, ..Default::default() };
    let mut walls = Vec::new();
    let mut per_stage: Vec<(&'static str, Vec<f64>)> = Vec::new();
    let mut totals = Vec::new();
    for f in 0..warmup + frames {
        let t = Instant::now();
        let r = renderer.render(&camera, &opts)?;
        let wall = t.elapsed().as_secs_f64() * 1e3;
        if f < warmup {
            continue;
        }
        walls.push(wall);
        totals.push(r.timings.iter().map(|s| s.ms).sum::<f64>());
        for s in r.timings {
            match per_stage.iter_mut().find(|(n, _)| *n == s.stage) {
                Some((_, v)) => v.push(s.ms),
                None => per_stage.push((s.stage, vec![s.ms])),
            }
        }
    }
    let total = median(&mut totals);
    Ok(Measurement {
        label: case.label(),
        splats,
        wall_ms: median(&mut walls),
        stages: per_stage.into_iter().map(|(n, mut v)| (n, median(&mut v))).collect(),
        splats_per_second: if total > 0.0 { splats as f64 / (total * 1e-3) } else { 0.0 },
    })
}

/// A markdown table of measurements.
pub fn table(ms: &[Measurement]) -> String {
    let mut s = String::from(
        "| case | splats | order ms | splat_params ms | footprint ms | composite ms | wall ms | splats/s |\n|---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for m in ms {
        let st = |n: &str| m.stages.iter().find(|(k, _)| *k == n).map(|(_, v)| format!("{v:.2}")).unwrap_or("-".into());
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.2} M |\n",
            m.label,
            m.splats,
            st("order"),
            st("splat_params"),
            st("footprint"),
            st("composite"),
            m.wall_ms,
            m.splats_per_second / 1e6
        );
    }
    s
}
