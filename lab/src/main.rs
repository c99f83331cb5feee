//! `voxsplat-lab`: the studies that measure the renderer, apart from the user's commands. Each
//! prints a markdown section or CSV that `scripts/results.sh` gathers into docs/RESULTS.md; none of
//! them is needed to render. `voxsplat-lab render` is `voxsplat render` with the research switches
//! (the truth, the k line, the engine's paths and budgets). docs/guide/lab.md says why they are a
//! binary of their own.
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use voxsplat::{Error, Renderer, RendererOptions, Result};
use voxsplat_cli::open::*;
use voxsplat_cli::render::{RenderArgs, Research};
use voxsplat_cli::scene_args::SceneResearch;
use voxsplat_cli::{print, println};

#[derive(Parser)]
#[command(
    name = "voxsplat-lab",
    version,
    about = "Studies that measure the voxsplat renderer (for its developers), and render with the research switches"
)]
struct Lab {
    #[command(subcommand)]
    study: Study,
    /// Host memory, in MiB, that what a file's header or a flag sizes may take (as `voxsplat`'s)
    /// [default: three quarters of physical memory].
    #[arg(long, global = true)]
    host_budget_mib: Option<u64>,
}

/// `voxsplat render`'s flags and the research switches.
#[derive(Args)]
struct LabRender {
    #[command(flatten)]
    render: RenderArgs,
    #[command(flatten)]
    research: Research,
    #[command(flatten)]
    scene_research: SceneResearch,
}

/// A study of the renderer.
#[derive(Subcommand)]
enum Study {
    /// `voxsplat render` with the research switches: the volumetric-summation truth, the k line,
    /// the engine's paths (--dense, --bisect, --direction, ...) and budgets.
    Render(Box<LabRender>),
    /// Write or check a visibility order (back to front): the device's PBTF order or the host's
    /// (--order).
    Order(Box<voxsplat_lab::order::OrderArgs>),
    /// Render many frames with changing scenes, cameras and modes; report host memory and GPU
    /// allocations per cycle (they must stay flat after warm-up).
    Soak {
        #[arg(long, default_value_t = 1000)]
        frames: usize,
        #[arg(long, default_value_t = 96)]
        size: u32,
        /// Enable the validation layer and count its messages.
        #[arg(long)]
        validation: bool,
    },
    /// Anti-aliasing on the seed's terrain and orthographic figures (Figs 3.7, 3.8, 5.3):
    /// none, Swan and EWA against a supersampled truth; a markdown section on stdout.
    Antialias {
        /// Square images of this side instead of the seed's sizes (Fig. 3.7 260x179, Fig. 3.8
        /// 290x290; at 128 three quarters of the terrain's splats lie beyond k).
        #[arg(long)]
        size: Option<u32>,
        /// Supersampling of the truth per axis.
        #[arg(long, default_value_t = 4)]
        factor: u32,
        /// Frames of the camera move the shimmer is measured over.
        #[arg(long, default_value_t = 24)]
        dolly: usize,
        /// Timed frames per mode.
        #[arg(long, default_value_t = 5)]
        frames: usize,
    },
    /// Orders under motion and the terrain's motion blur (chapters 4-5): PBTF, WBTF and
    /// BTF against the sorted order on the built-in animations, and blurred splats against the
    /// accumulation buffer on the orthographic terrain with WBTF; a markdown section on stdout.
    MotionOrders {
        /// First frame.
        #[arg(long, default_value_t = 8)]
        first: u32,
        /// Frames after it.
        #[arg(long, default_value_t = 12)]
        frames: u32,
        /// Timed rounds of the blur methods.
        #[arg(long, default_value_t = 5)]
        rounds: usize,
    },
    /// The reconstruction kernels side by side: sheet ripple, lattice RMS (Crawfis and
    /// Max's criterion), error against the peers' truth and time; a markdown section on stdout.
    Kernels {
        /// Side of the peers' volume.
        #[arg(long, default_value_t = 128)]
        n: u32,
        /// Image side.
        #[arg(long, default_value_t = 512)]
        size: u32,
        /// Rounds of alternating frames.
        #[arg(long, default_value_t = 5)]
        frames: usize,
        /// Chart of error against ripple (the markdown links it as bench/FILE).
        #[arg(long)]
        chart: Option<PathBuf>,
    },
    /// The rendering modes (composite, MIP, MinIP, average, X-ray, isosurface) of the gallery's
    /// volumes: each mode's default frame beside the ray caster in the same mode, speed against
    /// accuracy (PSNR against a fine ray cast in that mode); the page on stdout, a chart per volume.
    Modes {
        /// Image side.
        #[arg(long, default_value_t = 512)]
        size: u32,
        /// Timed frames per mode (after a warm-up).
        #[arg(long, default_value_t = 5)]
        frames: usize,
        /// Where the charts go (modes-NAME.svg); the page links them by file name.
        #[arg(long, default_value = "docs/bench")]
        charts: PathBuf,
        /// The shared data folder (bonsai, stent).
        #[arg(long, default_value = "../shared/data")]
        data: PathBuf,
    },
    /// The bricked-volume study: store sizes, dense against bricked frames, a TF change,
    /// hidden-brick culling and the 512³ bonsai against the 256³, alternating variants in one
    /// process; a markdown section on stdout. With --volume: one volume's load, store, frame and
    /// peak resident set (one file per process, for the memory target).
    Bricks {
        /// The 256³ bonsai.
        #[arg(long, default_value = "../shared/data/bonsai/bonsai.nii.gz")]
        bonsai: PathBuf,
        /// Its 2x upsampling (scripts/large-volumes.sh), if made.
        #[arg(long)]
        large: Option<PathBuf>,
        /// Image side.
        #[arg(long, default_value_t = 512)]
        size: u32,
        /// Rounds of alternating frames.
        #[arg(long, default_value_t = 5)]
        frames: usize,
        /// Measure this one volume instead.
        #[arg(long)]
        volume: Option<PathBuf>,
        /// Device-memory budget for --volume, MiB.
        #[arg(long, default_value_t = 1024)]
        gpu_budget_mib: u64,
        /// Transfer-function preset for --volume.
        #[arg(long, default_value = "ramp")]
        tf: String,
        /// With --volume: orbit it in this many steps at the default settings, one line per
        /// frame with the bytes of brick records it uploaded (a store that streams through the
        /// budget keeps the records it used in a cache on the device).
        #[arg(long, requires = "volume")]
        orbit: Option<u32>,
        /// With --orbit: the degrees the whole orbit turns (a viewer's drag turns a few).
        #[arg(long, default_value_t = 360.0, requires = "orbit")]
        arc: f32,
        /// With --orbit of an OME-Zarr image: the view's field of view in degrees. Each frame then
        /// reads its own part of the image (the chunks it may see, at the finest level that part
        /// fits the host budget at) through one chunk cache, and the table says what each read.
        #[arg(long, requires = "orbit")]
        fov: Option<f32>,
        /// With --fov: the chunk cache's size in MiB (0: none, every frame reads its chunks anew).
        #[arg(long, default_value_t = 1024, requires = "fov")]
        chunk_cache_mib: u64,
        /// Chart of the levels-of-detail study on peer256 (its markdown links it as bench/FILE).
        #[arg(long)]
        lod_chart: Option<PathBuf>,
        /// Draw the scaling chart from this CSV (voxels,vtk_ms,voxsplat_ms; scripts/bricks-vtk.sh)
        /// into --chart-out instead.
        #[arg(long, requires = "chart_out")]
        chart: Option<PathBuf>,
        /// The chart's SVG.
        #[arg(long)]
        chart_out: Option<PathBuf>,
    },
    /// Render the peers' scene (../shared/peers) with every voxsplat mode: median frame
    /// times as CSV on stdout, images into --out-dir; `scripts/peers.sh` runs it beside VTK.
    Peer {
        /// Volume side (the peers use 128 and 256).
        #[arg(long, default_value_t = 128)]
        n: u32,
        #[arg(long, default_value_t = 512)]
        size: u32,
        #[arg(long, default_value_t = 2)]
        warmup: usize,
        #[arg(long, default_value_t = 5)]
        frames: usize,
        #[arg(long, default_value = "peers-out")]
        out_dir: PathBuf,
        /// Also write the references: ray integration of the interpolated scalar (VTK's model) at
        /// this step, and the pre-classified volumetric truth.
        #[arg(long, value_parser = parse_finite)]
        truth_step: Option<f32>,
    },
    /// Splat rate of every raster variant against footprint size (the matrix's raster sweep): a
    /// sheet of N x N voxels head-on, footprints exactly S px wide; CSV on stdout.
    Rates {
        /// Voxels per side of the sheet.
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(4..=2048))]
        n: u32,
        /// Footprint quad sides in pixels, comma-separated.
        #[arg(long, default_value = "3,5,7,11,15", value_delimiter = ',', value_parser = parse_finite)]
        sizes: Vec<f32>,
        /// Timed frames per variant (median; one warm-up first).
        #[arg(long, default_value_t = 5)]
        frames: usize,
    },
    /// The method matrix (scene x order x compositing x kernel, beside the ray caster at several
    /// steps) timed and scored against the truth, with anti-aliasing, motion blur, stability, the
    /// roofline, raster rates and scaling: CSV files and SVG charts in --out-dir, and with
    /// --results the results page (scripts/results.sh runs it after the other studies).
    Matrix(MatrixArgs),
    /// A series (a 4-D NIfTI, or an OME-Zarr image with a time axis) played: each time point
    /// swapped into the renderer (`update_volume`) against set afresh (`set_bricks`), with the
    /// frames after each; the scene flags as `render` takes them (scripts/make_series.py writes
    /// series from the shared bonsai).
    Series(Box<SceneArgs>),
    /// How fast a volume file loads: the dense volume (`load_volume`) and the bricked store
    /// streamed from it (`BrickStore::load`), medians of --repeat reads, in MB/s of the samples as
    /// the file stores them (scripts/dicom_bench.sh sets a DICOM series beside dcm2niix).
    Load {
        /// The file or folder (any `render --volume`).
        file: PathBuf,
        /// Reads of each kind.
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        /// Bytes per stored sample (2 for 16-bit DICOM), for the MB/s.
        #[arg(long, default_value_t = 2)]
        sample_bytes: u64,
        /// A folder of several DICOM series: the one to read.
        #[arg(long)]
        series: Option<String>,
    },
}

#[derive(Args)]
struct MatrixArgs {
    /// A small matrix (two scenes at 128x128) that CI can afford.
    #[arg(long)]
    quick: bool,
    /// Measured frames per configuration (at least 5; after warm-up).
    #[arg(long)]
    frames: Option<usize>,
    /// Where the CSV files and SVG charts go.
    #[arg(long, default_value = "bench-out")]
    out_dir: PathBuf,
    /// Also write the results page (e.g. docs/RESULTS.md): one page linking the charts and the
    /// detail pages it writes beside them in --out-dir.
    #[arg(long)]
    results: Option<PathBuf>,
    /// Skip the scaling series.
    #[arg(long)]
    no_scaling: bool,
}

/// Runs one study.
fn run(study: Study) -> Result<()> {
    match study {
        Study::Render(a) => {
            let LabRender { mut render, research, scene_research } = *a;
            (render.research, render.scene.research) = (research, scene_research);
            voxsplat_cli::render::render(Box::new(render))
        }
        Study::Order(a) => voxsplat_lab::order::run(*a),
        Study::Series(a) => {
            print!("{}", voxsplat_cli::series::study(&a)?);
            Ok(())
        }
        Study::Load { file, repeat, sample_bytes, series } => {
            if repeat < 1 {
                return Err(Error::InvalidArgument("--repeat must be at least 1".into()));
            }
            let hints = voxsplat::loaders::VolumeHints { series, ..Default::default() };
            let median = |mut t: Vec<f64>| {
                t.sort_by(f64::total_cmp);
                t[t.len() / 2]
            };
            let (mut dense, mut bricked, mut voxels) = (Vec::new(), Vec::new(), 0u64);
            for _ in 0..repeat {
                let t = std::time::Instant::now();
                let v = voxsplat::loaders::load_volume(&file, &hints)?;
                dense.push(t.elapsed().as_secs_f64());
                voxels = v.values.len() as u64;
                drop(v);
                let t = std::time::Instant::now();
                voxsplat::bricks::BrickStore::load(&file, &hints)?;
                bricked.push(t.elapsed().as_secs_f64());
            }
            let mb = (voxels * sample_bytes) as f64 / 1e6;
            println!("| read | median of {repeat} | MB/s ({mb:.1} MB of samples) |\n|---|---:|---:|");
            for (what, t) in
                [("dense volume (load_volume)", median(dense)), ("bricked store (BrickStore::load)", median(bricked))]
            {
                println!("| {what} | {:.3} s | {:.0} |", t, mb / t);
            }
            Ok(())
        }
        Study::Rates { n, sizes, frames } => {
            if frames < 1 {
                return Err(Error::InvalidArgument("--frames must be at least 1".into()));
            }
            let mut r = Renderer::new(&RendererOptions::default())?;
            eprintln!("device: {}", r.device_name());
            let pts = voxsplat_lab::rates::raster_rates(&mut r, n, &sizes, frames, |m| eprintln!("{m}"))?;
            print!("{}", voxsplat_lab::rates::rates_csv(&pts));
            Ok(())
        }
        Study::Peer { n, size, warmup, frames, out_dir, truth_step } => {
            if frames < 5 {
                return Err(Error::InvalidArgument("--frames must be at least 5".into()));
            }
            std::fs::create_dir_all(&out_dir)
                .map_err(|e| Error::Io { path: out_dir.display().to_string(), source: e })?;
            let cam = voxsplat::scene::peer::camera(n, size);
            if let Some(step) = truth_step {
                let t = std::time::Instant::now();
                let vol = voxsplat::scene::peer::volume(n)?;
                let img = voxsplat::truth::ray_integrate_scalars(
                    &vol,
                    &voxsplat::scene::peer::transfer_function(),
                    &cam,
                    step as f64,
                )?;
                voxsplat::output::write_image(&img, &out_dir.join(format!("truth-scalar-{n}.png")))?;
                let set = voxsplat::classify::classify(&vol, &voxsplat::scene::peer::transfer_function(), None)?;
                let opts = voxsplat::truth::TruthOptions {
                    reconstruction: voxsplat::truth::Reconstruction::Trilinear,
                    ..Default::default()
                };
                let img = voxsplat::truth::volumetric_summation(&set, &cam, &opts)?;
                voxsplat::output::write_image(&img, &out_dir.join(format!("truth-classified-{n}.png")))?;
                eprintln!("references in {:.1} s", t.elapsed().as_secs_f64());
            }
            let mut r = Renderer::new(&RendererOptions::default())?;
            println!("label,median_ms");
            for run in voxsplat_lab::peer::time_variants(&mut r, n, size, warmup, frames)? {
                println!("{},{:.2}", run.label, run.median_ms);
                let file = format!("voxsplat-{}-{n}.png", run.label.replace(' ', "-"));
                voxsplat::output::write_image(&run.image, &out_dir.join(file))?;
            }
            Ok(())
        }
        Study::Soak { frames, size, validation } => {
            if frames == 0 || size == 0 {
                return Err(Error::InvalidArgument("--frames and --size must be positive".into()));
            }
            let mut ro = RendererOptions::default();
            ro.validation = validation;
            let mut r = Renderer::new(&ro)?;
            let bar = indicatif::ProgressBar::new(frames as u64);
            let rep = voxsplat_lab::soak::soak(&mut r, frames, size, |_| bar.inc(1))?;
            bar.finish_and_clear();
            println!("frames: {}", rep.frames);
            println!("cycle,rss_mib,gpu_allocations,gpu_bytes");
            for (i, (rss, (n, b))) in rep.rss.iter().zip(&rep.gpu).enumerate() {
                println!("{i},{:.1},{n},{b}", *rss as f64 / (1u64 << 20) as f64);
            }
            let growth = rep.rss_growth() as f64 / (1u64 << 20) as f64;
            println!("rss peak growth after warm-up: {growth:.1} MiB over {} frames", rep.growth_span_frames());
            let step = rep.rss_median_step() as f64 / (1u64 << 20) as f64;
            println!(
                "rss median step per cycle after warm-up: {step:.2} MiB ({} frames per cycle)",
                voxsplat_lab::soak::CYCLE
            );
            println!("validation messages: {}", rep.validation_messages);
            Ok(())
        }
        Study::Matrix(a) => matrix(a),
        Study::Antialias { size, factor, dolly, frames } => {
            if size.is_some_and(|s| !(16..=2048).contains(&s))
                || !(1..=16).contains(&factor)
                || dolly < 2
                || frames == 0
            {
                return Err(Error::InvalidArgument(
                    "--size in 16..=2048, --factor in 1..=16, --dolly at least 2, --frames at least 1".into(),
                ));
            }
            let rows = voxsplat_lab::antialias::study(size, factor, dolly, frames)?;
            print!("{}", voxsplat_lab::antialias::markdown(&rows, factor, dolly));
            Ok(())
        }
        Study::MotionOrders { first, frames, rounds } => {
            if frames == 0 || first + frames > 24 || rounds == 0 {
                return Err(Error::InvalidArgument(
                    "--frames at least 1, --first + --frames at most 24, --rounds at least 1".into(),
                ));
            }
            let (orders, blurs) = voxsplat_lab::motion_orders::study(first, frames, rounds)?;
            print!("{}", voxsplat_lab::motion_orders::markdown(&orders, &blurs, first, frames));
            Ok(())
        }
        Study::Kernels { n, size, frames, chart } => {
            if !(16..=512).contains(&n) || !(16..=4096).contains(&size) || frames == 0 {
                return Err(Error::InvalidArgument("--n in 16..=512, --size in 16..=4096, --frames at least 1".into()));
            }
            let rows = voxsplat_lab::kernels::study(n, size, frames)?;
            if let Some(c) = &chart {
                voxsplat_lab::kernels::chart(&rows, c)?;
            }
            print!("{}", voxsplat_lab::kernels::markdown(&rows, n, size, chart.as_deref()));
            Ok(())
        }
        Study::Modes { size, frames, charts, data } => {
            if !(16..=4096).contains(&size) || frames == 0 {
                return Err(Error::InvalidArgument("--size in 16..=4096, --frames at least 1".into()));
            }
            let volume = |name: &str, file: &str, tf: &str, iso: f32| voxsplat_lab::modes::ModeVolume {
                name: name.into(),
                path: data.join(file),
                tf: tf.into(),
                iso,
            };
            let volumes = [
                volume("bonsai", "bonsai/bonsai.nii.gz", "bonsai", 60.0),
                volume("stent", "stent/stent.nrrd", "ct", 1000.0),
            ];
            let (rows, device) = voxsplat_lab::modes::study(&volumes, size, frames)?;
            let written = voxsplat_lab::modes::charts(&rows, &charts)?;
            print!("{}", voxsplat_lab::modes::markdown(&rows, &device, size, frames, &written));
            Ok(())
        }
        Study::Bricks { chart: Some(csv), chart_out: Some(svg), .. } => voxsplat_lab::bench::scaling_chart(&csv, &svg),
        Study::Bricks {
            bonsai,
            large,
            size,
            frames,
            volume,
            gpu_budget_mib,
            tf,
            orbit,
            arc,
            fov,
            chunk_cache_mib,
            lod_chart,
            ..
        } => {
            if frames < 1 || size < 16 {
                return Err(Error::InvalidArgument("--frames must be at least 1 and --size at least 16".into()));
            }
            if let (Some(v), Some(steps)) = (&volume, orbit) {
                let budget = mib_bytes(gpu_budget_mib, "--gpu-budget-mib")?;
                let arc = voxsplat_lab::bricked::Arc { steps, degrees: arc };
                if let Some(fov) = fov {
                    if !voxsplat::loaders::is_ome_zarr(v) {
                        return Err(Error::InvalidArgument(format!(
                            "--fov orbits an OME-Zarr image a part at a time; {} is read whole (drop --fov)",
                            v.display()
                        )));
                    }
                    let cache = match chunk_cache_mib {
                        0 => 0,
                        m => mib_bytes(m, "--chunk-cache-mib")?,
                    };
                    print!("{}", voxsplat_lab::bricked::zarr_orbit(v, size, budget, &tf, arc, fov, cache)?);
                    return Ok(());
                }
                print!("{}", voxsplat_lab::bricked::orbit(v, size, budget, &tf, arc)?);
                return Ok(());
            }
            match volume {
                Some(v) => println!(
                    "{}",
                    voxsplat_lab::bricked::one_volume(
                        &v,
                        size,
                        mib_bytes(gpu_budget_mib, "--gpu-budget-mib")?,
                        &tf,
                        frames
                    )?
                ),
                None => print!(
                    "{}",
                    voxsplat_lab::bricked::study(&bonsai, large.as_deref(), size, frames, lod_chart.as_deref())?
                ),
            }
            Ok(())
        }
    }
}

/// `voxsplat-lab matrix`.
fn matrix(a: MatrixArgs) -> Result<()> {
    use voxsplat_lab::bench::*;
    let mut m = if a.quick { MatrixOptions::quick() } else { MatrixOptions::full() };
    if let Some(f) = a.frames {
        if f < 5 {
            return Err(Error::InvalidArgument("--frames must be at least 5".into()));
        }
        m.frames = f;
    }
    let io = |p: &std::path::Path| {
        let p = p.display().to_string();
        move |e| Error::Io { path: p, source: e }
    };
    std::fs::create_dir_all(&a.out_dir).map_err(io(&a.out_dir))?;
    let mut r = Renderer::new(&RendererOptions::default())?;
    let device = r.device_name();
    eprintln!("device: {device}");
    let bar = indicatif::ProgressBar::new((m.scenes.len() * m.methods.len()) as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut rows = run_matrix(&mut r, &m, |done, _, label| {
        bar.set_position(done as u64);
        bar.set_message(label.to_string());
    })?;
    bar.finish_and_clear();
    let (aa_size, aa_factor, aa_dolly) = if a.quick { (96, 4, 8) } else { (256, 8, 60) };
    let aa = antialias_study(&mut r, aa_size, aa_factor, aa_dolly, m.frames, |msg| eprintln!("{msg}"))?;
    rows.extend(antialias_rows(&aa, aa_size));
    eprintln!("motion blur...");
    let (mb_size, mb_frame) = if a.quick { (96, 9) } else { (256, 12) };
    let mb = motion_study(&mut r, mb_size, mb_frame, m.frames)?;
    rows.extend(motion_rows(&mb, mb_size));
    let mb_images = write_motion_images(&mb, &a.out_dir)?;
    let stab = voxsplat_lab::stability::run(&mut r, a.quick, |msg| eprintln!("{msg}"))?;
    voxsplat_lab::stability::write_outputs(&stab, &a.out_dir)?;
    write_csv(&rows, &a.out_dir.join("matrix.csv"))?;
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    for sc in &scenes {
        chart_svg(&rows, sc, &a.out_dir.join(format!("chart-{sc}.svg")))?;
    }
    eprintln!("roofline...");
    let (w, h) = (m.width.max(256), m.height.max(256));
    let sizes: &[u32] = if a.quick { &[3, 7] } else { &[3, 7, 15, 31] };
    let frags = if a.quick { 1 << 20 } else { 8 << 20 };
    let roof = roofline(&mut r, w, h, sizes, frags, 5)?;
    let (rate_n, rate_sizes): (u32, &[f32]) =
        if a.quick { (48, &[3.0, 7.0]) } else { (256, &[3.0, 5.0, 7.0, 11.0, 15.0]) };
    let rates =
        voxsplat_lab::rates::raster_rates(&mut r, rate_n, rate_sizes, m.frames.clamp(3, 5), |msg| eprintln!("{msg}"))?;
    voxsplat_lab::rates::write_rates_csv(&rates, &a.out_dir.join("rates.csv"))?;
    voxsplat_lab::rates::rates_svg(&rates, &a.out_dir.join("rates.svg"))?;
    let scale = if a.no_scaling {
        Vec::new()
    } else {
        let (cubes, images): (&[u32], &[u32]) =
            if a.quick { (&[22, 46], &[128, 256]) } else { (&[22, 46, 100, 146], &[128, 256, 512, 1024, 2048]) };
        let s = scaling(&mut r, cubes, images, if a.quick { m.frames } else { 5 }, |msg| eprintln!("{msg}"))?;
        write_scaling_csv(&s, &a.out_dir.join("scaling.csv"))?;
        // The bricked volumes' series (scripts/bricks-vtk.sh, run first by scripts/results.sh).
        let bricks = a.out_dir.join("bricks-scaling.csv");
        let bricks = bricks.exists().then(|| voxsplat_lab::bench::read_scaling_csv(&bricks)).transpose()?;
        scaling_svg(&s, bricks.as_deref(), &a.out_dir.join("scaling.svg"))?;
        s
    };
    if let Some(path) = &a.results {
        // The commit this binary was built from (cli/build.rs), not the checkout's HEAD now.
        let commit = voxsplat_cli::measure::COMMIT.to_string();
        let base = path.parent().unwrap_or(std::path::Path::new("."));
        let chart_dir = pathdiff(&a.out_dir, base);
        let notes_path = base.join("results-notes.md");
        let notes = std::fs::read_to_string(&notes_path).ok();
        let cmd = std::env::args().skip(1).collect::<Vec<_>>().join(" ");
        let roof_rates: Vec<(u32, f64)> = roof.0.iter().map(|p| (p.size_px, p.quads_per_s)).collect();
        let report = Report {
            device,
            commit,
            command: format!("voxsplat {cmd}"),
            rows: &rows,
            roofline: Some(&roof),
            scaling: &scale,
            chart_dir,
            // The modes study's charts (`lab modes`, which scripts/results.sh runs first).
            mode_charts: ["bonsai", "stent"]
                .map(|v| format!("modes-{v}.svg"))
                .into_iter()
                .filter(|f| a.out_dir.join(f).exists())
                .collect(),
            notes,
        };
        // The detail pages, beside the charts they link. The studies that scripts/results.sh runs
        // first (and scripts/peers.sh) wrote theirs; this run writes the rest.
        let written = [
            ("matrix.md", matrix_markdown(&report)?),
            (
                "raster.md",
                voxsplat_lab::rates::rates_markdown(&rates, &roof_rates, &voxsplat_lab::bench::link("", "rates.svg")),
            ),
            ("antialias-plane.md", antialias_markdown(&aa, aa_size, aa_factor, aa_dolly)),
            ("motion.md", motion_markdown(&mb, mb_size, mb_frame, &mb_images, "")),
            ("stability.md", voxsplat_lab::stability::markdown(&stab, "")),
        ];
        for (file, md) in &written {
            let p = a.out_dir.join(file);
            std::fs::write(&p, md).map_err(io(&p))?;
        }
        let mut details = vec![
            Detail {
                file: "matrix.md",
                what: "every method on every scene: stage times, error, the roofline, scaling",
            },
            Detail { file: "raster.md", what: "how footprints become pixels: splat rates by size" },
            Detail { file: "antialias-plane.md", what: "anti-aliasing on the checkerboard plane (chapter 3)" },
            Detail { file: "motion.md", what: "motion blur on the rotating box (chapter 4)" },
            Detail { file: "stability.md", what: "stability where methods fail: popping, brightening" },
        ];
        let studies = [
            ("bricks.md", "bricked volumes: levels of detail, streaming, beside VTK"),
            ("kernels.md", "reconstruction kernels: ripple, error, time"),
            ("antialias.md", "anti-aliasing on the terrain and the stripes"),
            ("motion-orders.md", "visibility orders of motion-blurred frames"),
            ("peers.md", "side by side with VTK and taichi on one scene"),
            ("modes.md", "projection modes (MIP, MinIP, average, X-ray) and isosurfaces: time against compositing, the ray caster"),
        ];
        let mut vtk = None;
        for (file, what) in studies {
            let p = a.out_dir.join(file);
            let Ok(md) = std::fs::read_to_string(&p) else { continue };
            // Written to be read from the results page: their charts' links become the page's own.
            let beside = md.replace("](bench/", "](");
            if beside != md {
                std::fs::write(&p, &beside).map_err(io(&p))?;
            }
            if file == "bricks.md" {
                vtk = section(&beside, "### Beside VTK on the same files").map(|v| relink(&v, &report.chart_dir));
            }
            details.push(Detail { file, what });
        }
        let md = results_markdown(&report, vtk.as_deref(), &details)?;
        std::fs::write(path, md).map_err(io(path))?;
        eprintln!("wrote {}", path.display());
    }
    print!("{}", std::fs::read_to_string(a.out_dir.join("matrix.csv")).map_err(io(&a.out_dir))?);
    Ok(())
}

/// `target` relative to `base` when it lies below it, else as given.
fn pathdiff(target: &std::path::Path, base: &std::path::Path) -> String {
    let t = std::fs::canonicalize(target).unwrap_or_else(|_| target.to_path_buf());
    let b = std::fs::canonicalize(base).unwrap_or_else(|_| base.to_path_buf());
    t.strip_prefix(&b).map(|p| p.display().to_string()).unwrap_or_else(|_| target.display().to_string())
}

/// The section of `md` under `heading` (without it), up to the next heading of its level or above.
fn section(md: &str, heading: &str) -> Option<String> {
    let start = md.find(heading)? + heading.len();
    let level = heading.chars().take_while(|&c| c == '#').count();
    let rest = &md[start..];
    let end = rest
        .lines()
        .scan(0, |at, l| {
            let here = *at;
            *at += l.len() + 1;
            Some((here, l))
        })
        .find(|(_, l)| {
            let hashes = l.chars().take_while(|&c| c == '#').count();
            hashes > 0 && hashes <= level && l[hashes..].starts_with(' ')
        })
        .map_or(rest.len(), |(at, _)| at);
    Some(rest[..end].trim().to_string())
}

/// A detail page's text moved to the results page: its links to files beside it (charts) go
/// through `dir`, the charts' folder as the page sees it.
fn relink(md: &str, dir: &str) -> String {
    let mut out = String::with_capacity(md.len());
    let mut rest = md;
    while let Some(i) = rest.find("](") {
        out.push_str(&rest[..i + 2]);
        rest = &rest[i + 2..];
        let local = !(rest.starts_with("http") || rest.starts_with('#') || rest.starts_with("../"));
        if local && !dir.is_empty() {
            out.push_str(dir);
            out.push('/');
        }
    }
    out.push_str(rest);
    out
}

fn main() -> ExitCode {
    let lab = Lab::parse();
    if let Some(mib) = lab.host_budget_mib {
        voxsplat::options::set_host_budget(Some(mib.saturating_mul(1 << 20)));
    }
    voxsplat_cli::stdout::exit_code(run(lab.study))
}

#[cfg(test)]
mod tests {
    /// clap's own checks of the command line (ids that conflicts and requirements name exist,
    /// headings, ...), which it runs only in debug builds.
    #[test]
    fn the_command_line_passes_clap_s_checks() {
        <super::Lab as clap::CommandFactory>::command().debug_assert();
    }
}
