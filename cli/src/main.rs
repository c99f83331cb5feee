//! The voxsplat command line: list scenes, render a frame, dump or check a visibility order.
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use voxsplat::{
    options::Composite, order::OrderKind, scene, Backend, Error, RenderOptions, Renderer, RendererOptions, Result,
};
use voxsplat_cli::open::*;

mod benchmark;
mod pick;
mod slice;
use voxsplat_cli::render::{self, RenderArgs};
use voxsplat_cli::{print, println};

#[derive(Parser)]
#[command(
    name = "voxsplat",
    version,
    about = "Render volumes (CT, MRI, microscopy, simulation fields) and terrain by splatting, on Vulkan"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Host memory, in MiB, that what a file's header or a flag sizes may take (volumes, frames,
    /// terrains, the store): past it the command stops with an error before allocating, as it does
    /// past what the host has available [default: three quarters of physical memory].
    #[arg(long, global = true)]
    host_budget_mib: Option<u64>,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes.
    Scenes,
    /// Render a scene to a PNG (straight alpha) or EXR (premultiplied alpha).
    Render(Box<RenderArgs>),
    /// Print what one pixel of a view shows: the point along its ray where the volume turns
    /// opaque (or, with --mode mip, the point of the largest value), its voxel, value and depth.
    Pick(Box<pick::PickArgs>),
    /// Write one plane of a volume's voxels, across x, y or z of its grid as the file stores it,
    /// as a grey PNG, windowed.
    Slice(Box<slice::SliceArgs>),
    /// Open a window with the volume and a panel: modes, shading, the transfer function over the
    /// data's histogram, the value under the pointer, sessions and screenshots.
    View(Box<voxsplat_cli::view::ViewArgs>),
    /// Describe a volume or height file: dims, spacing, value range, splats at the default
    /// classification and GPU bytes per splat.
    Info {
        /// The file (.nrrd/.nhdr, .nii/.nii.gz, .npy, .tif, .png, a DICOM file or a folder of DICOM
        /// series or of numbered slices, an OME-Zarr image's folder; raw with --dims and --dtype). A one-page TIFF or a PNG is a
        /// height grid, a TIFF of several pages a volume.
        file: PathBuf,
        #[arg(long, value_parser = parse_dims)]
        dims: Option<[u32; 3]>,
        #[arg(long, value_parser = ["u8", "u16", "i16", "f32"])]
        dtype: Option<String>,
        /// Transfer function for the splat count: a preset (ramp, ct, bonsai) or a TOML file.
        #[arg(long, default_value = "ramp")]
        tf: String,
        /// Vertical exaggeration of a height grid (as `render --vscale`).
        #[arg(long, value_parser = parse_finite, default_value = "1")]
        vscale: f32,
        /// Horizontal cell size of a height grid (as `render --cell`; 0: relief a sixth of the width).
        #[arg(long, value_parser = parse_finite, default_value = "0")]
        cell: f32,
        /// A folder of several DICOM series: the one to describe (its number in the list, or its
        /// UID); without it the series are listed.
        #[arg(long)]
        series: Option<String>,
        /// An OME-Zarr image's pyramid level to describe (its levels are listed; 0 by default).
        #[arg(long)]
        level: Option<u32>,
        /// The time point of a 4-D NIfTI or an OME-Zarr image to describe (needed when it holds
        /// several).
        #[arg(long)]
        time: Option<u32>,
        /// Also print how the volume's values are spread, in this many equal bins over its value
        /// range (bars on a log scale; its empty voxels counted apart): where to put a transfer
        /// function's ramps.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=voxsplat::bricks::MAX_BINS as i64))]
        histogram: Option<u32>,
    },
    /// Render an animation (built-in name or TOML file) to numbered frames and an animated GIF.
    Animate(Box<AnimateArgs>),
    /// Make a test volume: a file upsampled by an integer factor (e.g. a 512³ bonsai from the 256³
    /// one), a procedural field of side N (e.g. 1024³), or a T1 MRI head phantom of side N (placed
    /// in RAS); written as 8-bit NRRD slice by slice, so it may be larger than memory.
    MakeVolume {
        /// Upsample this volume file (any format `render --volume` reads)...
        #[arg(long, conflicts_with = "procedural")]
        from: Option<PathBuf>,
        /// ...by this factor per axis.
        #[arg(long, default_value_t = 2)]
        factor: u32,
        /// The channel of --from to upsample, from 0, when it holds several.
        #[arg(long, requires = "from")]
        channel: Option<u32>,
        /// Or make the procedural field of this side.
        #[arg(long, conflicts_with = "phantom")]
        procedural: Option<u32>,
        /// Or make a T1-weighted MRI head phantom of this side (220 mm across, RAS; for the `mri`
        /// preset: ../shared/data holds no brain MRI).
        #[arg(long, conflicts_with = "from")]
        phantom: Option<u32>,
        /// The NRRD file to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Print error metrics of image A against reference B (PNG or EXR): PSNR and RMSE over the
    /// covered pixels (either image's alpha above 1/255; the figure to quote) and over the whole
    /// frame, the largest difference and SSIM.
    Compare {
        /// The image to score.
        a: PathBuf,
        /// The reference.
        b: PathBuf,
    },
    /// Measure this machine's GPU: a fixed suite of named cases (scenes, the gallery files, the 512³
    /// bonsai and the 1024³ field, terrain, motion blur, MIP and iso), each drawn with the defaults;
    /// frame times, frames per second, splats a second, memory, PSNR against a truth, and a score.
    Bench(Box<benchmark::BenchArgs>),
    /// Describe the Vulkan device voxsplat would use: what it reports, and every choice voxsplat
    /// makes from it (raster path, subgroup build, timing, limits, memory budget, fallbacks).
    Device {
        /// Pick the device whose name contains this text.
        #[arg(long)]
        name: Option<String>,
        /// Print the profile as TOML (what tests/data/devices records), nothing else.
        #[arg(long)]
        toml: bool,
    },
}

#[derive(Args)]
struct AnimateArgs {
    /// A built-in animation (rotating-box, spinning-box, rotating-terrain, rotating-terrain-ortho)
    /// or a TOML file [default: rotating-box]. Not with --volume, whose time points are the frames.
    #[arg(long)]
    anim: Option<String>,
    /// none, splat (motion-blurred splats) or accum:N (N sub-frames averaged). Blurred splats
    /// take a path and a profile: splat:arc bends each path through its halfway point,
    /// splat:tapered averages the footprint over the shutter, splat:teardrop weights it towards
    /// the frame's time, splat:slotted composites the two halves of the shutter apart (the
    /// closest to accum:N); joined with '+', e.g. splat:arc+slotted [default: splat]. Not with
    /// --volume.
    #[arg(long)]
    blur: Option<String>,
    /// How footprints accumulate: composited per splat, or summed into Westover's axis-aligned
    /// sheets (`--mode composite`, the picture, is another idea).
    #[arg(long, default_value = "splat", value_parser = ["splat", "sheet"])]
    accumulate: String,
    /// Frame files: png or exr.
    #[arg(long, default_value = "png", value_parser = ["png", "exr"])]
    format: String,
    /// Where the frames and anim.gif go.
    #[arg(long, default_value = "anim-out")]
    out_dir: PathBuf,
    /// With --volume (a 4-D NIfTI, or an OME-Zarr image with a time axis): one frame per time
    /// point, from the view the scene flags describe, the whole series classified by one
    /// transfer function over its value range; an OME-Zarr image that --eye and --target see in
    /// part is read only there. Without it, the animation's own scene and camera (only --cpu
    /// and --validation apply).
    #[command(flatten)]
    scene: SceneArgs,
    /// The scene flags given on the command line, a default's value included (an animation
    /// refuses them: `refuse_scene_flags`).
    #[arg(skip)]
    given: Vec<String>,
}

/// An OME-Zarr image's axes and pyramid, one line per level.
fn print_ome_zarr(image: &voxsplat::loaders::OmeZarr) {
    let axes: Vec<String> = image
        .axes
        .iter()
        .map(|a| match &a.unit {
            Some(u) => format!("{} ({u})", a.name),
            None => a.name.clone(),
        })
        .collect();
    println!(
        "OME-Zarr {} '{}': axes {}; {} time point(s), {} channel(s)",
        image.version,
        image.name.as_deref().unwrap_or(""),
        axes.join(", "),
        image.times,
        image.channels
    );
    for (i, l) in image.levels.iter().enumerate() {
        println!(
            "level {i} '{}': {:?} voxels, spacing {:?}, origin {:?}, chunks {:?}, {} {}",
            l.path,
            l.dims,
            l.spacing,
            l.origin,
            l.chunk,
            l.dtype,
            l.codecs.join("+")
        );
    }
}

/// `store`'s histogram in `bins` bins (`info --histogram`), one line a bin: its values, its voxels and
/// a bar as long as its log height.
fn print_histogram(store: &voxsplat::bricks::BrickStore, bins: u32) -> Result<()> {
    let h = store.histogram(bins)?;
    println!(
        "histogram: {bins} bins of the stored values {} .. {}, bars on a log scale ({} voxels empty, not counted)",
        h.range.0, h.range.1, h.empty
    );
    for (i, (count, height)) in h.counts.iter().zip(h.log_heights()).enumerate() {
        let bar = "#".repeat((height * 40.0).round() as usize);
        println!("{:>12} .. {:<12} {count:>12} {bar}", h.edge(i), h.edge(i + 1));
    }
    Ok(())
}

fn print_store(store: &voxsplat::bricks::BrickStore) {
    let per_voxel = |bytes: u64| bytes as f64 / store.len().max(1) as f64;
    let pyramid = voxsplat::low_level::pyramid_bytes(store.headers.len());
    println!(
        "bricked store: {} stored voxels in {} bricks of {}^3, {} bytes on the GPU, {:.2} bytes per stored voxel \
         ({:.2} with the levels-of-detail pyramid of --lod auto; shaded or gradient-weighted frames add {:.2} for \
         each voxel's central differences)",
        store.len(),
        store.headers.len(),
        voxsplat::bricks::BRICK,
        store.bytes(),
        per_voxel(store.bytes()),
        per_voxel(store.bytes() + pyramid),
        per_voxel(store.gradient_len() * 8)
    );
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Scenes => {
            for (name, about) in scene::SCENES {
                println!("{name:<18} {about}");
            }
            Ok(())
        }
        Command::Render(a) => render::render(a),
        Command::Pick(a) => pick::pick(*a),
        Command::Slice(a) => slice::slice(*a),
        Command::View(a) => voxsplat_cli::view::view(*a),
        Command::Animate(a) => animate(a),
        Command::MakeVolume { from, factor, channel, procedural, phantom, out } => {
            // It writes NRRD (raw data, attached): a name that says otherwise would mislead.
            if !out.to_string_lossy().to_ascii_lowercase().ends_with(".nrrd") {
                return Err(Error::InvalidArgument(format!(
                    "make-volume writes NRRD: name the output .nrrd, not {}",
                    out.display()
                )));
            }
            let bar = indicatif::ProgressBar::new(0);
            let t = std::time::Instant::now();
            let dims = match (from, procedural.or(phantom)) {
                (None, Some(n)) if phantom.is_some() => {
                    bar.set_length(n as u64);
                    voxsplat_cli::volumes::head_phantom(n, &out, |z| bar.set_position(z as u64))?
                }
                (Some(file), None) => {
                    if voxsplat_cli::uneven::at_positions(&file, &Default::default())? {
                        return Err(Error::InvalidArgument(format!(
                            "{}: its slice gaps are too uneven to resample evenly, and make-volume writes an evenly \
                             spaced NRRD; render draws it at its slices' positions",
                            file.display()
                        )));
                    }
                    let vol = match slice::picked_channel(&file, &Default::default(), channel)? {
                        Some(v) => v,
                        None => voxsplat::loaders::load_volume(&file, &Default::default())?,
                    };
                    let placement = voxsplat::loaders::load_orientation(&file, &Default::default())?;
                    bar.set_length(vol.dims[2] as u64 * factor as u64);
                    voxsplat_cli::volumes::upsample(&vol, factor, placement.as_ref(), &out, |z| {
                        bar.set_position(z as u64)
                    })?
                }
                (None, Some(n)) => {
                    bar.set_length(n as u64);
                    voxsplat_cli::volumes::procedural(n, &out, |z| bar.set_position(z as u64))?
                }
                _ => return Err(Error::InvalidArgument("give --from FILE, --procedural N or --phantom N".into())),
            };
            bar.finish_and_clear();
            println!(
                "{} x {} x {} voxels -> {} in {:.1} s",
                dims[0],
                dims[1],
                dims[2],
                out.display(),
                t.elapsed().as_secs_f64()
            );
            Ok(())
        }
        Command::Info { file, dims, dtype, tf, vscale, cell, series, level, time, histogram } => {
            if voxsplat::loaders::is_ome_zarr(&file) {
                let image = voxsplat::loaders::OmeZarr::open(&file)?;
                print_ome_zarr(&image);
                if image.channels > 1 {
                    println!("{} channels: render them with --channel-tf for each after the first", image.channels);
                    return Ok(());
                }
            }
            // A folder of DICOM series: each listed, and the one picked (or the only one) described.
            if file.is_dir() && !voxsplat::loaders::is_ome_zarr(&file) {
                let scan = voxsplat::loaders::dicom_series(&file)?;
                let all = &scan.series;
                for (i, s) in all.iter().enumerate() {
                    let times =
                        if s.times > 1 { format!(", {} time points (--time N)", s.times) } else { String::new() };
                    println!(
                        "series {i}: {} {} '{}', {:?} (columns, rows, images){times}",
                        s.uid, s.modality, s.description, s.dims
                    );
                }
                if all.len() > 1 && series.is_none() {
                    // (A series described says so itself, with the images it leaves out.)
                    if let Some(note) = scan.note() {
                        eprintln!("note: {note}");
                    }
                    println!("{} series: describe one with --series N or UID", all.len());
                    return Ok(());
                }
            }
            let name = file.display().to_string().to_ascii_lowercase();
            // A TIFF of several pages, or a folder of slices, is a volume.
            let heights = (name.ends_with(".tif") || name.ends_with(".tiff") || name.ends_with(".png"))
                && !voxsplat::loaders::is_stack(&file)?
                || (name.ends_with(".npy") && voxsplat::loaders::npy_shape(&file)?.len() == 2);
            if heights && (dims.is_some() || dtype.is_some() || tf != "ramp" || histogram.is_some()) {
                return Err(Error::InvalidArgument(
                    "--dims, --dtype, --tf and --histogram describe volumes, not height grids".into(),
                ));
            }
            if !heights && (vscale != 1.0 || cell != 0.0) {
                return Err(Error::InvalidArgument("--vscale and --cell describe height grids, not volumes".into()));
            }
            let tf = load_tf(&tf)?;
            let set = if heights {
                let h = voxsplat::loaders::load_heights(&file)?;
                let (lo, hi) =
                    h.heights.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
                println!("height grid: {} x {} cells, heights {lo} .. {hi}", h.width, h.rows);
                // The columns `render --terrain` draws with the same --cell and --vscale.
                let opts = voxsplat::terrain::TerrainOptions { cell, vscale, ..Default::default() };
                voxsplat::terrain::terrain_splats(&h, &opts)?
            } else {
                // A series: the time point asked for, else the first.
                let times = voxsplat::loaders::time_points(&file)?;
                if times > 1 {
                    println!(
                        "{times} time points (a series: --time N describes one, time point {} below; animate --volume \
                         plays them all)",
                        time.unwrap_or(0)
                    );
                }
                let hints = voxsplat::loaders::VolumeHints {
                    dims,
                    dtype: dtype.as_deref().map(str::parse).transpose()?,
                    series: series.clone(),
                    level,
                    time: time.or((times > 1).then_some(0)),
                    ..Default::default()
                };
                voxsplat_cli::uneven::say_left_out(&file, &hints)?;
                match voxsplat::loaders::load_orientation(&file, &hints)? {
                    Some(o) => {
                        let [ij, ik, jk] = o.angles();
                        println!(
                            "orientation: {} (i, j, k run toward {}; world RAS+, grid centre at {:.2?}{}{})",
                            o.code(),
                            o.code().chars().map(String::from).collect::<Vec<_>>().join(", "),
                            o.to_world(voxsplat::glam::Vec3::ZERO).to_array(),
                            if o.flip_x() { "; left-handed: x stored reversed" } else { "" },
                            if o.is_sheared() {
                                format!("; sheared: axes i-j at {ij:.1}, i-k at {ik:.1}, j-k at {jk:.1} degrees")
                            } else {
                                String::new()
                            }
                        )
                    }
                    None => println!("orientation: none (no anatomical frame: --view framing)"),
                }
                // A file of several channels: each described (render draws them with --channel-tf).
                let channels = voxsplat::loaders::SliceReader::channels(&file)?;
                if channels > 1 {
                    println!("{channels} channels: render draws them with --channel-tf for each after the first");
                    for (k, v) in voxsplat::loaders::load_channels(&file, &hints)?.iter().enumerate() {
                        println!(
                            "channel {k}: {:?} voxels, spacing {:?}, values {}",
                            v.dims,
                            v.spacing,
                            span(&v.values)
                        );
                    }
                    return Ok(());
                }
                // Past the dense loader (a file read slice by slice, of more than MAX_VOXELS): the store only.
                if let Some(reader) = voxsplat::loaders::SliceReader::open(&file, &hints)? {
                    let voxels: u64 = reader.dims.iter().map(|&d| d as u64).product();
                    if voxels > voxsplat::loaders::MAX_VOXELS {
                        drop(reader);
                        let (bar, progress) = voxsplat_cli::progress::load_bar(&file);
                        let hints = voxsplat::loaders::VolumeHints { progress: Some(progress), ..hints };
                        let store = voxsplat::bricks::BrickStore::load(&file, &hints)?;
                        bar.finish_and_clear();
                        println!(
                            "volume: {:?} voxels, spacing {:?}, values {} .. {}",
                            store.dims,
                            store.spacing,
                            held(store.range.0),
                            held(store.range.1)
                        );
                        print_store(&store);
                        histogram.map(|bins| print_histogram(&store, bins)).transpose()?;
                        println!(
                            "splats: not counted (more than the dense loader's {} voxels): rendered bricked",
                            voxsplat::loaders::MAX_VOXELS
                        );
                        return Ok(());
                    }
                }
                let v = voxsplat::loaders::load_volume(&file, &hints)?;
                println!("volume: {:?} voxels, spacing {:?}, values {}", v.dims, v.spacing, span(&v.values));
                let store = voxsplat::bricks::BrickStore::build(&v)?;
                print_store(&store);
                histogram.map(|bins| print_histogram(&store, bins)).transpose()?;
                voxsplat::classify::classify(&v, &tf, None)?
            };
            println!("splats: {}", set.len());
            println!(
                "bytes per splat (classified on the host, voxsplat-lab render --dense): {:.0}",
                voxsplat::volume::gpu_bytes_per_splat(&set)
            );
            let most = voxsplat::low_level::MAX_GPU_SPLATS as usize;
            if set.len() > most {
                println!("over the dense GPU path's {most} splats: render it bricked (the default for volumes)");
            }
            Ok(())
        }
        Command::Compare { a, b } => {
            let (x, y) = (voxsplat::output::read_image(&a)?, voxsplat::output::read_image(&b)?);
            let m = voxsplat::metrics::compare(&x, &y)?;
            // Covered first: the figure to quote. The whole frame counts the empty background
            // both images agree on as right, which flatters a small object.
            let n = x.pixels.len();
            println!("covered:    {} of {} pixels (alpha above 1/255 in either image)", m.covered_pixels, n);
            println!("psnr:       {:.2} dB over the covered pixels", m.covered_psnr);
            println!("rmse:       {:.6} over the covered pixels", m.covered_rmse);
            println!("psnr_frame: {:.2} dB over the whole frame", m.psnr);
            println!("rmse_frame: {:.6} over the whole frame", m.rmse);
            println!("max_abs:    {:.6}", m.max_abs);
            println!("ssim_luma:  {:.5}", m.ssim_luma);
            println!("ssim_alpha: {:.5}", m.ssim_alpha);
            Ok(())
        }
        Command::Bench(a) => benchmark::bench(*a),
        Command::Device { name, toml } => {
            let ctx =
                voxsplat::vk::Context::new(&voxsplat::vk::ContextOptions { validation: false, device_name: name })?;
            if toml {
                print!("{}", voxsplat_cli::device_toml(ctx.profile())?);
            } else {
                print!("{}", voxsplat_cli::describe_device(ctx.profile()));
            }
            Ok(())
        }
    }
}

fn animate(a: Box<AnimateArgs>) -> Result<()> {
    use voxsplat::animate::{render_frame, Animation, Blur};
    voxsplat::output::ImageFormat::of(std::path::Path::new(&format!("frame.{}", a.format)))?;
    let composite = a.accumulate.parse::<Composite>()?;
    let out = |dir: &std::path::Path| {
        std::fs::create_dir_all(dir).map_err(|e| Error::Io { path: dir.display().to_string(), source: e })?;
        // Frames go to the GIF as they are drawn: one frame held at a time.
        voxsplat::output::GifWriter::create(&dir.join("anim.gif"), 1000 / 12)
    };
    let write = |i: u32, img: &voxsplat::image::ImageF32, gif: &mut voxsplat::output::GifWriter| {
        voxsplat::output::write_image(img, &a.out_dir.join(format!("frame{i:04}.{}", a.format)))?;
        gif.push(img)
    };
    if a.scene.volume.is_some() {
        if let Some(flag) = [(a.anim.is_some(), "--anim"), (a.blur.is_some(), "--blur")].iter().find(|f| f.0) {
            return Err(Error::InvalidArgument(format!(
                "{} with --volume: its time points are the frames, drawn from one view (the scene flags)",
                flag.1
            )));
        }
        // As `render` draws a volume (the library's defaults), so that frame t is `render --time t`'s.
        let mut opts = RenderOptions::default();
        opts.composite = composite;
        let mut gif = out(&a.out_dir)?;
        let report = voxsplat_cli::series::play(&a.scene, &opts, |t, img| write(t, img, &mut gif))?;
        gif.finish()?;
        eprintln!("{report}\nframes -> {}", a.out_dir.display());
        return Ok(());
    }
    refuse_scene_flags(&a.scene, &a.given)?;
    let anim = a.anim.as_deref().unwrap_or("rotating-box");
    let anim = if anim.ends_with(".toml") {
        let text = voxsplat::loaders::read_text(std::path::Path::new(anim), anim)?;
        Animation::from_toml(&text)?
    } else {
        Animation::builtin(anim)?
    };
    let blur: Blur = a.blur.as_deref().unwrap_or("splat").parse()?;
    let set = scene::build(&anim.scene)?;
    let grid = *set.grid();
    anim.check_path(&grid, blur)?;
    let mut opts = RenderOptions::default();
    opts.composite = composite;
    opts.order = a.scene.research.order.parse::<OrderKind>()?;
    let mut r = renderer_of(&a.scene)?;
    r.set_scene(set)?;
    let mut gif = out(&a.out_dir)?;
    let bar = indicatif::ProgressBar::new(anim.frames as u64);
    for i in 0..anim.frames {
        let img = render_frame(&mut r, &anim, &grid, i, blur, &opts)?;
        write(i, &img, &mut gif)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    gif.finish()?;
    report_validation(&r)?;
    eprintln!("{} frames -> {}", anim.frames, a.out_dir.display());
    Ok(())
}

/// An animation sets its own scene and camera: the scene flags (other than --cpu and --validation)
/// would be ignored.
fn refuse_scene_flags(s: &SceneArgs, given: &[String]) -> Result<()> {
    let named = |id: &str| given.iter().any(|g| g == id);
    let given = [
        (named("scene"), "--scene"),
        (s.eye.is_some() || s.target.is_some() || s.up.is_some(), "--eye, --target and --up"),
        (s.fov.is_some() || s.ortho.is_some() || s.near.is_some() || s.far.is_some(), "the projection flags"),
        (named("size"), "--size"),
        (named("view"), "--view"),
        (s.tf.is_some() || s.shade.is_some(), "--tf and --shade"),
        (s.labels.is_some() || !s.channels.is_empty() || !s.channel_tfs.is_empty(), "--labels and --channel"),
        (s.terrain.is_some() || s.color.is_some() || named("vscale") || named("cell"), "the terrain flags"),
        (s.series.is_some() || s.level.is_some() || s.time.is_some(), "--series, --level and --time"),
        (s.gpu_budget_mib.is_some(), "--gpu-budget-mib"),
    ];
    match given.iter().find(|g| g.0) {
        Some((_, flags)) => Err(Error::InvalidArgument(format!(
            "{flags}: an animation (--anim) sets its own scene and camera; --volume plays a volume's time points"
        ))),
        None => Ok(()),
    }
}

fn main() -> ExitCode {
    let matches = <Cli as clap::CommandFactory>::command().get_matches();
    let mut cli = match <Cli as clap::FromArgMatches>::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    if let (Command::Animate(a), Some(("animate", m))) = (&mut cli.command, matches.subcommand()) {
        a.given = m
            .ids()
            .filter(|id| m.value_source(id.as_str()) == Some(clap::parser::ValueSource::CommandLine))
            .map(|id| id.to_string())
            .collect();
    }
    if let Some(mib) = cli.host_budget_mib {
        voxsplat::options::set_host_budget(Some(mib.saturating_mul(1 << 20)));
    }
    voxsplat_cli::stdout::exit_code(run(cli))
}

/// The least and greatest of `values` as `info` prints them (`held`).
fn span(values: &[f32]) -> String {
    let (lo, hi) = values.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    format!("{} .. {}", held(lo), held(hi))
}

/// A value as the engine holds it: past f32's 2^24 whole numbers, every digit of the f32 (its
/// shortest form, "4294967000", would name a value it does not hold).
fn held(v: f32) -> String {
    if (16777216.0..1e15).contains(&v.abs()) {
        format!("{}", v as f64)
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    /// clap's own checks of the command line (ids that conflicts and requirements name exist,
    /// headings, ...), which it runs only in debug builds.
    #[test]
    fn the_command_line_passes_clap_s_checks() {
        <super::Cli as clap::CommandFactory>::command().debug_assert();
    }
}
