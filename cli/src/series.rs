//! A volume's time points played as frames (`voxsplat animate --volume`, `voxsplat-lab series`):
//! the series' value range read once, then each time point built as a store normalised by it and
//! swapped into the renderer (`Renderer::update_volume`), which rewrites only the bricks that
//! changed on the device.
use crate::open::*;
use std::path::PathBuf;
use std::time::Instant;
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::loaders::VolumeHints;
use voxsplat::orient::Orientation;
use voxsplat::{Camera, Error, RenderOptions, Renderer, Result};

/// A volume file's time points, each read as a store normalised by the whole series' range (so
/// that one transfer function classifies every time point alike and nothing flickers).
pub struct Series {
    /// The file.
    pub path: PathBuf,
    /// Its time points.
    pub times: u32,
    /// The smallest and largest value over every time point.
    pub range: (f32, f32),
    hints: VolumeHints,
    orientation: Option<Orientation>,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The median of `v` (0 when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

impl Series {
    /// The --volume of `a` as a series (its value range read first, with a progress bar). Flags
    /// that describe something other than a scalar volume's bricked store are refused.
    pub fn open(a: &SceneArgs) -> Result<Self> {
        let path = a.volume.clone().ok_or_else(|| Error::InvalidArgument("a series needs --volume FILE".into()))?;
        let refused = [
            (a.time.is_some(), "--time", "it draws one time point (voxsplat render --time N); animate plays them all"),
            (a.level.as_deref() == Some("auto"), "--level auto", "it picks a level for one view: give --level N"),
            (a.positions.is_some(), "--positions", "a series plays from its bricked store, on a uniform grid"),
            (a.labels.is_some(), "--labels", "a series plays one scalar volume"),
            (!a.channels.is_empty() || !a.channel_tfs.is_empty(), "--channel", "a series plays one scalar volume"),
        ];
        if let Some((_, flag, why)) = refused.iter().find(|r| r.0) {
            return Err(Error::InvalidArgument(format!("{flag} with a series: {why}")));
        }
        let times = voxsplat::loaders::time_points(&path)?;
        if times < 2 {
            return Err(Error::InvalidArgument(format!(
                "{}: one volume, no time axis: a series is a 4-D NIfTI or an OME-Zarr image with a time axis \
                 (voxsplat render draws one volume)",
                path.display()
            )));
        }
        let mut hints = volume_hints(a)?;
        if voxsplat::loaders::is_ome_zarr(&path) {
            // One view: where it sees part of the image, each time point reads only that part, as
            // `render` reads one.
            if let Some((seen, camera)) = crate::pyramid::seen_box(a, &path)? {
                (hints.crop, hints.view) = (Some(seen), Some(camera));
            }
            if hints.level.is_none() {
                let image = voxsplat::loaders::OmeZarr::open(&path)?;
                let level = match hints.crop {
                    None => image.default_level(),
                    Some(crop) => image.default_level_within(Some(crop), hints.view.as_ref()).ok_or_else(|| {
                        Error::InvalidArgument(format!("{}: the view sees none of the image", path.display()))
                    })?,
                };
                if level > 0 {
                    eprintln!("OME-Zarr level {level} drawn: the finer ones may not fit the host's memory (--level N)");
                }
                hints.level = Some(level);
            }
        }
        let chunks = voxsplat::loaders::zarr_chunks_read();
        let bar = indicatif::ProgressBar::new(times as u64).with_message("the series' value range");
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for t in 0..times {
            let (l, h) = voxsplat::loaders::value_range(&path, &VolumeHints { time: Some(t), ..hints.clone() })?;
            (lo, hi) = (lo.min(l), hi.max(h));
            bar.inc(1);
        }
        bar.finish_and_clear();
        if hints.crop.is_some() {
            let read = voxsplat::loaders::zarr_chunks_read() - chunks;
            eprintln!("OME-Zarr: the value range read {read} chunks over {times} time points");
        }
        let range = voxsplat::bricks::store_range(lo, hi);
        Ok(Self { path, times, range, hints, orientation: orientation_of(a)? })
    }

    /// The file's placement in patient space (`None`: no anatomical frame).
    pub fn orientation(&self) -> Option<Orientation> {
        self.orientation
    }

    /// Time point `t` as a store normalised by the series' range, placed as the file places it.
    pub fn store(&self, t: u32) -> Result<BrickStore> {
        let hints = VolumeHints { time: Some(t), ..self.hints.clone() };
        let (mut store, _) = BrickStore::load_in_range(&self.path, &hints, self.range)?;
        if let Some(o) = &self.orientation {
            store.place(o)?;
        }
        Ok(store)
    }

    /// Time point `t` as a scene classified by --tf, shaded as `render` shades the file.
    pub fn scene(&self, a: &SceneArgs, t: u32) -> Result<BrickScene> {
        let store = self.store(t)?;
        let shading = headlight(a, store.dims, store.spacing, self.orientation);
        BrickScene::new(store, transfer_function(a)?, shading)
    }

    /// A renderer (`a`'s backend and budget) holding time point 0, and the camera of --view
    /// framed on what time point 0 shows.
    pub fn first(&self, a: &SceneArgs) -> Result<(Renderer, Camera)> {
        let scene = self.scene(a, 0)?;
        let content = Content { orientation: self.orientation, bounds: scene.visible_bounds() };
        let camera = camera_of(a, &scene.store.grid()?, &content)?;
        let mut r = renderer_of(a)?;
        r.set_bricks(scene)?;
        Ok((r, camera))
    }
}

/// `voxsplat animate --volume`: every time point drawn with `opts` from one view, each frame
/// handed to `frame(t, image)`; the timings and what the device was sent, as a report.
pub fn play(
    a: &SceneArgs,
    opts: &RenderOptions,
    mut frame: impl FnMut(u32, &voxsplat::image::ImageF32) -> Result<()>,
) -> Result<String> {
    let series = Series::open(a)?;
    let chunks = voxsplat::loaders::zarr_chunks_read();
    let (mut r, cam) = series.first(a)?;
    let bar = indicatif::ProgressBar::new(series.times as u64);
    let (mut frames, mut reads, mut swaps) = (Vec::new(), Vec::new(), Vec::new());
    let (mut changed, mut written, mut whole, mut bricks) = (0usize, 0u64, 0u64, 0usize);
    for t in 0..series.times {
        if t > 0 {
            let t0 = Instant::now();
            let store = series.store(t)?;
            reads.push(ms(t0));
            let t0 = Instant::now();
            let u = r.update_volume(store)?;
            swaps.push(ms(t0));
            (changed, written, whole, bricks) =
                (changed + u.changed, written + u.uploaded, whole + u.store_bytes, bricks + u.bricks);
        }
        let t0 = Instant::now();
        let img = r.render(&cam, opts)?.image;
        frames.push(ms(t0));
        frame(t, &img)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    report_validation(&r)?;
    let mib = |b: u64| b as f64 / (1 << 20) as f64;
    let read = voxsplat::loaders::zarr_chunks_read() - chunks;
    let chunks = if voxsplat::loaders::is_ome_zarr(&series.path) {
        format!("; {:.0} OME-Zarr chunks read per time point", read as f64 / series.times as f64)
    } else {
        String::new()
    };
    let sent = if a.cpu {
        String::new()
    } else {
        format!(
            "; {:.2} MiB written to the device, where setting each time point afresh would send {:.2} MiB",
            mib(written),
            mib(whole)
        )
    };
    Ok(format!(
        "{} time points (values {:?} over the series): a frame {:.1} ms, reading a time point {:.1} ms, swapping it in \
         {:.2} ms (medians); per time point {:.0} bricks changed (their voxels, or appeared or went empty), {:.0} non-empty \
         (means){chunks}{sent}",
        series.times,
        series.range,
        median(frames),
        median(reads),
        median(swaps),
        changed as f64 / (series.times - 1) as f64,
        bricks as f64 / (series.times - 1) as f64,
    ))
}

/// `voxsplat-lab series`: per time point after the first, swapping it into a renderer that holds
/// the last (`update_volume`) against setting it afresh on another (`set_bricks`, as a program
/// without `update_volume` would), each followed by two frames (the first derives what the new
/// values need: levels of detail, gradients); alternated time point by time point so drift falls
/// on both. Reading the time point is left out of both; making the scene (its k-d tree) is in
/// both. A markdown table of medians.
pub fn study(a: &SceneArgs) -> Result<String> {
    let series = Series::open(a)?;
    let (mut played, cam) = series.first(a)?;
    let mut fresh = renderer_of(a)?;
    let opts = RenderOptions::default();
    fresh.set_bricks(series.scene(a, 0)?)?;
    played.render(&cam, &opts)?;
    fresh.render(&cam, &opts)?;
    let mut rows = [[(); 3].map(|_| Vec::new()), [(); 3].map(|_| Vec::new())];
    let (mut written, mut whole, mut changed, mut bricks) = (0u64, 0u64, 0usize, 0usize);
    let bar = indicatif::ProgressBar::new(series.times as u64 - 1);
    for t in 1..series.times {
        let store = series.store(t)?;
        let t0 = Instant::now();
        let u = played.update_volume(store)?;
        rows[0][0].push(ms(t0));
        (written, whole, changed, bricks) =
            (written + u.uploaded, whole + u.store_bytes, changed + u.changed, bricks + u.bricks);
        let store = series.store(t)?;
        let t0 = Instant::now();
        let shading = headlight(a, store.dims, store.spacing, series.orientation);
        fresh.set_bricks(BrickScene::new(store, transfer_function(a)?, shading)?)?;
        rows[1][0].push(ms(t0));
        for (r, row) in [&mut played, &mut fresh].into_iter().zip(rows.iter_mut()) {
            for times in &mut row[1..] {
                let t0 = Instant::now();
                r.render(&cam, &opts)?;
                times.push(ms(t0));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    report_validation(&played)?;
    report_validation(&fresh)?;
    let [p, f] = rows.map(|r| r.map(median));
    let mib = |b: u64| b as f64 / (1 << 20) as f64;
    let n = series.times - 1;
    Ok(format!(
        "{} time points of {}, {}x{}, {}: medians over the {n} after the first\n\n\
         | | swap in (ms) | first frame (ms) | next frame (ms) | swap + first frame (ms) | MiB sent per time point |\n\
         |---|---:|---:|---:|---:|---:|\n\
         | update_volume | {:.2} | {:.1} | {:.1} | {:.1} | {:.3} |\n\
         | set_bricks afresh | {:.2} | {:.1} | {:.1} | {:.1} | {:.3} |\n\n\
         played / afresh: first frame {:.2}x, next frame {:.2}x, swap + first frame {:.2}x; per time point {:.0} \
         bricks changed (their voxels, or appeared or went empty), {:.0} non-empty (means)\n",
        series.times,
        series.path.display(),
        a.size.0,
        a.size.1,
        played.device_name(),
        p[0],
        p[1],
        p[2],
        p[0] + p[1],
        mib(written) / n as f64,
        f[0],
        f[1],
        f[2],
        f[0] + f[1],
        mib(whole) / n as f64,
        p[1] / f[1],
        p[2] / f[2],
        (p[0] + p[1]) / (f[0] + f[1]),
        changed as f64 / n as f64,
        bricks as f64 / n as f64,
    ))
}
