//! The modes study (issue 46): each rendering mode of a volume's default (bricked) frame beside
//! the ray caster in the same mode, speed against accuracy, both scored against a fine ray cast in
//! that mode; charted per volume, with the composited frames the projections are measured against.
use crate::bench::{alternating_medians, median, scatter_svg_higher};
use crate::bricked::frame_ms;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::TransferFunction;
use voxsplat::{options::Mode, options::RaycastOptions, Camera, Renderer, RendererOptions, Result};

/// A volume of the study: its name, file, transfer-function preset and isosurface value (in the
/// file's units).
pub struct ModeVolume {
    pub name: String,
    pub path: PathBuf,
    pub tf: String,
    pub iso: f32,
}

/// One mode of one volume.
pub struct ModeRow {
    pub volume: String,
    /// The mode's name (`iso V` with its value in the file's units).
    pub mode: String,
    /// The default frame (the bricked store): median ms and PSNR against the fine ray cast.
    pub splat_ms: f64,
    pub splat_psnr: f64,
    /// The ray caster at the study's step: median ms and PSNR against the fine ray cast.
    pub ray_ms: f64,
    pub ray_psnr: f64,
    /// This volume's composited frames: every voxel as host splats (`--dense`) and the default.
    pub dense_ms: f64,
    pub default_ms: f64,
}

/// The ray caster's step beside the splats, and the reference's.
pub const RAY_STEP: f32 = 0.5;
pub const FINE_STEP: f32 = 0.25;

/// Every mode of each volume at `size`², the framing camera, no shading (the ray caster's
/// reference has none): splat frames alternating mode by mode for `rounds` rounds after a
/// warm-up, ray casts `rounds` times per mode.
/// Returns the rows and the device's name.
pub fn study(volumes: &[ModeVolume], size: u32, rounds: usize) -> Result<(Vec<ModeRow>, String)> {
    let mut rows = Vec::new();
    // One renderer each for the dense set and the bricked store, their scenes replaced per volume.
    let mut dense = Renderer::new(&RendererOptions::default())?;
    let mut bricked = Renderer::new(&RendererOptions::default())?;
    let device = bricked.context().map(|c| c.device_name().to_string()).unwrap_or_else(|| "no device".into());
    for v in volumes {
        let tf = TransferFunction::preset(&v.tf)?;
        // Read once: the dense classification and the bricked store both come from it.
        let vol = voxsplat::loaders::load_volume(&v.path, &Default::default())?;
        let store = BrickStore::build(&vol)?;
        let (lo, hi) = store.range;
        let iso = ((v.iso - lo) / (hi - lo).max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
        let cam = Camera::framing(&store.grid()?, size, size);
        dense.set_scene(voxsplat::classify::classify(&vol, &tf, None)?)?;
        drop(vol);
        bricked.set_bricks(BrickScene::new(store, tf, None)?)?;
        let options = |mode: Mode| {
            let mut o = crate::lab_options();
            o.mode = mode;
            o.iso = (mode == Mode::Iso).then_some(iso);
            o
        };
        // MIP drawing every voxel, not each texel's brightest (`--every-voxel`).
        let every_voxel = || {
            let mut o = options(Mode::Mip);
            o.every_voxel = true;
            o
        };
        // Splat frames: every mode's default frame, the composited frame of every voxel, MIP of
        // every voxel.
        let n = Mode::ALL.len();
        let splat_ms = alternating_medians(n + 2, 1, rounds, |i| {
            if i < n {
                frame_ms(&mut bricked, &cam, &options(Mode::ALL[i]))
            } else if i == n {
                frame_ms(&mut dense, &cam, &options(Mode::Composite))
            } else {
                frame_ms(&mut bricked, &cam, &every_voxel())
            }
        })?;
        for (i, &mode) in Mode::ALL.iter().enumerate() {
            // The ray caster reads a dense set's field; an isosurface, the bricked store's values.
            let caster = if mode == Mode::Iso { &mut bricked } else { &mut dense };
            let cast = |r: &mut Renderer, step: f32| {
                let o = RaycastOptions { mode, iso: options(mode).iso, step, ..Default::default() };
                r.raycast(&cam, &o)
            };
            let fine = cast(caster, FINE_STEP)?.image;
            let mut times = Vec::new();
            let mut image = None;
            for _ in 0..rounds.max(1) + 1 {
                let t = Instant::now();
                image = Some(cast(caster, RAY_STEP)?.image);
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
            let ray_ms = median(&mut times[1..]);
            let ray = image.expect("cast at least once");
            let splats = bricked.render(&cam, &options(mode))?.image;
            let ray_psnr = voxsplat::metrics::compare(&ray, &fine)?.psnr;
            rows.push(ModeRow {
                volume: v.name.clone(),
                mode: if mode == Mode::Iso { format!("iso {}", v.iso) } else { mode.to_string() },
                splat_ms: splat_ms[i],
                splat_psnr: voxsplat::metrics::compare(&splats, &fine)?.psnr,
                ray_ms,
                ray_psnr,
                dense_ms: splat_ms[n],
                default_ms: splat_ms[0],
            });
            if mode == Mode::Mip {
                let every = bricked.render(&cam, &every_voxel())?.image;
                rows.push(ModeRow {
                    volume: v.name.clone(),
                    mode: "mip, every voxel".into(),
                    splat_ms: splat_ms[n + 1],
                    splat_psnr: voxsplat::metrics::compare(&every, &fine)?.psnr,
                    ray_ms,
                    ray_psnr,
                    dense_ms: splat_ms[n],
                    default_ms: splat_ms[0],
                });
            }
        }
    }
    Ok((rows, device))
}

/// One chart per volume in `dir` (`modes-NAME.svg`): each mode's splats and ray caster, frame
/// time against PSNR. Returns the files written.
pub fn charts(rows: &[ModeRow], dir: &Path) -> Result<Vec<PathBuf>> {
    let mut names: Vec<&str> = rows.iter().map(|r| r.volume.as_str()).collect();
    names.dedup();
    let mut written = Vec::new();
    for name in names {
        let mut points = Vec::new();
        for r in rows.iter().filter(|r| r.volume == name) {
            points.push((format!("{} splats", r.mode), r.splat_ms, r.splat_psnr));
            // MIP of every voxel shares MIP's ray caster.
            if r.mode != "mip, every voxel" {
                points.push((format!("{} ray {RAY_STEP}", r.mode), r.ray_ms, r.ray_psnr));
            }
        }
        let path = dir.join(format!("modes-{name}.svg"));
        let title = format!("{name}: each mode, splats and the ray caster in the same mode");
        scatter_svg_higher(&points, &title, &format!("PSNR dB against the ray cast at step {FINE_STEP}"), &path)?;
        written.push(path);
    }
    Ok(written)
}

/// The study's page (docs/bench/modes.md); `charts` are linked by file name.
pub fn markdown(rows: &[ModeRow], device: &str, size: u32, rounds: usize, charts: &[PathBuf]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Rendering modes\n\n`voxsplat-lab modes` ({device}): each mode's default frame (the bricked store; MIP and \
         MinIP draw each texel's brightest voxel, *mip, every voxel* all of them: `--every-voxel`) at {size}², the framing camera, no shading, `--raster auto`, the median of {rounds} frames \
         alternating mode by mode after a warm-up; beside it the ray caster in the same mode at step {RAY_STEP} \
         (median of {rounds}). Both are scored by PSNR against a ray cast at step {FINE_STEP} in that mode \
         (premultiplied RGBA). *Composite, every voxel* draws the same voxels as host splats composited front to \
         back (`--dense`); *composite, default* is the default frame (levels of detail, early termination, hidden \
         bricks). `iso V`: the isosurface at V (the file's units), its surface splats made on the device each frame; \
         its ray caster has no empty-space skipping. One run on this machine: read the ratios.\n"
    );
    let _ = writeln!(
        s,
        "| volume | mode | frame ms | ÷ composite, every voxel | ÷ composite, default | PSNR dB | ray caster ms | \
         ray caster PSNR dB |\n|---|---|---:|---:|---:|---:|---:|---:|"
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.2} | {:.2} | {:.2} | {:.1} | {:.2} |",
            r.volume,
            r.mode,
            r.splat_ms,
            r.splat_ms / r.dense_ms,
            r.splat_ms / r.default_ms,
            r.splat_psnr,
            r.ray_ms,
            r.ray_psnr
        );
    }
    for c in charts {
        let file = c.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
        let _ = writeln!(s, "\n![{file}]({file})");
    }
    s
}
