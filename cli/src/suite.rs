//! `voxsplat bench`: a fixed, versioned suite of named cases, each drawn as `voxsplat render` draws
//! it by default, timed after a warm-up, and scored against its cached truth (docs/BENCHMARK.md).
use crate::open::{camera_of, normalised_iso, open, renderer_of};
use crate::scene_args::SceneArgs;
use clap::Parser;
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxsplat::{options::Mode, Error, RenderOptions, Renderer, Result};

mod report;
pub use report::{compare, score, CaseResult, Platform, Report};

/// The suite's version: it changes whenever a case, its view, its options or the score's definition
/// does, and reports of different versions are not compared.
pub const SUITE_VERSION: u32 = 1;

/// Where a case's scene comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Source {
    /// A built-in scene (`voxsplat scenes`).
    Scene(&'static str),
    /// A file under the data folder, with its transfer-function preset.
    File { path: &'static str, tf: &'static str },
    /// A data file upsampled by `factor` a side, made once into the cache folder.
    Upsampled { from: &'static str, factor: u32, tf: &'static str },
    /// The procedural field of side `side`, made once into the cache folder.
    Procedural { side: u32, tf: &'static str },
    /// A built-in animation's frames with motion-blurred splats (`voxsplat animate --blur splat`).
    Animation(&'static str),
}

/// What a case draws besides the defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CaseMode {
    /// Composited, as `render` draws by default.
    Default,
    /// Maximum intensity projection.
    Mip,
    /// The isosurface at this value, in the file's units.
    Iso(f32),
}

/// One named case of the suite.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    /// Its name in reports.
    pub name: &'static str,
    /// What it measures.
    pub about: &'static str,
    /// Its scene.
    pub source: Source,
    /// Its mode.
    pub mode: CaseMode,
    /// Frame width and height.
    pub size: [u32; 2],
    /// In `--quick`.
    pub quick: bool,
    /// Scored against a truth (the volumetric-summation truth of a built-in scene, the ray caster
    /// at a quarter-voxel step for a file); the made volumes (whose dense splat sets would not
    /// fit), the isosurface, the bricked peers' scene and the animation have none.
    pub truth: bool,
}

const BONSAI: &str = "bonsai/bonsai.nii.gz";

/// Suite 1: one case a row.
#[rustfmt::skip]
pub const SUITE: &[Case] = &[
    Case { name: "cube60", about: "the seed's hollow 60³ cube: thin sheets of splats, the PBTF order's test", source: Source::Scene("cube60"), mode: CaseMode::Default, size: [512, 512], quick: true, truth: true },
    Case { name: "plane", about: "one 498×398 sheet of splats face on: fill rate", source: Source::Scene("plane"), mode: CaseMode::Default, size: [512, 512], quick: true, truth: true },
    Case { name: "peer128", about: "the peers' synthetic 128³ volume (VTK and taichi draw it too)", source: Source::Scene("peer128"), mode: CaseMode::Default, size: [512, 512], quick: false, truth: false },
    Case { name: "bonsai", about: "CT of a bonsai, 256³, bricked with levels of detail", source: Source::File { path: BONSAI, tf: "bonsai" }, mode: CaseMode::Default, size: [512, 512], quick: true, truth: true },
    Case { name: "bonsai-mip", about: "the bonsai as a maximum intensity projection", source: Source::File { path: BONSAI, tf: "bonsai" }, mode: CaseMode::Mip, size: [512, 512], quick: true, truth: true },
    Case { name: "bonsai-iso", about: "the bonsai's isosurface at 60: surface splats", source: Source::File { path: BONSAI, tf: "bonsai" }, mode: CaseMode::Iso(60.0), size: [512, 512], quick: false, truth: false },
    Case { name: "stent", about: "CT of a stented aorta, 128×128×256", source: Source::File { path: "stent/stent.nrrd", tf: "ct" }, mode: CaseMode::Default, size: [512, 512], quick: false, truth: true },
    Case { name: "heptane", about: "a heptane flame simulation, 302³", source: Source::File { path: "heptane/heptane.nii.gz", tf: "ramp" }, mode: CaseMode::Default, size: [512, 512], quick: false, truth: true },
    Case { name: "terrain", about: "Rocky Mountain NP heights as voxel columns with Landsat colour", source: Source::Scene("rmnp"), mode: CaseMode::Default, size: [512, 512], quick: true, truth: true },
    Case { name: "motion", about: "the turning cube's frames with motion-blurred splats", source: Source::Animation("rotating-box"), mode: CaseMode::Default, size: [512, 512], quick: true, truth: false },
    Case { name: "bonsai512", about: "the bonsai upsampled to 512³ (made once into the cache)", source: Source::Upsampled { from: BONSAI, factor: 2, tf: "bonsai" }, mode: CaseMode::Default, size: [512, 512], quick: false, truth: false },
    Case { name: "field1024", about: "the procedural 1024³ field at 1920×1080 (1 GiB, made once into the cache)", source: Source::Procedural { side: 1024, tf: "ramp" }, mode: CaseMode::Default, size: [1920, 1080], quick: false, truth: false },
];

/// How the suite runs.
#[derive(Clone, Debug)]
pub struct SuiteOptions {
    /// The cases to run, by name (all of the chosen suite when empty).
    pub cases: Vec<String>,
    /// The quick suite and its fewer frames.
    pub quick: bool,
    /// Untimed frames before the timed ones.
    pub warmup: usize,
    /// Timed frames.
    pub frames: usize,
    /// The data folder (`../shared/data` or `VOXSPLAT_DATA`).
    pub data: PathBuf,
    /// Where made volumes and truths are kept between runs.
    pub cache: PathBuf,
    /// Khronos validation on (timings then mean nothing: the report says so).
    pub validation: bool,
    /// The CPU mirrors instead of Vulkan.
    pub cpu: bool,
}

/// The cases `opts` selects, or an error naming an unknown one.
pub fn selected(opts: &SuiteOptions) -> Result<Vec<Case>> {
    for name in &opts.cases {
        if !SUITE.iter().any(|c| c.name == name) {
            let names: Vec<_> = SUITE.iter().map(|c| c.name).collect();
            return Err(Error::InvalidArgument(format!(
                "no case '{name}' in suite {SUITE_VERSION}: {}",
                names.join(", ")
            )));
        }
    }
    Ok(SUITE
        .iter()
        .filter(|c| if opts.cases.is_empty() { c.quick || !opts.quick } else { opts.cases.iter().any(|n| n == c.name) })
        .copied()
        .collect())
}

#[derive(Parser)]
struct Flags {
    #[command(flatten)]
    scene: SceneArgs,
}

/// The render flags a case stands for (`voxsplat render` with these draws its frame).
pub fn case_flags(case: &Case, opts: &SuiteOptions) -> Result<Vec<String>> {
    let mut f: Vec<String> = Vec::new();
    let file = |p: &str| opts.data.join(p).to_string_lossy().into_owned();
    match case.source {
        Source::Scene(s) => f.extend(["--scene".into(), s.into()]),
        Source::File { path, tf } => f.extend(["--volume".into(), file(path), "--tf".into(), tf.into()]),
        Source::Upsampled { tf, .. } | Source::Procedural { tf, .. } => {
            let made = made_volume(case, opts)?;
            f.extend(["--volume".into(), made.to_string_lossy().into_owned(), "--tf".into(), tf.into()]);
        }
        Source::Animation(_) => {}
    }
    f.extend(["--size".into(), format!("{}x{}", case.size[0], case.size[1])]);
    if opts.validation {
        f.push("--validation".into());
    }
    if opts.cpu {
        f.push("--cpu".into());
    }
    Ok(f)
}

/// Why `case` cannot run here: its data file is missing (`None`: it can).
pub fn missing(case: &Case, opts: &SuiteOptions) -> Option<String> {
    let file = match case.source {
        Source::File { path, .. } | Source::Upsampled { from: path, .. } => path,
        Source::Scene("rmnp") => "rmnp/rmnp-dem.tif",
        _ => return None,
    };
    let path = opts.data.join(file);
    (!path.exists()).then(|| format!("{} is missing (give --data DIR)", path.display()))
}

/// Where a made volume lives in the cache.
pub fn made_path(case: &Case, cache: &Path) -> Option<PathBuf> {
    match case.source {
        // Named by the suite's version, as the truths are: a new version makes them again.
        Source::Upsampled { factor, .. } => Some(cache.join(format!("v{SUITE_VERSION}-{}-x{factor}.nrrd", case.name))),
        Source::Procedural { side, .. } => Some(cache.join(format!("v{SUITE_VERSION}-field{side}.nrrd"))),
        _ => None,
    }
}

/// The case's made volume, made now when the cache lacks it.
fn made_volume(case: &Case, opts: &SuiteOptions) -> Result<PathBuf> {
    let path = made_path(case, &opts.cache).expect("a made source");
    if path.exists() {
        return Ok(path);
    }
    std::fs::create_dir_all(&opts.cache).map_err(|e| io_error(&opts.cache, e))?;
    // Written under another name first: an interrupted make leaves no half file behind.
    let part = path.with_extension("part.nrrd");
    let bar = indicatif::ProgressBar::new(0).with_message(format!("{}: making {}", case.name, path.display()));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} {bar:30} {percent}% {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    match case.source {
        Source::Upsampled { from, factor, .. } => {
            let src = opts.data.join(from);
            let vol = voxsplat::loaders::load_volume(&src, &Default::default())?;
            let placement = voxsplat::loaders::load_orientation(&src, &Default::default())?;
            bar.set_length(vol.dims[2] as u64 * factor as u64);
            crate::volumes::upsample(&vol, factor, placement.as_ref(), &part, |z| bar.set_position(z as u64))?;
        }
        Source::Procedural { side, .. } => {
            bar.set_length(side as u64);
            crate::volumes::procedural(side, &part, |z| bar.set_position(z as u64))?;
        }
        _ => unreachable!("made_path is Some only for made sources"),
    }
    bar.finish_and_clear();
    std::fs::rename(&part, &path).map_err(|e| io_error(&path, e))?;
    Ok(path)
}

fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}

/// `render`'s default options (the library's) for a case's mode.
fn case_options(case: &Case) -> RenderOptions {
    let mut o = RenderOptions::default();
    o.mode = match case.mode {
        CaseMode::Default => Mode::Composite,
        CaseMode::Mip => Mode::Mip,
        CaseMode::Iso(_) => Mode::Iso,
    };
    o
}

/// Clear the process's peak resident memory (Linux: `clear_refs` 5), so each case reports its own.
fn reset_peak_rss() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// Draws a case's frame `i`.
type Draw = Box<dyn FnMut(&mut Renderer, u32) -> Result<voxsplat::Rendered>>;
/// Makes a case's truth.
type Truth = Box<dyn FnOnce() -> Result<voxsplat::image::ImageF32>>;

/// A case, loaded and ready to draw.
struct Loaded {
    renderer: Renderer,
    draw: Draw,
    splats_stored: u64,
    truth: Option<Truth>,
}

fn load(case: &Case, opts: &SuiteOptions) -> Result<Loaded> {
    let flags = case_flags(case, opts)?;
    // SceneArgs holds no Clone: the truth's copy is parsed anew from the same flags.
    let parse = || {
        Flags::try_parse_from(std::iter::once("bench".to_string()).chain(flags.iter().cloned()))
            .map(|f| f.scene)
            .map_err(|e| Error::InvalidArgument(format!("case {}: {e}", case.name)))
    };
    let scene = parse()?;
    let mut o = case_options(case);
    if let Source::Animation(name) = case.source {
        use voxsplat::animate::{render_frame_timed, Animation, Blur};
        let anim = Animation::builtin(name)?;
        let blur: Blur = "splat".parse()?;
        let set = voxsplat::scene::build(&anim.scene)?;
        let grid = *set.grid();
        anim.check_path(&grid, blur)?;
        let mut r = renderer_of(&scene)?;
        let stored = set.len() as u64;
        r.set_scene(set)?;
        // Frames 1.. of the animation, round again past its last: each a blurred view of its own.
        let draw = move |r: &mut Renderer, i: u32| {
            let (image, gpu) = render_frame_timed(r, &anim, &grid, 1 + i % (anim.frames - 1).max(1), blur, &o)?;
            let timings = vec![voxsplat::options::StageTime { stage: "frame", ms: gpu }];
            Ok(voxsplat::Rendered { image, timings, raster: None, stats: Default::default() })
        };
        return Ok(Loaded { renderer: r, draw: Box::new(draw), splats_stored: stored, truth: None });
    }
    let (bricked, set, content) = open(&scene, false)?;
    let iso = match case.mode {
        CaseMode::Iso(v) => Some(v),
        _ => None,
    };
    o.iso = normalised_iso(bricked.as_ref(), &scene, iso)?;
    o.validate()?;
    let cam = camera_of(&scene, set.grid(), &content)?;
    let mut r = renderer_of(&scene)?;
    let stored = bricked.as_ref().map_or(set.len() as u64, |b| b.store.len() as u64);
    let truth: Option<Truth> = match case.source {
        Source::Scene(_) if case.truth => {
            let (set, kernel) = (set.clone(), o.kernel);
            Some(Box::new(move || {
                let t = voxsplat::truth::TruthOptions {
                    reconstruction: voxsplat::truth::Reconstruction::Kernel(kernel),
                    ..Default::default()
                };
                voxsplat::truth::volumetric_summation(&set, &cam, &t)
            }))
        }
        Source::File { .. } if case.truth => {
            let (mode, scene) = (o.mode, parse()?);
            Some(Box::new(move || {
                // The ray caster reads the host's splats, on a renderer of its own.
                let (_, set, _) = open(&scene, true)?;
                let mut t = renderer_of(&scene)?;
                t.set_scene(set)?;
                let step = 0.25;
                Ok(t.raycast(&cam, &voxsplat::options::RaycastOptions { mode, step, ..Default::default() })?.image)
            }))
        }
        _ => None,
    };
    match bricked {
        Some(b) => r.set_bricks(b)?,
        None => r.set_scene(set)?,
    }
    let draw = move |r: &mut Renderer, _: u32| r.render(&cam, &o);
    Ok(Loaded { renderer: r, draw: Box::new(draw), splats_stored: stored, truth })
}

/// The case's truth, from the cache or made now (and cached as EXR).
fn truth_image(case: &Case, opts: &SuiteOptions, l: &mut Loaded) -> Result<Option<voxsplat::image::ImageF32>> {
    let Some(make) = l.truth.take() else { return Ok(None) };
    let path = opts.cache.join(format!("truth-v{SUITE_VERSION}-{}-{}x{}.exr", case.name, case.size[0], case.size[1]));
    if let Ok(img) = voxsplat::output::read_image(&path) {
        return Ok(Some(img));
    }
    let img = make()?;
    std::fs::create_dir_all(&opts.cache).map_err(|e| io_error(&opts.cache, e))?;
    voxsplat::output::write_image(&img, &path)?;
    Ok(Some(img))
}

/// Run one case: load, warm up, time, score. `phase` says what it is doing.
pub fn run_case(case: &Case, opts: &SuiteOptions, mut phase: impl FnMut(&str)) -> Result<CaseResult> {
    reset_peak_rss();
    phase("loading");
    let t = Instant::now();
    let mut l = load(case, opts)?;
    let load_s = t.elapsed().as_secs_f64();
    let (warmup, frames) = (opts.warmup, opts.frames.max(1));
    let mut walls = Vec::with_capacity(frames);
    let mut gpus = Vec::with_capacity(frames);
    let mut device_bytes = 0u64;
    let mut last = None;
    for i in 0..warmup + frames {
        phase(&if i < warmup {
            format!("warm-up {}/{warmup}", i + 1)
        } else {
            format!("frame {}/{frames}", i + 1 - warmup)
        });
        let t = Instant::now();
        let f = (l.draw)(&mut l.renderer, i as u32)?;
        let wall = t.elapsed().as_secs_f64() * 1e3;
        if i >= warmup {
            walls.push(wall);
            gpus.push(f.timings.iter().map(|s| s.ms).sum::<f64>());
        }
        if let Some(ctx) = l.renderer.context() {
            device_bytes = device_bytes.max(ctx.allocation_report().1);
        }
        last = Some(f);
    }
    crate::open::report_validation(&l.renderer)?;
    let last = last.expect("at least one frame");
    phase("truth");
    let psnr = match truth_image(case, opts, &mut l)? {
        // Over the covered pixels: the empty background both agree on is not counted as right.
        Some(t) => Some(voxsplat::metrics::compare(&last.image, &t)?.covered_psnr),
        None => None,
    };
    let stats = last.stats;
    let splats = if stats.splats > 0 { stats.splats } else { l.splats_stored };
    Ok(CaseResult::new(case, walls, gpus, splats, stats.nodes, device_bytes, psnr, load_s, &last))
}

/// The default cache folder: `$XDG_CACHE_HOME/voxsplat/bench`, else `~/.cache/voxsplat/bench`.
pub fn default_cache() -> PathBuf {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("voxsplat").join("bench")
}
