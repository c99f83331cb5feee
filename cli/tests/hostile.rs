//! Issue 25 through the command line: what a hostile user tried, each now a clear error (exit 2,
//! a message that names the problem) or the right output. The library's side: tests/hostile.rs.
use crate::cmd;
use crate::common;
use cmd::voxsplat;

fn tmp(name: &str) -> std::path::PathBuf {
    cmd::tmp_in("hostile-cli", name)
}

fn data(rel: &str) -> String {
    format!("{}/../../shared/data/{rel}", env!("CARGO_MANIFEST_DIR"))
}

/// Exit 2 with `needle` in the message, and no panic.
fn fails_with(args: &[&str], needle: &str) -> String {
    let out = voxsplat(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{args:?} should fail: {err}");
    assert!(err.contains(needle) && !err.contains("panicked"), "{args:?}: {err}");
    cmd::assert_user_words(&err);
    err
}

#[test]
fn bad_values_are_refused_with_a_reason() {
    let out = tmp("x.png");
    let out = out.to_str().unwrap();
    let link = tmp("full.png");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink("/dev/full", &link).unwrap();
    fails_with(&["render", "--size", "96x64", "--out", link.to_str().unwrap()], "No space left");
    fails_with(&["render", "--size", "32x32", "--raycast", "0.000001", "--cpu", "--out", out], "max_steps");
    fails_with(&["render", "--size", "32x32", "--ortho", "1e-7", "--out", out], "f32 cannot resolve");
    fails_with(&["render", "--size", "32x32", "--eye", "0,0,1e30", "--out", out], "within 1e15");
    // An eye at the view's target names the flag to add; inside the scene with a target it sees
    // from a fitted near plane (both were camera errors).
    fails_with(&["render", "--size", "32x32", "--eye", "0,0,0", "--out", out], "give --target too");
    let inside = voxsplat(&["render", "--size", "32x32", "--eye", "0,0,0", "--target", "0,0,-10", "--out", out]);
    assert!(inside.status.success(), "{}", String::from_utf8_lossy(&inside.stderr));
    fails_with(&["render", "--accumulate", "sheet", "--sheet-budget-mib", "17592186044416", "--out", out], "overflows");
    fails_with(&["render", "--gpu-budget-mib", "0", "--out", out], "must be positive");
    // A spacing the camera cannot resolve is a spacing error (it was "eye and target coincide").
    let stent = data("stent/stent.nrrd");
    fails_with(
        &["render", "--volume", &stent, "--spacing", "1e-30,1e-30,1e-30", "--out", out],
        "below 1e-15 units a voxel",
    );
    let dem = data("rmnp/rmnp-dem.tif");
    fails_with(&["render", "--terrain", &dem, "--vscale", "1e30", "--out", out], "lower --vscale");
    // A bad extension is found before anything is drawn.
    let err = fails_with(&["render", "--size", "32x32", "--out", tmp("x.jpg").to_str().unwrap()], "must end in .png");
    assert!(!err.contains("splats"), "rendered first: {err}");
}

#[test]
fn flags_that_would_be_ignored_are_refused() {
    let out = tmp("y.png");
    let out = out.to_str().unwrap();
    let stent = data("stent/stent.nrrd");
    fails_with(&["render", "--volume", &stent, "--dims", "4,4,4", "--out", out], "describe raw files");
    fails_with(&["render", "--volume", &stent, "--scene", "cube40", "--out", out], "cannot be used with");
    let npy = tmp("v.npy");
    std::fs::write(&npy, common::npy(&[2, 2, 2], "|u1", &[1, 2, 3, 4, 5, 6, 7, 8])).unwrap();
    fails_with(&["render", "--volume", npy.to_str().unwrap(), "--big-endian", "--out", out], "describe raw files");
    let dem = data("rmnp/rmnp-dem.tif");
    fails_with(&["render", "--terrain", &dem, "--spacing", "1,1,2", "--out", out], "--volume");
    fails_with(&["render", "--raycast", "0.5", "--repeat", "3", "--out", out], "cannot be used with");
    fails_with(&["info", &stent, "--vscale", "2"], "describe height grids");
    fails_with(&["info", &data("rmnp/rmnp-dem.tif"), "--histogram", "8"], "describe volumes");
}

#[test]
fn info_agrees_with_render() {
    // The terrain's splat count is render's (info counted 1,553,333 with another cell size).
    let dem = data("rmnp/rmnp-dem.tif");
    let info = voxsplat(&["info", &dem]);
    assert!(info.status.success());
    let text = String::from_utf8_lossy(&info.stdout);
    let count = text.lines().find_map(|l| l.strip_prefix("splats: ")).expect("a splat count").to_string();
    let render =
        voxsplat(&["render", "--terrain", &dem, "--size", "32x32", "--cpu", "--out", tmp("t.png").to_str().unwrap()]);
    let err = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success() && err.contains(&format!("{count} splats ->")), "info {count}, render: {err}");
    // A TOML transfer function, as render takes it.
    let tf = tmp("tf.toml");
    std::fs::write(&tf, "points = [[0.0, [1.0, 1.0, 1.0, 0.0]], [1.0, [1.0, 1.0, 1.0, 1.0]]]\n").unwrap();
    let out = voxsplat(&["info", &data("stent/stent.nrrd"), "--tf", tf.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // A 2-D .npy is a height grid (its help says "volume or height file").
    let heights: Vec<u8> = (0..12u8).collect();
    let npy = tmp("h.npy");
    std::fs::write(&npy, common::npy(&[3, 4], "|u1", &heights)).unwrap();
    let out = voxsplat(&["info", npy.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("height grid: 4 x 3 cells"), "{text}");
}

#[test]
fn an_animation_fails_before_writing_a_frame() {
    let anim = tmp("through.toml");
    std::fs::write(
        &anim,
        "scene = \"cube40\"\nframes = 10\nsize = [32, 32]\n[camera]\neye = [0.0, 0.0, 100.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[keyframe]]\nframe = 0\neye = [0.0, 0.0, 100.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[keyframe]]\nframe = 8\neye = [0.0, 0.0, -100.0]\ntarget = [0.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let dir = tmp("anim-out");
    fails_with(&["animate", "--anim", anim.to_str().unwrap(), "--out-dir", dir.to_str().unwrap()], "frame 4");
    assert!(!dir.exists() || std::fs::read_dir(&dir).unwrap().next().is_none(), "frames were written");
    // A short one streams to the GIF; on a full disk it fails.
    let short = tmp("short.toml");
    std::fs::write(
        &short,
        "scene = \"cube40\"\nframes = 2\nsize = [32, 32]\n[camera]\neye = [0.0, 0.0, 100.0]\ntarget = [0.0, 0.0, 0.0]\n\
         [[keyframe]]\nframe = 0\nrotate = [0.0, 1.0, 0.0, 10.0]\n",
    )
    .unwrap();
    let ok = tmp("anim-ok");
    let out = voxsplat(&["animate", "--anim", short.to_str().unwrap(), "--out-dir", ok.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(ok.join("anim.gif").exists() && ok.join("frame0001.png").exists());
    let full = tmp("anim-full");
    std::fs::create_dir_all(&full).unwrap();
    let _ = std::fs::remove_file(full.join("anim.gif"));
    std::os::unix::fs::symlink("/dev/full", full.join("anim.gif")).unwrap();
    fails_with(&["animate", "--anim", short.to_str().unwrap(), "--out-dir", full.to_str().unwrap()], "No space left");
}

/// `voxsplat info FILE | head -1`: the reader closes the pipe early; the writer ends quietly with
/// success instead of panicking ("failed printing to stdout: Broken pipe").
#[test]
fn a_closed_stdout_pipe_ends_quietly() {
    use std::process::{Command, Stdio};
    for args in [&["info", &data("bonsai/bonsai.nii.gz")][..], &["scenes"][..]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_voxsplat"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // closed before the first line is written
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success() && !err.contains("panicked"), "{args:?}: {:?} {err}", out.status);
    }
}

/// Peak resident memory, as `render --timings` reports it.
fn peak_mib(args: &[&str]) -> f64 {
    let out = voxsplat(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let line = text.lines().find(|l| l.starts_with("host memory, peak:")).expect("a peak memory line");
    line.split_whitespace().nth(3).and_then(|v| v.parse().ok()).expect("MiB")
}

/// `--repeat N` keeps one frame at a time (each 4 MiB at 512²), not all N.
#[test]
fn repeated_frames_are_not_all_kept() {
    let out = tmp("repeat.png");
    let base = ["render", "--scene", "cube40", "--size", "512x512", "--timings", "--out", out.to_str().unwrap()];
    let one = peak_mib(&[&base[..], &["--repeat", "2"]].concat());
    let many = peak_mib(&[&base[..], &["--repeat", "30"]].concat());
    assert!(many < one + 40.0, "30 frames peak at {many} MiB against {one} MiB for 2");
}

/// Issue 76: a large frame is drawn in bands (`voxsplat::bands`) and takes at most 1.5 times its own
/// RGBA32F size above a small frame's peak: a PNG streamed band by band (4096²: measured 264 MiB
/// above, 1.03x), an EXR put together whole (8192²: 1,222 MiB above, 1.19x). Drawn whole, 8192²
/// took 4.5 GB and 4096² 733 MB.
#[test]
fn a_large_frame_takes_at_most_half_again_its_own_size() {
    let run = |size: &str, name: &str, scale: &str| {
        let out = tmp(name);
        let o = out.to_str().unwrap();
        peak_mib(&["render", "--scene", "cube40", "--size", size, "--render-scale", scale, "--timings", "--out", o])
    };
    let base = run("256x256", "band-base.png", "1");
    // A render scale draws the coarse frame whole and resamples it band by band into the PNG
    // (such a frame was refused: "a render scale below 1 needs the whole frame").
    for (side, name, scale) in
        [(4096u64, "band-4096.png", "1"), (8192, "band-8192.exr", "1"), (4096, "band-half.png", "0.5")]
    {
        let own = (side * side * 16) as f64 / 1048576.0;
        let peak = run(&format!("{side}x{side}"), name, scale);
        assert!(
            peak - base <= 1.5 * own,
            "{side}² at {scale}: {peak} MiB peak against {base} MiB for 256², own {own} MiB"
        );
        assert!(covered(&tmp(name)) > (side * side / 20) as usize, "{name}: the cube drawn");
    }
}

/// Pixels with any coverage in an image the CLI wrote.
fn covered(path: &std::path::Path) -> usize {
    voxsplat::output::read_image(path).unwrap().pixels.iter().filter(|p| p[3] > 0.0).count()
}

/// Issue 44: what anti-aliasing widens is not culled whole. A cube seen from far away, or at a
/// 4 x 4 image, drew nothing with `--aa swan|ewa` (every widened splat fell within the cull margin
/// of the fitted near and far planes); a 2 x 2 terrain drew nothing (the fly-over's eye sat within
/// the margin of its splats). On the GPU and `--cpu`.
#[test]
fn far_small_and_tiny_scenes_are_drawn() {
    let out = tmp("far.exr");
    let o = out.to_str().unwrap();
    for cpu in [false, true] {
        let c: &[&str] = if cpu { &["--cpu"] } else { &[] };
        for aa in ["none", "swan", "ewa"] {
            for args in [
                &["--scene", "cube60", "--size", "256x256", "--eye", "3200,2600,5800"][..],
                &["--scene", "cube60", "--size", "4x4"][..],
            ] {
                let run = voxsplat(&[&["render", "--aa", aa, "--out", o][..], args, c].concat());
                assert!(run.status.success(), "{args:?} {aa}: {}", String::from_utf8_lossy(&run.stderr));
                assert!(covered(&out) > 0, "{args:?} --aa {aa} cpu {cpu}: an empty frame");
            }
        }
        // The smallest terrain a height grid may be: 2 x 2 cells.
        voxsplat::output::write_image(
            &voxsplat::image::ImageF32 {
                width: 2,
                height: 2,
                pixels: vec![[0.1, 0.1, 0.1, 1.0], [0.2; 4], [0.3; 4], [0.4; 4]],
            },
            &tmp("dem-2x2.png"),
        )
        .unwrap();
        let run = voxsplat(
            &[&["render", "--terrain", tmp("dem-2x2.png").to_str().unwrap(), "--size", "64x64", "--out", o][..], c]
                .concat(),
        );
        assert!(run.status.success(), "2x2 terrain: {}", String::from_utf8_lossy(&run.stderr));
        assert!(covered(&out) > 100, "2x2 terrain cpu {cpu}: {} px", covered(&out));
    }
}

/// Issue 44: spacing in metres draws the object as spacing in millimetres does (1e-4 drew an
/// empty frame, 1e-3 drew it at a fifth of its size: the framing had a floor of one unit), down
/// to 1e-9.
#[test]
fn metre_scale_spacing_frames_the_object_as_any_other() {
    let out = tmp("metres.exr");
    let o = out.to_str().unwrap();
    let bonsai = data("bonsai/bonsai.nii.gz");
    let mut pixels = Vec::new();
    for sp in ["1,1,1", "0.001,0.001,0.001", "0.0001,0.0001,0.0001", "1e-9,1e-9,1e-9"] {
        let run = voxsplat(&["render", "--volume", &bonsai, "--spacing", sp, "--size", "96x96", "--out", o]);
        assert!(run.status.success(), "{sp}: {}", String::from_utf8_lossy(&run.stderr));
        pixels.push(covered(&out));
    }
    for (p, sp) in pixels.iter().zip(["1", "1e-3", "1e-4", "1e-9"]) {
        assert!(p.abs_diff(pixels[0]) * 20 < pixels[0], "spacing {sp}: {p} px against {} at 1", pixels[0]);
    }
}

/// Issue 44: flags that cannot apply are refused, not silently ignored: what describes a --volume
/// file given with a built-in scene or a terrain, --slab-thickness without slabs, and make-volume
/// writing NRRD bytes under another extension.
#[test]
fn flags_that_were_silently_ignored_are_refused() {
    // Issue 76's hostile run: each of these drew (exit 0) as if the flag were not there.
    let out = tmp("ignored.png");
    let o = out.to_str().unwrap();
    let stent = data("stent/stent.nrrd");
    for (args, needle) in [
        (vec!["render", "--repeat", "0"], "--repeat"),
        (vec!["render", "--sheet-budget-mib", "64"], "--sheet-budget-mib bounds the summation layers"),
        (vec!["render", "--volume", &stent, "--raycast", "0.5", "--aa", "swan"], "--aa filters splats"),
        (vec!["render", "--volume", &stent, "--raycast", "0.5", "--aa", "none"], "--aa filters splats"),
        (vec!["render", "--volume", &stent, "--dense", "--keep-hidden-bricks"], "--keep-hidden-bricks draws"),
        (vec!["render", "--exchange", "direct-send"], "--exchange picks how the ranks"),
    ] {
        fails_with(&[&args[..], &["--size", "32x32", "--out", o]].concat(), needle);
    }
    // A flag given at its default's value is still given: an animation sets its own scene and view.
    let dir = tmp("anim-flags");
    for flag in [["--scene", "cube60"], ["--size", "512x512"], ["--view", "auto"]] {
        let args = [&["animate", "--anim", "rotating-box", "--out-dir", dir.to_str().unwrap()][..], &flag[..]].concat();
        fails_with(&args, flag[0]);
    }
    assert!(!dir.join("frame0000.png").exists(), "refused before a frame");
    // What does apply still runs.
    for args in [
        vec!["render", "--accumulate", "sheet", "--sheet-budget-mib", "64"],
        vec!["render", "--volume", &stent, "--keep-hidden-bricks", "--aa", "swan"],
        vec!["render", "--repeat", "2"],
    ] {
        let run = voxsplat(&[&args[..], &["--size", "32x32", "--out", o]].concat());
        assert!(run.status.success(), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
    }
}

#[test]
fn bench_compare_refuses_reports_that_cannot_be_compared() {
    let report = |cases: &str| {
        format!(
            r#"{{"suite": 1, "quick": false, "validation": false, "warmup": 1, "frames": 3, "score": 1.0,
            "score_noise": 0.01, "skipped": [], "platform": {{"voxsplat": "0", "commit": "x", "device": "d",
            "kind": "cpu", "driver": "v", "api": "1.3", "host_cpus": 2}},
            "cases": [{cases}]}}"#
        )
    };
    let case = |name: &str, fps: f64| {
        format!(
            r#"{{"name": "{name}", "size": [64, 64], "frames": 3, "median_ms": 10.0, "min_ms": 9.0, "max_ms": 11.0,
            "spread": 0.05, "stages_ms": 9.0, "fps": {fps}, "splats": 10, "nodes": 0, "msplats_per_s": 1.0,
            "device_mib": 1.0, "host_peak_mib": 1.0, "psnr_db": null, "load_s": 0.0, "raster": "compute"}}"#
        )
    };
    let write = |name: &str, text: String| {
        let p = tmp(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let good = write("good.json", report(&case("cube60", 100.0)));
    let run = voxsplat(&["bench", "--compare", &good, &good]);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success() && text.contains("B/A 1.000x"),
        "the fixture is a report: {text}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    for (name, text, needle) in [
        ("negative.json", report(&case("cube60", -3.7)), "fps is -3.7"),
        ("zero.json", report(&case("cube60", 0.0)), "fps is 0"),
        ("twice.json", report(&[case("cube60", 100.0), case("cube60", 50.0)].join(",")), "appears twice"),
        ("other.json", report(&case("motion", 100.0)), "share no case"),
    ] {
        let bad = write(name, text);
        fails_with(&["bench", "--compare", &good, &bad], needle);
    }
}

#[test]
fn flags_that_cannot_apply_are_refused() {
    let out = tmp("flags.png");
    let o = out.to_str().unwrap();
    let stent = data("stent/stent.nrrd");
    let dem = data("rmnp/rmnp-dem.tif");
    for (args, needle) in [
        (vec!["render", "--scene", "cube60", "--spacing", "2,2,2"], "--spacing describes a --volume"),
        (vec!["render", "--scene", "cube60", "--tf", "ct"], "--tf describes a --volume"),
        (vec!["render", "--scene", "cube60", "--tf", "/nonexistent.toml"], "--tf describes a --volume"),
        (vec!["render", "--scene", "peer128", "--tf", "ct"], "--tf describes a --volume"),
        (vec!["render", "--terrain", &dem, "--tf", "ct"], "--tf colours a --volume"),
        (vec!["render", "--scene", "cube60", "--slab-thickness", "2"], "draws no slabs"),
    ] {
        fails_with(&[&args[..], &["--size", "32x32", "--out", o]].concat(), needle);
    }
    fails_with(&["make-volume", "--procedural", "8", "--out", o], "name the output .nrrd");
    // What does apply still runs.
    for args in [
        vec!["render", "--volume", &stent, "--tf", "ct"],
        vec!["render", "--scene", "cube60", "--accumulate", "slab", "--slab-thickness", "2"],
    ] {
        let run = voxsplat(&[&args[..], &["--size", "32x32", "--out", o]].concat());
        assert!(run.status.success(), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
    }
}

/// Issue 44: `--host-budget-mib` bounds what a header or a flag sizes, refused before it is
/// allocated: an 8192² frame (it took 4.4 GB), a volume's samples and its store, a terrain's
/// columns. Within the budget the same commands run.
#[test]
fn the_host_budget_refuses_before_allocating() {
    let out = tmp("budget.png");
    let o = out.to_str().unwrap();
    let bonsai = data("bonsai/bonsai.nii.gz");
    let dem = data("rmnp/rmnp-dem.tif");
    // The bricked store costs what the volume holds (bonsai's records: 13 MiB), checked as it grows.
    fails_with(
        &["render", "--volume", &bonsai, "--size", "32x32", "--out", o, "--host-budget-mib", "8"],
        "for its records and the next slab, past the host budget of 8 MiB",
    );
    // Two frames compared: each image's decoded bytes and floats are checked from its header (two
    // 8000x8000 PNGs took 2.3 GB within a budget of 10 MiB).
    let big = tmp("big.png");
    image::RgbaImage::new(3000, 3000).save(&big).unwrap();
    let big = big.to_str().unwrap();
    fails_with(&["compare", big, big, "--host-budget-mib", "10"], "reading");
    let run = voxsplat(&["compare", big, big, "--host-budget-mib", "400"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    for (args, needle) in [
        (vec!["render", "--scene", "cube40", "--size", "8192x8192", "--out", o], "a 8192x8192 frame may need"),
        (
            vec!["render", "--volume", &bonsai, "--dense", "--size", "32x32", "--out", o],
            "past the host budget of 40 MiB",
        ),
        (vec!["info", &bonsai], "past the host budget of 40 MiB"),
        // rmnp at 50x relief: 1.2 M column voxels.
        (
            vec!["render", "--terrain", &dem, "--vscale", "50", "--size", "32x32", "--out", o],
            "terrain's 1222732 splats",
        ),
    ] {
        let t = std::time::Instant::now();
        fails_with(&[&args[..], &["--host-budget-mib", "40"][..]].concat(), needle);
        assert!(t.elapsed().as_secs_f64() < 20.0, "{args:?}");
    }
    for args in
        [vec!["render", "--scene", "cube40", "--size", "64x64"], vec!["render", "--terrain", &dem, "--size", "32x32"]]
    {
        let run = voxsplat(&[&args[..], &["--host-budget-mib", "400", "--out", o][..]].concat());
        assert!(run.status.success(), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
    }
}

/// Issue 44: an eye straight above or below the target, with no --up, gets another up, as a viewer
/// picks one (it was refused: "up is parallel"); an --up given along the view is still refused.
#[test]
fn a_view_along_the_default_up_picks_another() {
    let out = tmp("topdown.png");
    let o = out.to_str().unwrap();
    for eye in ["0,200,0", "0,-200,0"] {
        let run = voxsplat(&[
            "render", "--scene", "cube40", "--eye", eye, "--target", "0,0,0", "--size", "48x48", "--out", o,
        ]);
        assert!(run.status.success(), "{eye}: {}", String::from_utf8_lossy(&run.stderr));
        assert!(covered(&out) > 100, "{eye}");
    }
    fails_with(
        &[
            "render", "--scene", "cube40", "--eye", "0,200,0", "--target", "0,0,0", "--up", "0,1,0", "--size", "48x48",
            "--out", o,
        ],
        "parallel",
    );
}
