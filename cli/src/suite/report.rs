//! The suite's report: per-case figures, the score, the readable table, JSON, and the comparison of
//! two reports.
use super::{Case, SUITE_VERSION};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;
use voxsplat::{Error, Result};

/// One case's figures.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CaseResult {
    /// The case's name.
    pub name: String,
    /// Frame width and height.
    pub size: [u32; 2],
    /// Timed frames.
    pub frames: usize,
    /// Wall time of a frame, image read back included: median, fastest, slowest (ms).
    pub median_ms: f64,
    /// Fastest frame (ms).
    pub min_ms: f64,
    /// Slowest frame (ms).
    pub max_ms: f64,
    /// The frame times' range (slowest less fastest) over their median: the case's noise.
    pub spread: f64,
    /// Median of the summed stage times (GPU timestamps; the host's clock on a CPU device).
    pub stages_ms: f64,
    /// Frames per second at the median.
    pub fps: f64,
    /// Splats drawn in the last frame (a bricked volume's voxels and coarse cells; a splat set's
    /// splats).
    pub splats: u64,
    /// Level-of-detail nodes above the brick drawn in the last frame.
    pub nodes: u32,
    /// Millions of splats drawn a second at the median.
    pub msplats_per_s: f64,
    /// Device memory held, the largest seen after a frame (MiB).
    pub device_mib: f64,
    /// The process's peak resident host memory while the case ran (MiB).
    pub host_peak_mib: f64,
    /// PSNR of the last frame against the case's truth over the covered pixels (either image's
    /// alpha above 1/255; dB; `None` without one).
    pub psnr_db: Option<f64>,
    /// Seconds to load the case (read, classify, upload), not in the frame times.
    pub load_s: f64,
    /// The raster path the frame took, and why.
    pub raster: String,
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let x = q * (sorted.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] * (1.0 - f) + sorted[j] * f
}

impl CaseResult {
    /// The figures of `case` from its frames' wall and stage times.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        case: &Case,
        mut walls: Vec<f64>,
        mut stages: Vec<f64>,
        splats: u64,
        nodes: u32,
        device_bytes: u64,
        psnr_db: Option<f64>,
        load_s: f64,
        last: &voxsplat::Rendered,
    ) -> Self {
        walls.sort_by(f64::total_cmp);
        stages.sort_by(f64::total_cmp);
        let median_ms = quantile(&walls, 0.5);
        let spread =
            (walls.last().copied().unwrap_or(f64::NAN) - walls.first().copied().unwrap_or(f64::NAN)) / median_ms;
        Self {
            name: case.name.into(),
            size: case.size,
            frames: walls.len(),
            median_ms,
            min_ms: walls.first().copied().unwrap_or(f64::NAN),
            max_ms: walls.last().copied().unwrap_or(f64::NAN),
            spread,
            stages_ms: quantile(&stages, 0.5),
            fps: 1e3 / median_ms,
            splats,
            nodes,
            msplats_per_s: splats as f64 / median_ms / 1e3,
            device_mib: device_bytes as f64 / 1048576.0,
            host_peak_mib: crate::measure::peak_rss_mib().unwrap_or(f64::NAN),
            psnr_db: psnr_db.map(|p| if p.is_finite() { p } else { 99.0 }),
            load_s,
            raster: last.raster.as_ref().map(|c| format!("{} ({})", c.raster, c.reason)).unwrap_or_default(),
        }
    }
}

/// The device and build a report was measured on.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Platform {
    /// The Vulkan device's name ("cpu" for the CPU mirrors).
    pub device: String,
    /// Its kind (discrete, cpu, ...).
    pub kind: String,
    /// Its driver.
    pub driver: String,
    /// Its Vulkan version.
    pub api: String,
    /// voxsplat's version.
    pub voxsplat: String,
    /// The commit it was built from ("unknown" outside a git checkout).
    pub commit: String,
    /// Host CPUs the process may use.
    pub host_cpus: usize,
}

/// A whole run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Report {
    /// The suite's version (`SUITE_VERSION`).
    pub suite: u32,
    /// The quick suite.
    pub quick: bool,
    /// Validation was on: the times are not a measurement.
    pub validation: bool,
    /// Untimed frames a case, before the timed ones.
    pub warmup: usize,
    /// Timed frames a case.
    pub frames: usize,
    /// Where it ran.
    pub platform: Platform,
    /// The cases run, in the suite's order.
    pub cases: Vec<CaseResult>,
    /// Cases that could not run, with why.
    pub skipped: Vec<(String, String)>,
    /// The geometric mean of the cases' frames per second.
    pub score: f64,
    /// The score's relative noise: the mean of the cases' spreads (a shared machine's drift moves
    /// every case at once, so their noise adds up rather than averaging out).
    pub score_noise: f64,
}

/// The geometric mean of `fps` and its relative noise from each case's `spread`.
pub fn score(cases: &[CaseResult]) -> (f64, f64) {
    if cases.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = cases.len() as f64;
    let mean_log = cases.iter().map(|c| c.fps.ln()).sum::<f64>() / n;
    let noise = cases.iter().map(|c| c.spread).sum::<f64>() / n;
    (mean_log.exp(), noise)
}

impl Report {
    /// The report's table, as `voxsplat bench` prints it.
    pub fn table(&self) -> String {
        let p = &self.platform;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "voxsplat {} ({}) suite {}{} on {} ({}, {}, Vulkan {})",
            p.voxsplat,
            p.commit,
            self.suite,
            if self.quick { " quick" } else { "" },
            p.device,
            p.kind,
            p.driver,
            p.api
        );
        let _ = writeln!(
            s,
            "{:<11} {:>9} {:>9} {:>9} {:>9} {:>6} {:>8} {:>10} {:>8} {:>8} {:>7} {:>6}",
            "case", "size", "median", "min", "max", "spread", "fps", "splats", "Msplat/s", "dev MiB", "PSNR", "load"
        );
        for c in &self.cases {
            let _ = writeln!(
                s,
                "{:<11} {:>9} {:>7.1}ms {:>7.1}ms {:>7.1}ms {:>5.1}% {:>8.2} {:>10} {:>8.1} {:>8.0} {:>7} {:>5.1}s",
                c.name,
                format!("{}x{}", c.size[0], c.size[1]),
                c.median_ms,
                c.min_ms,
                c.max_ms,
                c.spread * 100.0,
                c.fps,
                c.splats,
                c.msplats_per_s,
                c.device_mib,
                c.psnr_db.map(|p| format!("{p:.1}dB")).unwrap_or_else(|| "-".into()),
                c.load_s
            );
        }
        for (name, why) in &self.skipped {
            let _ = writeln!(s, "{name:<11} skipped: {why}");
        }
        let _ = writeln!(
            s,
            "score: {:.3} (geometric mean of frames per second over {} case(s), ±{:.1}%){}",
            self.score,
            self.cases.len(),
            self.score_noise * 100.0,
            if self.validation { "; validation was on: not a measurement" } else { "" }
        );
        s
    }

    /// Write the report as JSON.
    pub fn write_json(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
        std::fs::write(path, text).map_err(|source| Error::Io { path: path.display().to_string(), source })
    }

    /// Read a report written by `write_json`.
    pub fn read_json(path: &Path) -> Result<Self> {
        let text = voxsplat::loaders::read_text(path, "a benchmark report")?;
        let report: Self = serde_json::from_str(&text)
            .map_err(|e| Error::InvalidArgument(format!("{}: not a voxsplat bench report: {e}", path.display())))?;
        report.check().map_err(|why| Error::InvalidArgument(format!("{}: {why}", path.display())))?;
        Ok(report)
    }

    /// What a report `voxsplat bench` wrote holds: each case once, its frame rate and times
    /// positive and finite, its spread finite and not negative (a ratio of such reports is one).
    fn check(&self) -> std::result::Result<(), String> {
        for (i, c) in self.cases.iter().enumerate() {
            let case = format!("case {} ({}x{})", c.name, c.size[0], c.size[1]);
            for (field, v) in [("fps", c.fps), ("median_ms", c.median_ms)] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(format!("{case}: {field} is {v}; a measured case has a positive, finite {field}"));
                }
            }
            if !(c.spread.is_finite() && c.spread >= 0.0) {
                return Err(format!("{case}: spread is {}; a spread is finite and not negative", c.spread));
            }
            if self.cases[..i].iter().any(|d| d.name == c.name && d.size == c.size) {
                return Err(format!("{case} appears twice; a report holds each case once"));
            }
        }
        Ok(())
    }
}

/// Reports `a` and `b` side by side: per case the frame rate's ratio b/a with the two spreads
/// combined, then the scores'. Reports of different suite versions are refused.
pub fn compare(a: &Report, b: &Report) -> Result<String> {
    if a.suite != b.suite {
        return Err(Error::InvalidArgument(format!(
            "suite {} against suite {}: their cases differ; run both with one voxsplat",
            a.suite, b.suite
        )));
    }
    let mut s = String::new();
    let _ = writeln!(s, "A: {} ({}, {})", a.platform.device, a.platform.commit, a.platform.driver);
    let _ = writeln!(s, "B: {} ({}, {})", b.platform.device, b.platform.commit, b.platform.driver);
    let _ = writeln!(s, "{:<11} {:>9} {:>9} {:>8} {:>8}", "case", "A fps", "B fps", "B/A", "noise");
    let mut common = Vec::new();
    for ca in &a.cases {
        let Some(cb) = b.cases.iter().find(|c| c.name == ca.name && c.size == ca.size) else {
            let _ = writeln!(s, "{:<11} only in A", ca.name);
            continue;
        };
        let ratio = cb.fps / ca.fps;
        let noise = (ca.spread * ca.spread + cb.spread * cb.spread).sqrt();
        let verdict = if (ratio.ln()).abs() <= noise {
            "within the noise"
        } else if ratio > 1.0 {
            "faster"
        } else {
            "slower"
        };
        let _ = writeln!(
            s,
            "{:<11} {:>9.2} {:>9.2} {:>7.3}x {:>7.1}%  {verdict}",
            ca.name,
            ca.fps,
            cb.fps,
            ratio,
            noise * 100.0
        );
        common.push((ca.clone(), cb.clone()));
    }
    for cb in b.cases.iter().filter(|c| !a.cases.iter().any(|x| x.name == c.name && x.size == c.size)) {
        let _ = writeln!(s, "{:<11} only in B", cb.name);
    }
    if common.is_empty() {
        return Err(Error::InvalidArgument(
            "the two reports share no case (name and size): nothing to compare; run the same suite on both".into(),
        ));
    }
    let (sa, na) = score(&common.iter().map(|c| c.0.clone()).collect::<Vec<_>>());
    let (sb, nb) = score(&common.iter().map(|c| c.1.clone()).collect::<Vec<_>>());
    let noise = (na * na + nb * nb).sqrt();
    let _ = writeln!(
        s,
        "score over the {} common case(s): A {sa:.3}, B {sb:.3}, B/A {:.3}x ±{:.1}%",
        common.len(),
        sb / sa,
        noise * 100.0
    );
    if a.suite != SUITE_VERSION {
        let _ = writeln!(s, "(suite {} reports; this voxsplat runs suite {SUITE_VERSION})", a.suite);
    }
    Ok(s)
}
