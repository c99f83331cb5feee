//! `voxsplat render`: one frame of a built-in scene, a volume file or a terrain, to PNG or EXR;
//! under mpirun (feature `mpi`), one box of the volume per rank.
use crate::open::*;
use crate::{print, println};
use clap::Args;
use glam::Vec3;
use std::path::PathBuf;
use voxsplat::{
    kernel::Kernel, options::Composite, order::Direction, order::OrderKind, scene, Error, RenderOptions, Result,
};

mod research;
pub use research::Research;

#[derive(Args)]
pub struct RenderArgs {
    /// The research switches (`voxsplat-lab render`); their defaults under `voxsplat render`.
    #[arg(skip)]
    pub research: Research,
    #[command(flatten)]
    pub scene: SceneArgs,
    /// A clipping plane NX,NY,NZ,D in world space: what lies where NX x + NY y + NZ z + D < 0 is
    /// not drawn (splat centres; the ray caster cuts its rays). Up to 6.
    #[arg(help_heading = "View", long = "clip", value_parser = parse_floats::<4>, allow_hyphen_values = true)]
    pub clip: Vec<[f32; 4]>,
    /// A crop box X0,Y0,Z0,X1,Y1,Z1 in world space: only what lies inside is drawn. An OME-Zarr
    /// image reads only the chunks the box needs, from the finest level whose part fits the host's
    /// memory, its values normalised by their own range.
    #[arg(help_heading = "View", long, value_parser = parse_floats::<6>, allow_hyphen_values = true)]
    pub crop: Option<[f32; 6]>,
    /// Composite the frame over this colour R,G,B[,A] (each in [0, 1]; A defaults to 1, opaque), as
    /// a window shows it; without it the PNG is transparent where nothing was drawn.
    #[arg(help_heading = "Transfer function and mode", long, value_parser = parse_background)]
    pub background: Option<[f32; 4]>,
    /// What each pixel shows of its ray: emission and absorption composited in order (the default);
    /// the largest value (mip) or the smallest (minip), each mapped through --colormap; the mean
    /// value (average); an X-ray (the extinction summed along the ray, a radiograph); or the
    /// surface where the values cross --iso (iso: shaded discs on the surface, whatever --tf
    /// draws). The projections need no visibility order and read every voxel (no levels of detail
    /// or early termination); --raycast casts in the same mode.
    #[arg(help_heading = "Transfer function and mode", long, default_value = "composite", value_parser = ["composite", "mip", "minip", "average", "xray", "iso"])]
    pub mode: String,
    /// The value of --mode iso's surface, in the volume file's units (a built-in scene's values lie
    /// in 0 to 1). A value the data never crosses draws nothing, and says so.
    #[arg(help_heading = "Transfer function and mode", long, value_parser = parse_finite, allow_hyphen_values = true)]
    pub iso: Option<f32>,
    /// The colours of --mode mip, minip, average and xray (a transfer function preset or TOML file:
    /// its colours over the values 0 to 1; --tf still picks the voxels drawn) [default: grey]; with
    /// --mode iso, the surface takes the colour at its value [default: bone].
    #[arg(help_heading = "Transfer function and mode", long)]
    pub colormap: Option<String>,
    /// Draw on a grid this fraction of --size and resample it bilinearly to full size (1/16 to 1):
    /// faster where voxels cover several pixels; the added error is in docs/RESULTS.md (peers).
    #[arg(help_heading = "Quality and speed", long, value_parser = parse_finite, default_value = "1")]
    pub render_scale: f32,
    /// Levels of detail of a volume drawn per splat: auto (the default: where voxels project
    /// smaller than --lod-pixels, groups of them drawn as one prefiltered splat, within
    /// --lod-error; docs/MODEL.md) or off (every voxel a splat).
    #[arg(help_heading = "Quality and speed", long, value_parser = ["off", "auto"])]
    pub lod: Option<String>,
    /// Anti-aliasing of distant splats (chapter 3): none, Swan's d/k scaling, or an EWA low-pass.
    /// [default: none]
    #[arg(help_heading = "Quality and speed", long, value_parser = ["none", "swan", "ewa"])]
    pub aa: Option<String>,
    /// Render with the ray caster at this step (in voxel spacings) instead of splatting.
    #[arg(help_heading = "Quality and speed", long, value_parser = parse_finite)]
    pub raycast: Option<f32>,
    /// Print per-stage times.
    #[arg(help_heading = "Output", long)]
    pub timings: bool,
    /// Under mpirun (a build with `--features mpi`): how the ranks exchange their frames to
    /// composite them, direct-send, binary-swap (a power of two ranks) or auto (binary-swap from
    /// 4 ranks).
    #[arg(help_heading = "Output", long)]
    pub exchange: Option<String>,
    /// Print what the frame would draw and how (the raster, the order, the sheet batches, a
    /// volume's memory split and levels of detail) instead of rendering it.
    #[arg(help_heading = "Output", long, conflicts_with_all = ["raycast", "out", "timings"])]
    pub plan: bool,
    /// Draw a session the viewer saved (its camera, transfer function, shading, mode, clipping and
    /// the options its keys change) of the same --volume, at --size.
    #[arg(help_heading = "Scene and file", long, requires = "volume", conflicts_with_all = ["eye", "target", "up", "fov", "ortho", "near", "far",
        "view", "tf", "shade", "mode", "iso", "lod", "background", "clip", "crop"])]
    pub session: Option<PathBuf>,
    /// Output file, .png or .exr.
    #[arg(help_heading = "Output", long, required_unless_present = "plan")]
    pub out: Option<PathBuf>,
}

/// Runs `voxsplat render`.
pub fn render(mut a: Box<RenderArgs>) -> Result<()> {
    if let Some(path) = &a.session {
        // (clap's `requires` does not reach the flattened --volume.)
        if a.scene.volume.is_none() {
            return Err(Error::InvalidArgument("--session draws the --volume it was saved from: give it".into()));
        }
        // (clap's conflicts cannot name --order: it is `SceneResearch`'s, which `voxsplat-lab order`
        // also takes, without --session.)
        if a.scene.research.order != "pbtf" {
            return Err(Error::InvalidArgument("--order with --session: the session sets the order".into()));
        }
        let s = crate::session::Session::load(path)?;
        (a.mode, a.research.accumulate, a.research.raster, a.research.kernel) =
            (s.mode.clone(), s.composite.clone(), s.raster.clone(), s.kernel.clone());
        a.background = Some(s.background);
        // A projection draws in no order and without levels of detail, whatever the viewer had set.
        if s.mode == "composite" {
            (a.scene.research.order, a.lod) = (s.order.clone(), Some(s.lod.clone()));
        }
        a.scene.session = Some(s);
    }
    a.scene.crop = a.crop.map(|c| [[c[0], c[1], c[2]], [c[3], c[4], c[5]]]);
    // One frame: an OME-Zarr image need be read only where it is seen.
    if let Some(path) = a.scene.volume.clone().filter(|p| a.crop.is_none() && voxsplat::loaders::is_ome_zarr(p)) {
        if let Some((seen, camera)) = crate::pyramid::seen_box(&a.scene, &path)? {
            (a.scene.crop, a.scene.view_read) = (Some(seen), Some(camera));
        }
    }
    let out = a.out.clone().unwrap_or_default();
    if !a.plan {
        voxsplat::output::ImageFormat::of(&out)?;
    }
    let order = a.scene.research.order.parse::<OrderKind>()?;
    let composite = a.research.accumulate.parse::<Composite>()?;
    let mode = a.mode.parse::<voxsplat::options::Mode>()?;
    if mode.is_projection() {
        let refuse = |flag: &str, why: &str| Err(Error::InvalidArgument(format!("--mode {mode} {flag}: {why}")));
        if a.research.truth {
            return refuse("--truth", "the truth composites; the projections' reference is --raycast");
        }
        if a.research.k_line {
            return refuse("--k-line", "the k line marks where composited splats grow; use --mode composite");
        }
        if a.scene.research.order != "pbtf" {
            return refuse("--order", "a projection draws in no order");
        }
        if a.research.early_termination != voxsplat::options::DEFAULT_EARLY_TERMINATION || a.research.keep_hidden_bricks
        {
            return refuse("early termination", "a projection reads every splat along the ray");
        }
        if a.lod.as_deref() == Some("auto") || a.research.lod_nodes {
            return refuse("levels of detail", "a projection reads each voxel's value, which coarse cells do not keep");
        }
    } else if a.colormap.is_some() {
        return Err(Error::InvalidArgument(
            "--colormap colours --mode mip, minip, average, xray or iso; a composited frame takes its colours from \
             --tf"
                .into(),
        ));
    }
    let session_iso = a.scene.session.as_ref().and_then(|s| s.iso);
    match (mode, a.iso.or(session_iso)) {
        (voxsplat::options::Mode::Iso, None) => {
            return Err(Error::InvalidArgument("--mode iso needs the surface's value: --iso VALUE".into()))
        }
        (m, Some(_)) if m != voxsplat::options::Mode::Iso => {
            return Err(Error::InvalidArgument(format!("--iso sets --mode iso's surface, not --mode {m}'s")))
        }
        _ => {}
    }
    // A volume is a bricked store classified on the device unless a mode needs host splats (the
    // ray caster reads a bricked store's isosurface).
    let cast_splats = a.raycast.is_some() && mode != voxsplat::options::Mode::Iso;
    let host_splats = order != OrderKind::Pbtf || a.research.truth || cast_splats || a.research.k_line;
    let mut opts = RenderOptions::default();
    opts.mode = mode;
    // In the file's units until the scene is open (then its store's normalisation).
    opts.iso = a.iso;
    opts.colormap = a.colormap.as_deref().map(load_tf).transpose()?;
    opts.order = order;
    opts.composite = composite;
    opts.kernel = a.research.kernel.parse::<Kernel>()?;
    opts.antialias = a.aa.as_deref().unwrap_or("none").parse::<voxsplat::options::Antialias>()?;
    if a.aa.is_some() && a.raycast.is_some() {
        return Err(Error::InvalidArgument(
            "--aa filters splats' footprints; the ray caster samples along each pixel's rays (--supersample K \
             averages K x K of them)"
                .into(),
        ));
    }
    opts.direction =
        a.research
            .direction
            .as_deref()
            .map(|d| if d == "ftb" { Direction::FrontToBack } else { Direction::BackToFront });
    if let Some(mib) = a.research.sheet_budget_mib {
        if composite == Composite::Splat || a.raycast.is_some() || a.research.truth {
            return Err(Error::InvalidArgument(
                "--sheet-budget-mib bounds the summation layers of --accumulate sheet or slab; this frame draws none"
                    .into(),
            ));
        }
        opts.sheet_budget_bytes = mib_bytes(mib, "--sheet-budget-mib")?;
    }
    if let Some(t) = a.research.slab_thickness {
        if composite != Composite::Slab {
            return Err(Error::InvalidArgument(
                "--slab-thickness sets the slabs of --accumulate slab; this frame draws no slabs".into(),
            ));
        }
        opts.slab_thickness = t;
    }
    opts.early_termination = a.research.early_termination;
    opts.cull_hidden_bricks = !a.research.keep_hidden_bricks;
    opts.every_voxel = a.research.every_voxel;
    opts.raster = a.research.raster.parse::<voxsplat::options::Raster>()?;
    opts.render_scale = a.render_scale;
    opts.lod = a.lod.as_deref().unwrap_or("auto").parse()?;
    let planes: Vec<voxsplat::glam::Vec4> = a.clip.iter().map(|p| voxsplat::glam::Vec4::from(*p)).collect();
    let crop = a.crop.map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5])]);
    opts.clip = voxsplat::options::Clip::new(&planes, crop)?;
    // A session's clipping cuts the whole volume, as the viewer did (--crop would read a part).
    if let Some(s) = &a.scene.session {
        opts.clip = s.clip()?;
    }
    opts.background = a.background;
    (opts.lod_pixels, opts.lod_error) = (a.research.lod_pixels, a.research.lod_error);
    if let Some(band) = a.research.lod_band {
        opts.lod_band = band;
    }
    if a.research.lod_nodes && opts.lod == voxsplat::options::Lod::Off {
        return Err(Error::InvalidArgument(
            "--lod-nodes draws levels of detail above the brick: it needs --lod auto (the default), not --lod off"
                .into(),
        ));
    }
    opts.lod_nodes = a.research.lod_nodes;
    opts.validate()?;
    #[cfg(feature = "mpi")]
    let launched = voxsplat::distributed::mpi::launched();
    #[cfg(not(feature = "mpi"))]
    let launched = false;
    if let Some(c) = &a.exchange {
        c.parse::<voxsplat::distributed::Scheme>()?;
        if !launched {
            return Err(Error::InvalidArgument(
                "--exchange picks how the ranks exchange their frames under mpirun (a build with --features \
                 mpi); this run is one renderer"
                    .into(),
            ));
        }
    }
    #[cfg(feature = "mpi")]
    if launched {
        if a.plan {
            return Err(Error::InvalidArgument("--plan prints one renderer's plan: run it without mpirun".into()));
        }
        if mode == voxsplat::options::Mode::Iso {
            return Err(Error::Unsupported("--mode iso draws on one renderer: run it without mpirun".into()));
        }
        return render_distributed(&a, &opts, host_splats);
    }
    let (bricked, set, content) = open(&a.scene, host_splats)?;
    // --iso in the file's units: the bricked store's normalisation (its values' range).
    let iso_range = bricked.as_ref().map(|b| b.store.range);
    opts.iso = match session_iso {
        Some(v) => Some(v),
        None => normalised_iso(bricked.as_ref(), &a.scene, a.iso)?,
    };
    let asked = if a.research.lod_nodes {
        Some("--lod-nodes")
    } else {
        a.lod.as_deref().filter(|l| *l == "auto").map(|_| "--lod auto")
    };
    if let Some(flag) = asked.filter(|_| bricked.is_none() || composite != Composite::Splat) {
        return Err(Error::InvalidArgument(format!(
            "{flag}: levels of detail are drawn per splat (--accumulate splat) from a volume's bricked store; \
             this scene is a classified splat set (a built-in scene, --dense, another order, --truth, --raycast)"
        )));
    }
    if a.research.keep_hidden_bricks && (bricked.is_none() || a.raycast.is_some() || a.research.truth) {
        return Err(Error::InvalidArgument(
            "--keep-hidden-bricks draws a volume's bricked store whole; this frame draws no bricks (a built-in scene, \
             --dense, another order, --truth or --raycast)"
                .into(),
        ));
    }
    let cam = camera_of(&a.scene, set.grid(), &content)?;
    if let voxsplat::camera::Projection::Perspective { fov_y_deg } = cam.projection {
        // Other renderers (scripts/vtk_file.py) take the same view from this line.
        let v = |v: Vec3| format!("{:.4},{:.4},{:.4}", v.x, v.y, v.z);
        eprintln!("camera (grid frame): eye {} target {} up {} fov {fov_y_deg}", v(cam.eye), v(cam.target), v(cam.up));
    }
    let splats = bricked.as_ref().map(|b| b.store.len()).unwrap_or(set.len());
    let r_bricked = bricked.is_some();
    let set_for_k = if a.research.k_line { set.clone() } else { scene::build("empty")? };
    if a.research.truth && a.render_scale != 1.0 {
        return Err(Error::InvalidArgument("--truth is the full-size reference: drop --render-scale".into()));
    }
    if a.plan {
        let mut r = renderer_of(&a.scene)?;
        match bricked {
            Some(b) => r.set_bricks(b)?,
            None => r.set_scene(set)?,
        }
        print!("{}", r.plan(&cam, &opts)?);
        return report_validation(&r);
    }
    let mut wall = Vec::new();
    // Whether the frame went to its file band by band as it was drawn.
    let mut written = false;
    let frame = if a.research.truth {
        let t = std::time::Instant::now();
        let opts = voxsplat::truth::TruthOptions {
            reconstruction: voxsplat::truth::Reconstruction::Kernel(opts.kernel),
            ..Default::default()
        };
        let image = voxsplat::truth::volumetric_summation(&set, &cam, &opts)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        voxsplat::Rendered {
            image,
            timings: vec![voxsplat::options::StageTime { stage: "truth", ms }],
            raster: None,
            stats: Default::default(),
        }
    } else {
        let mut r = renderer_of(&a.scene)?;
        match bricked {
            Some(b) => r.set_bricks(b)?,
            None => r.set_scene(set)?,
        }
        let f = match a.raycast {
            Some(step) => {
                let mut o = voxsplat::options::RaycastOptions {
                    mode,
                    colormap: opts.colormap.clone(),
                    iso: opts.iso,
                    step,
                    render_scale: a.render_scale,
                    clip: opts.clip,
                    supersample: a.research.supersample,
                    ..Default::default()
                };
                if let Some(stop) = a.research.raycast_stop {
                    o.min_transmittance = stop;
                }
                r.raycast(&cam, &o)?
            }
            // A frame past one band goes to its PNG band by band, never whole (`render_bands`).
            None if streams(&a, &cam, &out)? => {
                let mut png = voxsplat::output::PngRows::create(&out, cam.width, cam.height)?;
                let t = std::time::Instant::now();
                let d = r.render_bands(&cam, &opts, &mut |_, band| png.push(band))?;
                png.finish()?;
                wall.push(t.elapsed().as_secs_f64() * 1e3);
                written = true;
                let image = voxsplat::image::ImageF32::new(0, 0);
                voxsplat::Rendered { image, timings: d.timings, raster: Some(d.raster), stats: d.stats }
            }
            None => median_timings((0..a.research.repeat).map(|_| {
                let t = std::time::Instant::now();
                let f = r.render(&cam, &opts);
                wall.push(t.elapsed().as_secs_f64() * 1e3);
                f
            }))?,
        };
        report_validation(&r)?;
        f
    };
    let empty = frame.image.pixels.iter().all(|p| p[3] == 0.0);
    let mut image = frame.image;
    if let (Some(bg), true) = (a.background, a.research.truth || a.raycast.is_some()) {
        // The reference renderers have no present stage: its mirror, on the host.
        voxsplat::low_level::present_over(&mut image, bg);
    }
    if a.research.k_line {
        let regions = voxsplat::aa::k_regions(&set_for_k, &cam);
        if regions.iter().all(|&r| r == 0) {
            return Err(Error::InvalidArgument("--k-line needs a scene in view".into()));
        }
        voxsplat::aa::draw_k_line(&mut image, &regions);
    }
    if !written {
        voxsplat::output::write_image(&image, &out)?;
    }
    let what = if r_bricked { "stored voxels" } else { "splats" };
    eprintln!("{splats} {what} -> {}", out.display());
    if let Some(v) = a.iso {
        let range = iso_range.map(|(lo, hi)| format!(" (its values lie in {lo} .. {hi})")).unwrap_or_default();
        let none = if a.raycast.is_some() { empty } else { frame.stats.splats == 0 };
        if none {
            eprintln!("--iso {v}: no cell of the data crosses it{range}: nothing drawn");
        } else if a.raycast.is_none() {
            eprintln!("isosurface: {} surface splats", frame.stats.splats);
        }
    }
    if let Some(c) = &frame.raster {
        eprintln!("raster: {} ({})", c.raster, c.reason);
    }
    if a.timings {
        for t in &frame.timings {
            println!("{:<14} {:>9.3} ms", t.stage, t.ms);
        }
        let st = frame.stats;
        if st.bricks > 0 {
            println!(
                "drawn: {} splats from {} of {} bricks ({} drawn coarser, {} of them nodes of several bricks, {} \
                 hidden by nearer ones), {} waves",
                st.splats, st.bricks_visible, st.bricks, st.bricks_coarse, st.nodes, st.bricks_hidden, st.waves
            );
        }
        if st.records_resident > 0 {
            println!(
                "brick records: {:.1} MiB uploaded, {:.1} MiB held on the device",
                st.bytes_uploaded as f64 / 1048576.0,
                st.records_resident as f64 / 1048576.0
            );
        }
        if !wall.is_empty() {
            let n = wall.len();
            // Not a stage line: scripts sum those.
            println!("frame, wall:   {:>9.3} ms (median of {n})", crate::measure::median(&mut wall));
        }
        if let Some(mib) = crate::measure::peak_rss_mib() {
            println!("host memory, peak: {mib:.0} MiB resident");
        }
    }
    Ok(())
}

/// Whether `render` writes its frame band by band: a PNG of more than one band
/// (`voxsplat::low_level::frame_bands`) drawn once, with nothing to add to the whole frame after it.
fn streams(a: &RenderArgs, cam: &voxsplat::Camera, out: &std::path::Path) -> Result<bool> {
    let png = voxsplat::output::ImageFormat::of(out)? == voxsplat::output::ImageFormat::Png;
    Ok(png && a.research.repeat == 1 && !a.research.k_line && voxsplat::low_level::frame_bands(cam).len() > 1)
}

/// The last of `frames` with each stage's median time over all of them, keeping one image at a
/// time (`--repeat` would otherwise hold every frame).
fn median_timings(frames: impl Iterator<Item = Result<voxsplat::Rendered>>) -> Result<voxsplat::Rendered> {
    let mut earlier: Vec<Vec<voxsplat::options::StageTime>> = Vec::new();
    let mut last: Option<voxsplat::Rendered> = None;
    for f in frames {
        let f = f?;
        if let Some(prev) = last.replace(f) {
            earlier.push(prev.timings);
        }
    }
    let mut last = last.expect("at least one frame");
    for t in &mut last.timings {
        let mut v: Vec<f64> =
            earlier.iter().flat_map(|ts| ts.iter().filter(|s| s.stage == t.stage).map(|s| s.ms)).collect();
        v.push(t.ms);
        t.ms = crate::measure::median(&mut v);
    }
    Ok(last)
}

/// `voxsplat render` under mpirun: the --volume file cut into one box per rank, each drawn by its
/// rank, composited in the boxes' visibility order; rank 0 writes the image.
#[cfg(feature = "mpi")]
fn render_distributed(a: &RenderArgs, opts: &RenderOptions, host_splats: bool) -> Result<()> {
    use voxsplat::distributed::mpi::rsmpi::{self, traits::CommunicatorCollectives};
    let universe =
        rsmpi::initialize().ok_or_else(|| Error::Unsupported("MPI was initialised already or cannot be".into()))?;
    let result = distributed_frames(a, opts, host_splats, universe.world());
    if let Err(e @ Error::OnRank { .. }) = &result {
        // Every rank holds this error: each reports it, and none exits (which makes mpirun stop
        // the others) before all have.
        let line = format!("error: {e}\n");
        let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
        universe.world().barrier();
        drop(universe);
        std::process::exit(2);
    }
    result
}

/// `render_distributed` on an initialised `world`.
#[cfg(feature = "mpi")]
fn distributed_frames(
    a: &RenderArgs,
    opts: &RenderOptions,
    host_splats: bool,
    world: voxsplat::distributed::mpi::rsmpi::topology::SimpleCommunicator,
) -> Result<()> {
    use voxsplat::distributed::mpi::{rsmpi::traits::Communicator, Distributed};
    let rank = world.rank();
    // Whatever one rank alone may fail at (its view of the file, its device) is agreed on before
    // the first collective, so no rank waits for one that has quit.
    let setup = (|| {
        let Some(path) = a.scene.volume.as_ref().filter(|_| !host_splats && a.scene.positions.is_none()) else {
            return Err(Error::Unsupported(
                "under mpirun, render draws a --volume file as a bricked store per splat in PBTF order (no --truth, \
                 --raycast, --k-line, --positions or other orders)"
                    .into(),
            ));
        };
        let hints = crate::open::volume_hints(&a.scene)?;
        let reader = voxsplat::distributed::open(path, &hints)?;
        let orientation = crate::open::orientation_of(&a.scene)?;
        let spacing = hints.spacing.unwrap_or(reader.spacing);
        let grid = voxsplat::orient::placed_grid(reader.dims, spacing, orientation.as_ref())?;
        // Checked here; framed on the visible voxels once the ranks hold them.
        camera_of(&a.scene, &grid, &crate::open::Content { orientation, bounds: None })?;
        let tf = crate::open::transfer_function(&a.scene)?;
        let shading = crate::open::headlight(&a.scene, grid.dims, grid.spacing, orientation);
        let scheme: voxsplat::distributed::Scheme = a.exchange.as_deref().unwrap_or("auto").parse()?;
        Ok((path, hints, grid, orientation, tf, shading, scheme, renderer_of(&a.scene)?))
    })();
    let (path, hints, grid, orientation, tf, shading, scheme, r) = voxsplat::distributed::mpi::agree(&world, setup)?;
    let mut d = Distributed::load(world, r, path, &hints, tf, shading, scheme)?;
    let content = crate::open::Content { orientation, bounds: d.visible_bounds() };
    let cam = d.agree(camera_of(&a.scene, &grid, &content))?;
    let stored = d.stored_per_rank();
    let mut frames = Vec::new();
    for _ in 0..a.research.repeat {
        frames.push(d.render(&cam, opts)?);
    }
    d.agree(report_validation(d.renderer()))?;
    let store_bytes = d.gather(d.store_bytes());
    let peaks = d.gather(voxsplat::distributed::peak_rss_bytes().unwrap_or(0));
    if rank != 0 {
        return Ok(());
    }
    let frames: Vec<_> = frames.into_iter().flatten().collect();
    let Some(last) = frames.last() else { return Ok(()) };
    let out = a.out.clone().unwrap_or_default();
    voxsplat::output::write_image(&last.image, &out)?;
    eprintln!(
        "{} stored voxels on {} ranks ({}) by {} -> {}",
        stored.iter().sum::<u64>(),
        stored.len(),
        stored.iter().map(u64::to_string).collect::<Vec<_>>().join(" + "),
        d.scheme().name(),
        out.display()
    );
    if a.timings {
        for stage in ["render", "composite"] {
            let mut ms: Vec<f64> =
                frames.iter().flat_map(|f| f.timings.iter().filter(|t| t.stage == stage).map(|t| t.ms)).collect();
            ms.sort_by(f64::total_cmp);
            println!("{stage:<14} {:>9.3} ms", ms[ms.len() / 2]);
        }
        let mib = |v: &[u64]| v.iter().map(|b| format!("{:.1}", *b as f64 / (1 << 20) as f64)).collect::<Vec<_>>();
        println!("{:<14} {} MiB per rank", "store", mib(&store_bytes).join(" "));
        println!("{:<14} {} MiB per rank", "peak memory", mib(&peaks).join(" "));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cmd {
        #[command(flatten)]
        render: RenderArgs,
    }

    /// `render` with no flags draws what `RenderOptions::default()` draws, so an embedder's
    /// default frame is the command's (the library's kernel was the Gaussian while the command's
    /// was Crawfis-Max).
    #[test]
    fn render_s_defaults_are_the_library_s() {
        let a = Cmd::try_parse_from(["render", "--out", "frame.png"]).unwrap().render;
        let d = RenderOptions::default();
        assert_eq!(a.mode.parse::<voxsplat::options::Mode>().unwrap(), d.mode);
        assert_eq!(a.scene.research.order.parse::<OrderKind>().unwrap(), d.order);
        assert_eq!(a.research.accumulate.parse::<Composite>().unwrap(), d.composite);
        assert_eq!(a.research.kernel.parse::<Kernel>().unwrap(), d.kernel);
        assert_eq!(a.aa, None);
        assert_eq!(voxsplat::options::Antialias::None, d.antialias);
        assert_eq!(a.research.raster.parse::<voxsplat::options::Raster>().unwrap(), d.raster);
        assert_eq!(a.lod.as_deref().unwrap_or("auto").parse::<voxsplat::options::Lod>().unwrap(), d.lod);
        assert_eq!(
            (a.research.lod_pixels, a.research.lod_error, a.research.lod_band),
            (d.lod_pixels, d.lod_error, None)
        );
        assert_eq!((a.research.early_termination, a.render_scale), (d.early_termination, d.render_scale));
        assert_eq!((a.research.sheet_budget_mib, mib_bytes(256, "").unwrap()), (None, d.sheet_budget_bytes));
        assert_eq!((a.research.direction.is_none(), d.direction.is_none()), (true, true));
        assert_eq!(a.background, d.background);
        assert_eq!((a.research.every_voxel, !a.research.keep_hidden_bricks), (d.every_voxel, d.cull_hidden_bricks));
    }

    /// `voxsplat render` takes the research switches' `Default`s, `voxsplat-lab render` their clap
    /// defaults: the two agree, so the lab's render with no switches is the user's.
    #[test]
    fn the_research_switches_default_alike_in_both_binaries() {
        #[derive(Parser)]
        struct Lab {
            #[command(flatten)]
            render: RenderArgs,
            #[command(flatten)]
            research: Research,
            #[command(flatten)]
            scene: crate::scene_args::SceneResearch,
        }
        let lab = Lab::try_parse_from(["render", "--out", "frame.png"]).unwrap();
        assert_eq!(format!("{:?}", lab.research), format!("{:?}", Research::default()));
        assert_eq!(format!("{:?}", lab.scene), format!("{:?}", crate::scene_args::SceneResearch::default()));
        let _ = lab.render;
    }
}
