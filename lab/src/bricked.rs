//! The bricked-volume study: what a volume costs as a bricked store and what a frame
//! costs from it, alternating the variants frame by frame in one process (`voxsplat-lab bricks`).
//! Prints a markdown section for docs/RESULTS.md.
use crate::bench::median;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;
use voxsplat::bricks::{BrickScene, BrickStore};
use voxsplat::classify::{classify, TransferFunction};
use voxsplat::{options::Raster, order::Direction, Camera, Error, RenderOptions, Renderer, RendererOptions, Result};

pub use voxsplat_cli::measure::peak_rss_mib;

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The wall time of one frame, ms.
pub fn frame_ms(r: &mut Renderer, cam: &Camera, o: &RenderOptions) -> Result<f64> {
    let t = Instant::now();
    r.render(cam, o)?;
    Ok(ms(t))
}

/// A loaded volume as a bricked scene, with its load and build times.
pub struct Loaded {
    pub scene: BrickScene,
    /// Reading the file and building the store (an uncompressed NRRD streams slice by slice).
    pub load_ms: f64,
    pub voxels: u64,
}

pub fn load(path: &Path, tf: &TransferFunction) -> Result<Loaded> {
    let t = Instant::now();
    let store = BrickStore::load(path, &Default::default())?;
    let load_ms = ms(t);
    let voxels = store.dims.iter().map(|&d| d as u64).product();
    Ok(Loaded { scene: BrickScene::new(store, tf.clone(), None)?, load_ms, voxels })
}

fn renderer() -> Result<Renderer> {
    Renderer::new(&RendererOptions::default())
}

fn opts(early_termination: f32) -> RenderOptions {
    let mut o = crate::lab_options();
    (o.raster, o.direction, o.early_termination) = (Raster::Compute, Some(Direction::FrontToBack), early_termination);
    // Full detail unless a variant asks for levels of detail.
    o.lod = voxsplat::options::Lod::Off;
    o
}

/// The study on `bonsai` (256³) and, when given, its 2x upsampling `large` (512³), `frames`
/// rounds each, at `size`².
pub fn study(
    bonsai: &Path,
    large: Option<&Path>,
    size: u32,
    frames: usize,
    lod_chart: Option<&Path>,
) -> Result<String> {
    let tf = TransferFunction::preset("bonsai")?;
    let small = load(bonsai, &tf)?;
    let grid = small.scene.store.grid()?;
    let cam = Camera::framing(&grid, size, size);
    let mut s = String::new();
    let _ = writeln!(s, "## Bricked volumes\n");
    let _ = writeln!(
        s,
        "`voxsplat-lab bricks`, one process, {size}², the framing view, tile compositor front to back; every \
         variant of a pair alternates frame by frame, {frames} rounds after a warm-up frame; medians.\n"
    );
    let _ = writeln!(s, "| volume | voxels | stored | bricks | GPU bytes / stored voxel | load + bricks ms |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    let row = |s: &mut String, name: &str, l: &Loaded| {
        let st = &l.scene.store;
        let _ = writeln!(
            s,
            "| {name} | {} | {} | {} | {:.2} | {:.0} |",
            l.voxels,
            st.len(),
            st.headers.len(),
            st.bytes() as f64 / st.len().max(1) as f64,
            l.load_ms,
        );
    };
    row(&mut s, "bonsai 256³", &small);
    let large = large.map(|p| load(p, &tf)).transpose()?;
    if let Some(l) = &large {
        row(&mut s, "bonsai 512³ (2x upsampled)", l);
    }

    // Dense classified splats against the bricked store, and a TF change against a plain frame.
    let vol = voxsplat::loaders::load_volume(bonsai, &Default::default())?;
    let mut dense = renderer()?;
    dense.set_scene(classify(&vol, &tf, None)?)?;
    drop(vol);
    let mut bricked = renderer()?;
    bricked.set_bricks(small.scene.clone())?;
    let other = TransferFunction::preset("ct")?;
    let o = opts(0.0);
    let a = dense.render(&cam, &o)?.image;
    let b = bricked.render(&cam, &o)?.image;
    let m = voxsplat::metrics::compare(&a, &b)?;
    frame_ms(&mut bricked, &cam, &o)?;
    let mut with_lod = o.clone();
    (with_lod.lod, with_lod.lod_pixels) = (voxsplat::options::Lod::Auto, 1.0);
    frame_ms(&mut bricked, &cam, &with_lod)?;
    let (mut t_dense, mut t_bricked, mut t_tf) = (Vec::new(), Vec::new(), Vec::new());
    let (mut t_lod, mut t_tf_lod) = (Vec::new(), Vec::new());
    // A TF change, then the frame it gives (alternating two transfer functions), then back.
    let tf_change = |r: &mut Renderer, o: &RenderOptions, i: usize| -> Result<f64> {
        let t = Instant::now();
        r.set_transfer_function(if i.is_multiple_of(2) { &other } else { &tf }, None)?;
        r.render(&cam, o)?;
        let spent = ms(t);
        r.set_transfer_function(&tf, None)?;
        Ok(spent)
    };
    for i in 0..frames {
        t_dense.push(frame_ms(&mut dense, &cam, &o)?);
        t_bricked.push(frame_ms(&mut bricked, &cam, &o)?);
        t_tf.push(tf_change(&mut bricked, &o, i)?);
        // With levels of detail a TF change rebuilds the pyramid too: a plain LOD frame after one
        // that rebuilt it, then a TF change and its LOD frame.
        bricked.render(&cam, &with_lod)?;
        t_lod.push(frame_ms(&mut bricked, &cam, &with_lod)?);
        t_tf_lod.push(tf_change(&mut bricked, &with_lod, i)?);
    }
    let (d, b, t) = (median(&mut t_dense), median(&mut t_bricked), median(&mut t_tf));
    let (tl, ttl) = (median(&mut t_lod), median(&mut t_tf_lod));
    let _ = writeln!(s, "\n| bonsai 256³ frame | median ms | ratio |");
    let _ = writeln!(s, "|---|---|---|");
    let _ = writeln!(s, "| dense classified splats (`--dense`) | {d:.0} | 1.00 |");
    let _ = writeln!(s, "| bricked store, classified on the device | {b:.0} | {:.2} |", b / d);
    let _ = writeln!(s, "| bricked, a TF change then its frame | {t:.0} | {:.2} of the bricked frame |", t / b);
    let _ = writeln!(s, "| bricked, LOD auto (1 px) | {tl:.0} | {:.2} |", tl / d);
    let _ = writeln!(
        s,
        "| bricked, LOD auto, a TF change (pyramid rebuilt) then its frame | {ttl:.0} | {:.2} of the LOD frame |",
        ttl / tl
    );
    let _ = writeln!(
        s,
        "\nBricked against dense, same view: {:.1} dB PSNR, largest difference {:.4} (the same splats in \
         another valid visibility order, and values quantised to 16 bits).",
        m.psnr, m.max_abs
    );

    // Hidden bricks, front to back with early termination.
    let et = opts(voxsplat::options::DEFAULT_EARLY_TERMINATION);
    let mut keep = et.clone();
    keep.cull_hidden_bricks = false;
    frame_ms(&mut bricked, &cam, &et)?;
    let (mut culled, mut kept) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        culled.push(frame_ms(&mut bricked, &cam, &et)?);
        kept.push(frame_ms(&mut bricked, &cam, &keep)?);
    }
    let (c, k) = (median(&mut culled), median(&mut kept));
    let _ = writeln!(
        s,
        "\nEarly termination at 1/1024, front to back: dropping hidden bricks between batches {c:.0} ms, keeping \
         them {k:.0} ms ({:.2}x; the same frame).",
        k / c
    );

    // The sheet modes over the bricks against the same modes over dense splats.
    let _ = writeln!(s, "\n| bonsai 256³, compute raster | dense ms | bricked ms | bricked / dense | PSNR dB |");
    let _ = writeln!(s, "|---|---|---|---|---|");
    for composite in [voxsplat::options::Composite::Sheet, voxsplat::options::Composite::Slab] {
        let mut so = o.clone();
        so.composite = composite;
        let a = dense.render(&cam, &so)?.image;
        let b = bricked.render(&cam, &so)?.image;
        let m = voxsplat::metrics::compare(&a, &b)?;
        let (mut td, mut tb) = (Vec::new(), Vec::new());
        for _ in 0..frames {
            td.push(frame_ms(&mut dense, &cam, &so)?);
            tb.push(frame_ms(&mut bricked, &cam, &so)?);
        }
        let (d, b) = (median(&mut td), median(&mut tb));
        let _ = writeln!(s, "| {composite:?} | {d:.0} | {b:.0} | {:.2} | {:.1} |", b / d, m.psnr);
    }

    if let Some(l) = large {
        let lgrid = l.scene.store.grid()?;
        let lcam = Camera::framing(&lgrid, size, size);
        let mut big = renderer()?;
        big.set_bricks(l.scene)?;
        let lod = |pixels: f32, error: f32| {
            let mut x = o.clone();
            (x.lod, x.lod_pixels, x.lod_error) = (voxsplat::options::Lod::Auto, pixels, error);
            x
        };
        let default_error = voxsplat::options::DEFAULT_LOD_ERROR;
        let lod1 = lod(1.0, default_error);
        // The 512³ levels of detail: the default bound at 1 and 1.5 px (like for like with the
        // 256³ voxels, below), and at 1.5 px the looser bound of issue 23's measurement.
        let big_lods = [(1.0, default_error), (1.5, default_error), (1.5, 0.25)].map(|(p, e)| (p, e, lod(p, e)));
        // Warm-up frames (the pyramids are built here, once per classification), and each frame's
        // distance from full detail.
        let full_small = bricked.render(&cam, &o)?.image;
        let full_big = big.render(&lcam, &o)?.image;
        let psnr = |a: &voxsplat::image::ImageF32, b: &voxsplat::image::ImageF32| {
            voxsplat::metrics::compare(a, b).map(|m| m.covered_psnr)
        };
        let p_small = psnr(&full_small, &bricked.render(&cam, &lod1)?.image)?;
        let mut p_big = Vec::new();
        for (_, _, x) in &big_lods {
            p_big.push(psnr(&full_big, &big.render(&lcam, x)?.image)?);
        }
        let mut t: Vec<Vec<f64>> = vec![Vec::new(); 4 + big_lods.len()];
        for _ in 0..frames {
            t[0].push(frame_ms(&mut bricked, &cam, &o)?);
            t[1].push(frame_ms(&mut bricked, &cam, &lod1)?);
            t[2].push(frame_ms(&mut big, &lcam, &o)?);
            t[3].push(frame_ms(&mut big, &lcam, &et)?);
            for (k, (_, _, x)) in big_lods.iter().enumerate() {
                t[4 + k].push(frame_ms(&mut big, &lcam, x)?);
            }
        }
        // The sheets at 512³ stream (the visible voxels pass one batch): once, after the others.
        let mut so = o.clone();
        so.composite = voxsplat::options::Composite::Sheet;
        let sheet = frame_ms(&mut big, &lcam, &so)?;
        let m: Vec<f64> = t.iter_mut().map(|v| median(v)).collect();
        let (sm, sl, bg, be) = (m[0], m[1], m[2], m[3]);
        let _ = writeln!(
            s,
            "\n| frame, same view | median ms | over the 256³ full-detail frame | over the 256³ frame, same options \
             | PSNR dB against its full detail (covered pixels) |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|");
        let _ = writeln!(s, "| bonsai 256³ bricked | {sm:.0} | 1.00 | 1.00 | |");
        let _ = writeln!(
            s,
            "| bonsai 256³ bricked, LOD auto 1 px, error {default_error} | {sl:.0} | {:.2} | 1.00 | {p_small:.1} |",
            sl / sm
        );
        let _ = writeln!(s, "| bonsai 512³ bricked | {bg:.0} | {:.2} | {:.2} | |", bg / sm, bg / sm);
        let _ = writeln!(
            s,
            "| bonsai 512³ bricked, early termination 1/1024 | {be:.0} | {:.2} | {:.2} | |",
            be / sm,
            be / sm
        );
        for (k, (pixels, error, _)) in big_lods.iter().enumerate() {
            let bl = m[4 + k];
            let _ = writeln!(
                s,
                "| bonsai 512³ bricked, LOD auto {pixels} px, error {error} | {bl:.0} | {:.2} | {:.2} | {:.1} |",
                bl / sm,
                bl / sl,
                p_big[k]
            );
        }
        let _ =
            writeln!(s, "| bonsai 512³ bricked, sheets streamed (one frame) | {sheet:.0} | {:.2} | | |", sheet / sm);
    }
    s += &lod_peer(256, size, frames, lod_chart)?;
    if let Some(rss) = peak_rss_mib() {
        let _ = writeln!(s, "\nPeak resident set of the whole study process: {rss:.0} MiB.");
    }
    Ok(s)
}

/// A GPU renderer within `budget_bytes` holding `scene`, and its framing camera at `size`².
fn framed(scene: voxsplat::bricks::BrickScene, size: u32, budget_bytes: u64) -> Result<(Renderer, Camera)> {
    let cam = Camera::framing(&scene.store.grid()?, size, size);
    let mut o = RendererOptions::default();
    o.gpu_budget_bytes = Some(budget_bytes);
    let mut r = Renderer::new(&o)?;
    r.set_bricks(scene)?;
    Ok((r, cam))
}

/// Load `path` as a bricked scene with the transfer-function preset `tf` and draw `frames` frames
/// (after a warm-up) on the GPU within `budget_bytes`: one line with the load time, the store, the
/// median frame and the peak resident set (run one file per process for the memory target).
pub fn one_volume(path: &Path, size: u32, budget_bytes: u64, tf: &str, frames: usize) -> Result<String> {
    let tf = TransferFunction::preset(tf)?;
    let l = load(path, &tf)?;
    let rss_loaded = peak_rss_mib().unwrap_or(0.0);
    let (stored, bytes) = (l.scene.store.len(), l.scene.store.bytes());
    let (mut r, cam) = framed(l.scene, size, budget_bytes)?;
    // Full detail and levels of detail (1 px), alternating frame by frame after a warm-up each: what
    // `render --raster compute --direction ftb` draws (its kernel, early termination), the frames
    // docs/RESULTS.md sets beside VTK's.
    let mut full = RenderOptions::default();
    (full.raster, full.direction, full.lod) =
        (Raster::Compute, Some(Direction::FrontToBack), voxsplat::options::Lod::Off);
    let mut lod = full.clone();
    (lod.lod, lod.lod_pixels) = (voxsplat::options::Lod::Auto, 1.0);
    let reference = r.render(&cam, &full)?.image;
    let psnr = voxsplat::metrics::compare(&r.render(&cam, &lod)?.image, &reference)?.covered_psnr;
    let (mut times, mut lod_times) = (Vec::new(), Vec::new());
    for _ in 0..frames.max(1) {
        times.push(frame_ms(&mut r, &cam, &full)?);
        lod_times.push(frame_ms(&mut r, &cam, &lod)?);
    }
    let rss = peak_rss_mib().ok_or_else(|| Error::Unsupported("no /proc/self/status".into()))?;
    Ok(format!(
        "{}: {} voxels ({:.0} MiB at one byte each), {stored} stored ({:.0} MiB store), load and bricks {:.0} ms, \
         median frame {:.0} ms, levels of detail (1 px) {:.0} ms at {psnr:.1} dB against full detail, peak RSS \
         {rss_loaded:.0} MiB after loading, {rss:.0} MiB after the frames",
        path.display(),
        l.voxels,
        l.voxels as f64 / 1048576.0,
        bytes as f64 / 1048576.0,
        l.load_ms,
        median(&mut times),
        median(&mut lod_times),
    ))
}

/// An orbit's path: `steps` equal steps over `degrees` about the framing camera's up axis.
#[derive(Clone, Copy, Debug)]
pub struct Arc {
    /// Frames drawn, the first from the framing camera.
    pub steps: u32,
    /// Degrees turned over all of them (360: each step turns 360 / steps).
    pub degrees: f32,
}

impl Arc {
    /// The steps, when they and the degrees are in range.
    fn check(&self) -> Result<u32> {
        if !(1..=3600).contains(&self.steps) {
            return Err(Error::InvalidArgument(format!("--orbit {}: between 1 and 3600 steps", self.steps)));
        }
        if !(self.degrees > 0.0 && self.degrees <= 360.0) {
            return Err(Error::InvalidArgument(format!("--arc {}: above 0 and at most 360 degrees", self.degrees)));
        }
        Ok(self.steps)
    }

    /// The angle of step `i`, radians.
    fn angle(&self, i: u32) -> f32 {
        i as f32 * self.degrees.to_radians() / self.steps as f32
    }

    /// `cam` turned to step `i` about its up axis through its target.
    fn camera(&self, cam: &Camera, i: u32) -> Camera {
        let turn = glam::Quat::from_axis_angle(cam.up.normalize(), self.angle(i));
        Camera { eye: cam.target + turn * (cam.eye - cam.target), ..*cam }
    }
}

/// Orbit `path` (preset `tf`) along `arc` about its framing camera's up axis at the
/// default settings within `budget_bytes`: per frame its time, splats, and the bytes of brick
/// records it uploaded against those the record cache holds after it (a streamed store); then the
/// largest fraction after the first frame. A markdown table on stdout.
pub fn orbit(path: &Path, size: u32, budget_bytes: u64, tf: &str, arc: Arc) -> Result<String> {
    let steps = arc.check()?;
    let tf = TransferFunction::preset(tf)?;
    let (mut r, cam) = framed(load(path, &tf)?.scene, size, budget_bytes)?;
    let opts = RenderOptions::default();
    let mut out = String::from(
        "| frame | degrees | ms | splats | record MiB uploaded | record MiB held | uploaded / held |\n|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut worst = 0.0f64;
    for i in 0..steps {
        let (angle, c) = (arc.angle(i), arc.camera(&cam, i));
        let t = Instant::now();
        let st = r.render(&c, &opts)?.stats;
        let (up, held) = (st.bytes_uploaded as f64, st.records_resident as f64);
        let fraction = if held > 0.0 { up / held } else { 0.0 };
        if i > 0 {
            worst = worst.max(fraction);
        }
        out += &format!(
            "| {i} | {:.0} | {:.0} | {} | {:.1} | {:.1} | {:.3} |\n",
            angle.to_degrees(),
            ms(t),
            st.splats,
            up / 1048576.0,
            held / 1048576.0,
            fraction
        );
    }
    out += &format!("\nlargest upload after the first frame: {:.1} % of the records held\n", worst * 100.0);
    Ok(out)
}

/// The error bounds of the levels-of-detail curve on peer256.
const LOD_CURVE_ERRORS: [f32; 5] = [0.003, 0.01, 0.02, 0.05, 0.25];

/// Levels of detail on the peers' volume (the peer256 target): `n`³ at `size`², the peers'
/// camera and transfer function, the bricked store at full detail and with levels of detail over
/// an error sweep (the LOD curve), against the peers' truth (scalar ray integration, step 0.25
/// voxel), alternated frame by frame over `frames` rounds; the dense classified splats beside them.
/// The levels-of-detail curve (pixel test off, error swept) goes on a chart at `chart`.
pub fn lod_peer(n: u32, size: u32, frames: usize, chart: Option<&Path>) -> Result<String> {
    let vol = voxsplat::scene::peer::volume(n)?;
    let tf = voxsplat::scene::peer::transfer_function();
    let camera = voxsplat::scene::peer::camera(n, size);
    let truth = voxsplat::truth::ray_integrate_scalars(&vol, &tf, &camera, 0.25)?;
    let mut dense = renderer()?;
    dense.set_scene(classify(&vol, &tf, None)?)?;
    let mut bricked = renderer()?;
    bricked.set_bricks(BrickScene::new(BrickStore::build(&vol)?, tf, None)?)?;
    drop(vol);
    let mut o = crate::lab_options();
    (o.raster, o.lod) = (Raster::Compute, voxsplat::options::Lod::Off);
    let mut variants: Vec<(String, bool, RenderOptions)> =
        vec![("dense classified splats".into(), true, o.clone()), ("bricked, full detail".into(), false, o.clone())];
    let unbounded = crate::bench::LOD_UNBOUNDED;
    let any = crate::bench::LOD_ANY_ERROR;
    let mut lods = vec![(1.0, 0.25), (1.0, any), (1.5, 0.25), (2.0, 0.25), (4.0, 0.25)];
    lods.extend(LOD_CURVE_ERRORS.iter().map(|&e| (unbounded, e)));
    for (pixels, error) in lods {
        let mut x = o.clone();
        (x.lod, x.lod_pixels, x.lod_error) = (voxsplat::options::Lod::Auto, pixels, error);
        let e = if error >= any { "unbounded".to_string() } else { format!("{error}") };
        let name = if pixels >= unbounded {
            format!("{} {error}", crate::bench::LOD_CURVE)
        } else {
            format!("bricked, LOD auto {pixels} px, error {e}")
        };
        variants.push((name, false, x));
    }
    let mut images = Vec::new();
    for (_, is_dense, x) in &variants {
        let r = if *is_dense { &mut dense } else { &mut bricked };
        images.push(r.render(&camera, x)?.image);
    }
    let mut times = vec![Vec::new(); variants.len()];
    for _ in 0..frames {
        for (t, (_, is_dense, x)) in times.iter_mut().zip(&variants) {
            t.push(frame_ms(if *is_dense { &mut dense } else { &mut bricked }, &camera, x)?);
        }
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n### Levels of detail on peer{n}\n\nThe peers' volume, camera and transfer function, {size}², tile \
         compositor; PSNR against the peers' truth (scalar ray integration, step 0.25 voxel); every variant alternates \
         frame by frame, {frames} rounds after a warm-up; medians.\n"
    );
    let _ =
        writeln!(s, "| variant | median ms | over bricked full detail | PSNR dB against the truth (covered pixels) |");
    let _ = writeln!(s, "|---|---:|---:|---:|");
    let medians: Vec<f64> = times.iter_mut().map(|t| median(t)).collect();
    let mut points = Vec::new();
    for (((name, _, _), image), ms) in variants.iter().zip(&images).zip(&medians) {
        let m = voxsplat::metrics::compare(image, &truth)?;
        let _ = writeln!(s, "| {name} | {ms:.0} | {:.2} | {:.2} |", ms / medians[1], m.covered_psnr);
        points.push((name.clone(), *ms, m.covered_psnr));
    }
    if let Some(path) = chart {
        let title = format!("peer{n}, {size}²: frame time against PSNR (higher is better)");
        crate::bench::scatter_svg_higher(&points, &title, "PSNR dB against the truth", path)?;
        let file = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
        let _ = writeln!(s, "\n![levels of detail on peer{n}](bench/{file})");
    }
    Ok(s)
}

/// Orbit the OME-Zarr image `path` along `arc` about its framing camera's up axis, the view
/// narrowed to `fov` degrees so each sees part of the image: every frame's store is read for that
/// view alone (`VolumeHints::crop` and `view`: the chunks it may see, at the finest level whose
/// part fits the host budget), through one chunk cache of `cache_bytes` (0: none), then drawn at
/// the default settings within `budget_bytes`. Per frame the level, the chunks read from the file
/// and those the cache held, the load time (the store read and handed to the renderer) and the
/// frame time; a markdown table on stdout.
pub fn zarr_orbit(
    path: &Path,
    size: u32,
    budget_bytes: u64,
    tf: &str,
    arc: Arc,
    fov: f32,
    cache_bytes: u64,
) -> Result<String> {
    use voxsplat::loaders::{ChunkCache, OmeZarr, VolumeHints, VIEW_MARGIN_PX};
    let steps = arc.check()?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(Error::InvalidArgument(format!("--fov {fov}: between 0 and 180 degrees")));
    }
    let tf = TransferFunction::preset(tf)?;
    let image = OmeZarr::open(path)?;
    let l = &image.levels[0];
    let grid = voxsplat::Grid::centered(l.dims, l.spacing)?;
    let half = voxsplat::glam::Vec3::from(l.dims.map(|d| d as f32)) * voxsplat::glam::Vec3::from(l.spacing) * 0.5;
    let mut cam = Camera::framing(&grid, size, size);
    cam.projection = voxsplat::camera::Projection::Perspective { fov_y_deg: fov };
    let cache = (cache_bytes > 0).then(|| ChunkCache::new(cache_bytes)).transpose()?;
    let mut o = RendererOptions::default();
    o.gpu_budget_bytes = Some(budget_bytes);
    let mut r = Renderer::new(&o)?;
    let mut out = String::from(
        "| frame | degrees | level | chunks read | chunks held, reused | load ms | frame ms | splats |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let (mut read_total, mut loads, mut frames) = (0u64, Vec::new(), Vec::new());
    let bar = indicatif::ProgressBar::new(steps as u64);
    for i in 0..steps {
        let (angle, c) = (arc.angle(i), arc.camera(&cam, i));
        let Some([lo, hi]) = c.box_in_view(-half, half, VIEW_MARGIN_PX) else {
            return Err(Error::InvalidArgument(format!("{}: the view at step {i} sees none of it", path.display())));
        };
        let crop = [lo.to_array(), hi.to_array()];
        let level = image.default_level_within(Some(crop), Some(&c)).ok_or_else(|| {
            Error::InvalidArgument(format!("{}: the view at step {i} sees none of it", path.display()))
        })?;
        let hints = VolumeHints {
            level: Some(level),
            crop: Some(crop),
            view: Some(c),
            chunk_cache: cache.clone(),
            ..Default::default()
        };
        let (before, chunks) =
            (cache.as_ref().map(|c| c.stats()).unwrap_or_default(), voxsplat::loaders::zarr_chunks_read());
        let t = Instant::now();
        let store = BrickStore::load(path, &hints)?;
        r.set_bricks(BrickScene::new(store, tf.clone(), None)?)?;
        loads.push(ms(t));
        let read = voxsplat::loaders::zarr_chunks_read() - chunks;
        let hits = cache.as_ref().map_or(0, |c| c.stats().hits - before.hits);
        read_total += read;
        let t = Instant::now();
        let st = r.render(&c, &RenderOptions::default())?.stats;
        frames.push(ms(t));
        let (load_ms, frame_ms) = (loads[i as usize], frames[i as usize]);
        out += &format!(
            "| {i} | {:.0} | {level} | {read} | {hits} | {load_ms:.0} | {frame_ms:.0} | {} |\n",
            angle.to_degrees(),
            st.splats
        );
        bar.inc(1);
    }
    bar.finish_and_clear();
    let held = cache.as_ref().map_or(0, |c| c.stats().held_bytes);
    out += &format!(
        "\n{read_total} chunks read in {steps} frames; median load {:.0} ms, median frame {:.0} ms; the chunk cache \
         ({} MiB) holds {:.0} MiB\n",
        median(&mut loads),
        median(&mut frames),
        cache_bytes >> 20,
        held as f64 / 1048576.0
    );
    Ok(out)
}
