//! Running the built binary from the CLI's integration tests.
#![allow(dead_code)]
use std::process::{Command, Output};

/// The research switches of `render`, which only `voxsplat-lab render` takes.
pub const RESEARCH: [&str; 21] = [
    "--truth",
    "--k-line",
    "--bisect",
    "--dense",
    "--every-voxel",
    "--lod-band",
    "--lod-nodes",
    "--sheet-budget-mib",
    "--direction",
    "--keep-hidden-bricks",
    "--slab-thickness",
    "--accumulate",
    "--early-termination",
    "--raster",
    "--lod-pixels",
    "--lod-error",
    "--kernel",
    "--supersample",
    "--raycast-stop",
    "--repeat",
    "--order",
];

/// `voxsplat ARGS`, waited for. Three kinds run the lab's binary: `["lab", STUDY, ...]` runs
/// `voxsplat-lab STUDY ...`, a `render` with a research switch (`RESEARCH`) runs as
/// `voxsplat-lab render` (the same command with those switches), and `order` (a study since
/// issue 77) as `voxsplat-lab order`.
pub fn voxsplat(args: &[&str]) -> Output {
    let bin = binary_for(args);
    let args = if args.first() == Some(&"lab") { &args[1..] } else { args };
    Command::new(&bin).args(args).output().unwrap_or_else(|e| panic!("run {}: {e}", bin.display()))
}

/// The binary that runs `voxsplat ARGS` (`voxsplat` itself or `voxsplat-lab`, as `voxsplat`
/// says); with `["lab", ...]` the lab's, which takes the rest.
pub fn binary_for(args: &[&str]) -> std::path::PathBuf {
    let research = |a: &&str| RESEARCH.contains(&a.split('=').next().unwrap_or(a));
    match args {
        ["lab", ..] | ["order", ..] => lab_binary(),
        ["render", ..] if args.iter().any(research) => lab_binary(),
        _ => std::path::PathBuf::from(env!("CARGO_BIN_EXE_voxsplat")),
    }
}

/// `voxsplat ARGS` itself, whatever they are (`voxsplat` routes some to the lab).
pub fn user_binary(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_voxsplat")).args(args).output().expect("run voxsplat")
}

/// `voxsplat-lab`, beside `voxsplat` in the target directory: a package of its own (`lab/`), which
/// the top level's `cargo test` builds with its tests.
pub fn lab_binary() -> std::path::PathBuf {
    let lab = std::path::Path::new(env!("CARGO_BIN_EXE_voxsplat")).with_file_name("voxsplat-lab");
    assert!(
        lab.exists(),
        "{} is not built: run `cargo test` at the top level, or `cargo build -p voxsplat-lab`",
        lab.display()
    );
    lab
}

/// A path in this test process's own temporary directory (`tag` names the test file).
pub fn tmp_in(tag: &str, name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("voxsplat-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// `voxsplat ARGS`, which must fail with a typed error (no panic); its stderr.
pub fn refused(args: &[&str]) -> String {
    let out = voxsplat(args);
    let text = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success() && text.starts_with("error:"), "voxsplat {args:?} should fail: {text}");
    assert!(!text.contains("panicked"), "{text}");
    assert_user_words(&text);
    text
}

/// A message a command prints names no Rust path (`loaders::load_channels`, `VolumeHints::time`):
/// the user's words, flags and files only.
pub fn assert_user_words(text: &str) {
    assert!(!text.contains("::"), "a Rust path in a message: {text}");
}

/// `voxsplat compare A B`'s PSNR in dB over the covered pixels (infinite for equal images).
pub fn psnr(a: &std::path::Path, b: &std::path::Path) -> f64 {
    let out = voxsplat(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "compare: {}", String::from_utf8_lossy(&out.stderr));
    text.lines()
        .find_map(|l| l.strip_prefix("psnr:"))
        .map(|s| s.split_whitespace().next().unwrap_or("").parse().unwrap_or(f64::INFINITY))
        .unwrap_or_else(|| panic!("no psnr in {text}"))
}

/// A transfer function file at `path` over the file values `lo..hi` (a fixed range: frames of
/// different parts or time points classify alike).
pub fn tf_file(path: &std::path::Path, lo: f32, hi: f32) -> &std::path::Path {
    let points = "points = [[0.0, [0, 0, 0, 0]], [0.4, [0.9, 0.5, 0.3, 0.05]], [1.0, [1, 1, 1, 0.9]]]";
    std::fs::write(path, format!("{points}\nrange = [{lo:?}, {hi:?}]\n")).unwrap();
    path
}

/// Runs a Python script (python3: pydicom, nibabel, zarr-python, numpy...) with each `{}` replaced
/// by `args` in turn.
pub fn python(script: &str, args: &[&std::path::Path]) {
    let script = args.iter().fold(script.to_string(), |s, a| s.replacen("{}", &a.display().to_string(), 1));
    let out = std::process::Command::new("python3").args(["-c", &script]).output().expect("python3");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}
