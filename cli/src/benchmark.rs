//! `voxsplat bench`: runs the suite (voxsplat_cli::suite) with a progress bar, prints its table,
//! writes JSON, compares two reports.
use super::*;
use voxsplat_cli::suite::{self, Report, SuiteOptions};
use voxsplat_cli::{print, println};

#[derive(Args)]
pub(crate) struct BenchArgs {
    /// The quick suite (under five minutes on lavapipe): the small scenes, the bonsai, MIP, the
    /// terrain and motion blur, with fewer frames.
    #[arg(long)]
    quick: bool,
    /// Run only this case (repeat for several); --list names them.
    #[arg(long = "case")]
    cases: Vec<String>,
    /// List the suite's cases and exit.
    #[arg(long)]
    list: bool,
    /// Timed frames a case [default: 10; 3 with --quick].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1000))]
    frames: Option<u32>,
    /// Untimed frames before them [default: 2; 1 with --quick].
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=100))]
    warmup: Option<u32>,
    /// Also write the report as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Compare two JSON reports (A then B) instead of running: each case's frame rate B/A with
    /// the noise both runs measured, and the scores.
    #[arg(long, num_args = 2, value_names = ["A", "B"], conflicts_with_all = ["quick", "cases", "list", "frames", "warmup", "json", "validation", "cpu"])]
    compare: Vec<PathBuf>,
    /// The data folder holding bonsai/, stent/, heptane/ and rmnp/ [default: ../shared/data, or
    /// VOXSPLAT_DATA].
    #[arg(long)]
    data: Option<PathBuf>,
    /// Where the made 512³ and 1024³ volumes and the truths are kept between runs [default:
    /// ~/.cache/voxsplat/bench].
    #[arg(long)]
    cache: Option<PathBuf>,
    /// Khronos validation on: a first pass on a new device (the times then measure the layer).
    #[arg(long)]
    validation: bool,
    /// The CPU mirrors instead of Vulkan.
    #[arg(long)]
    cpu: bool,
}

pub(crate) fn bench(a: BenchArgs) -> Result<()> {
    if let [x, y] = a.compare.as_slice() {
        print!("{}", suite::compare(&Report::read_json(x)?, &Report::read_json(y)?)?);
        return Ok(());
    }
    let opts = SuiteOptions {
        cases: a.cases.clone(),
        quick: a.quick,
        warmup: a.warmup.map_or(if a.quick { 1 } else { 2 }, |w| w as usize),
        frames: a.frames.map_or(if a.quick { 3 } else { 10 }, |f| f as usize),
        data: a.data.clone().unwrap_or_else(voxsplat::loaders::data_dir),
        cache: a.cache.clone().unwrap_or_else(suite::default_cache),
        validation: a.validation,
        cpu: a.cpu,
    };
    let cases = suite::selected(&opts)?;
    if let Some(d) = &a.data {
        // The built-in scenes that read data files (the terrain) look there too.
        std::env::set_var("VOXSPLAT_DATA", d);
    }
    if a.list {
        for c in suite::SUITE {
            let quick = if c.quick { "quick" } else { "" };
            println!("{:<11} {:>9} {quick:<5} {}", c.name, format!("{}x{}", c.size[0], c.size[1]), c.about);
        }
        return Ok(());
    }
    let platform = platform(&opts)?;
    let bar = indicatif::ProgressBar::new(cases.len() as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:24} {pos}/{len} {msg} {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let (mut done, mut skipped) = (Vec::new(), Vec::new());
    for c in &cases {
        // A case whose data file is missing is skipped, and says so; any other failure stops the run.
        if let Some(why) = suite::missing(c, &opts) {
            // (The table lists it too; a hidden bar prints nothing.)
            bar.println(format!("{}: skipped: {why}", c.name));
            skipped.push((c.name.to_string(), why));
            bar.inc(1);
            continue;
        }
        match suite::run_case(c, &opts, |phase| bar.set_message(format!("{}: {phase}", c.name))) {
            Ok(r) => done.push(r),
            Err(e) => {
                bar.finish_and_clear();
                return Err(Error::InvalidArgument(format!("case {}: {e}", c.name)));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let (score, score_noise) = suite::score(&done);
    let report = Report {
        suite: suite::SUITE_VERSION,
        quick: opts.quick,
        validation: opts.validation,
        warmup: opts.warmup,
        frames: opts.frames,
        platform,
        cases: done,
        skipped,
        score,
        score_noise,
    };
    print!("{}", report.table());
    if let Some(path) = &a.json {
        report.write_json(path)?;
        eprintln!("report -> {}", path.display());
    }
    if report.cases.is_empty() {
        return Err(Error::InvalidArgument("no case ran: see the skipped lines above".into()));
    }
    Ok(())
}

/// The device the cases will use, and this build.
fn platform(opts: &SuiteOptions) -> Result<suite::Platform> {
    let host_cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let (voxsplat, commit) = (env!("CARGO_PKG_VERSION").to_string(), voxsplat_cli::measure::COMMIT.to_string());
    if opts.cpu {
        let kind = "cpu mirrors".to_string();
        return Ok(suite::Platform {
            device: "cpu".into(),
            kind,
            driver: "-".into(),
            api: "-".into(),
            voxsplat,
            commit,
            host_cpus,
        });
    }
    let ctx = voxsplat::vk::Context::new(&voxsplat::vk::ContextOptions::default())?;
    let p = ctx.profile();
    Ok(suite::Platform {
        device: p.name.clone(),
        kind: format!("{:?}", p.kind).to_lowercase(),
        driver: p.driver.clone(),
        api: p.api(),
        voxsplat,
        commit,
        host_cpus,
    })
}
