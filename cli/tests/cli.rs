//! The command-line contract: listed scenes, rendered files, order dumps, and clear errors (never
//! a panic) for bad input.
use crate::cmd;
use crate::common;
use cmd::voxsplat;

fn tmp(name: &str) -> std::path::PathBuf {
    cmd::tmp_in("cli", name)
}

#[test]
fn scenes_are_listed() {
    let out = voxsplat(&["scenes"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for name in ["cube40", "cube60", "plane", "empty"] {
        assert!(text.lines().any(|l| l.starts_with(name)), "{name} missing from:\n{text}");
    }
}

#[test]
fn render_writes_png_and_exr() {
    for (ext, extra) in
        [("png", vec!["--cpu"]), ("exr", vec!["--validation", "--accumulate", "sheet", "--kernel", "cubic"])]
    {
        let path = tmp(&format!("cube.{ext}"));
        let p = path.to_str().unwrap();
        let mut args = vec!["render", "--scene", "cube40", "--size", "96x64", "--out", p];
        args.extend(extra);
        let out = voxsplat(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let bytes = std::fs::read(&path).unwrap();
        match ext {
            "png" => {
                let img = image::load_from_memory(&bytes).unwrap().to_rgba8();
                assert_eq!(img.dimensions(), (96, 64));
                assert!(img.pixels().any(|px| px[3] > 200), "the cube is drawn");
                assert!(img.pixels().any(|px| px[3] == 0), "the background is transparent");
            }
            _ => assert_eq!(&bytes[..4], &[0x76, 0x2f, 0x31, 0x01], "EXR magic"),
        }
    }
}

/// A --target away from the scene puts it off the view's axis: its depth along the view is less
/// than its distance, and the fitted near plane must follow the depth (it followed the distance and
/// clipped this cube away whole: an empty frame, no error).
#[test]
fn a_scene_off_the_axis_is_not_clipped() {
    let path = tmp("off-axis.png");
    // 20 degrees off the axis, 1000 away: 1 - cos 20° of the distance (60) passes the cube's radius.
    let out = voxsplat(&[
        "render",
        "--scene",
        "cube40",
        "--eye",
        "0,0,1000",
        "--target",
        "364,0,0",
        "--size",
        "96x64",
        "--cpu",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&path).unwrap().to_rgba8();
    let drawn: Vec<u32> = img.enumerate_pixels().filter(|(_, _, px)| px[3] > 200).map(|(x, _, _)| x).collect();
    assert!(!drawn.is_empty(), "the cube is drawn");
    assert!(drawn.iter().all(|&x| x < 32), "on the left, where the view's axis turned from it: {drawn:?}");
}

#[test]
fn order_dump_and_check() {
    let path = tmp("order.csv");
    let out = voxsplat(&[
        "order",
        "--scene",
        "cube40",
        "--eye",
        "5,8,45",
        "--target",
        "0,0,0",
        "--order",
        "pbtf",
        "--dump",
        path.to_str().unwrap(),
        "--check",
        "--validation",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().last(), Some("violations: 0"));
    let csv = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 40 * 40 * 40 - 38 * 38 * 38);
    let fields: Vec<f32> = lines[0].split(',').map(|f| f.parse().unwrap()).collect();
    assert_eq!(fields.len(), 6);
    // x = i - 19.5 for the centred 40^3 grid.
    assert_eq!(fields[3], fields[0] - 19.5);
    // Back to front: the first splat is farther from the eye than the last.
    let dist = |l: &str| {
        let f: Vec<f32> = l.split(',').map(|x| x.parse().unwrap()).collect();
        ((f[3] - 5.0).powi(2) + (f[4] - 8.0).powi(2) + (f[5] - 45.0).powi(2)).sqrt()
    };
    assert!(dist(lines[0]) > dist(lines[lines.len() - 1]));

    let out =
        voxsplat(&["order", "--scene", "cube40", "--eye", "5,8,45", "--target", "0,0,0", "--order", "btf", "--check"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap();
    let n: u64 = last.strip_prefix("violations: ").unwrap().parse().unwrap();
    assert!(n > 0, "BTF breaks on this close perspective view");
}

#[test]
fn bad_arguments_fail_cleanly() {
    let cases: &[&[&str]] = &[
        &["render", "--scene", "nosuch", "--out", "x.png"],
        &["render", "--scene", "cube40", "--eye", "nan,0,0", "--out", "x.png"],
        &["render", "--scene", "cube40", "--eye", "1,2", "--out", "x.png"],
        &["render", "--scene", "cube40", "--eye", "0,0,0", "--target", "0,0,0", "--out", "x.png"],
        &["render", "--scene", "cube40", "--size", "0x10", "--out", "x.png"],
        &["render", "--scene", "cube40", "--size", "100000x10", "--out", "x.png"],
        &["render", "--scene", "cube40", "--fov", "180", "--out", "x.png"],
        &["render", "--scene", "cube40", "--fov", "-5", "--out", "x.png"],
        &["render", "--scene", "cube40", "--ortho", "0", "--out", "x.png"],
        &["render", "--scene", "cube40", "--up", "0,0,0", "--out", "x.png"],
        &["render", "--scene", "cube40", "--order", "zigzag", "--out", "x.png"],
        &["render", "--scene", "cube40", "--render-scale", "0", "--out", "x.png"],
        &["render", "--scene", "cube40", "--render-scale", "1.5", "--out", "x.png"],
        &["render", "--scene", "cube40", "--render-scale", "nan", "--out", "x.png"],
        &["render", "--scene", "cube40", "--render-scale", "0.5", "--truth", "--out", "x.png"],
        &["render", "--scene", "cube40", "--out", "x.bmp", "--cpu"],
        &["render", "--scene", "cube40", "--near", "10", "--far", "5", "--out", "x.png"],
        &["order", "--scene", "cube40", "--dump", "/nonexistent-dir/x.csv", "--cpu"],
        &["frobnicate"],
    ];
    for args in cases {
        let out = voxsplat(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} should fail");
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
        assert!(stderr.contains("error"), "{args:?}: no message: {stderr}");
    }
}

/// The quick bench's RMSE against the truth per (scene, method): 1.2x the values of the run that
/// set them (2026-11-24; frames are bit-identical run to run), so an accuracy regression fails
/// here and not only in docs/RESULTS.md. A new method needs its own line.
const QUICK_RMSE_CEILINGS: &[(&str, &str, f64)] = &[
    ("cube40", "btf splat gaussian", 0.0212),
    ("cube40", "pbtf splat gaussian", 0.0212),
    ("cube40", "sheet gaussian", 0.0334),
    ("cube40", "slab gaussian", 0.00812),
    ("cube40", "pbtf splat gaussian compute", 0.0212),
    ("cube40", "sheet gaussian compute", 0.0334),
    ("cube40", "raycast 1", 0.0069),
    ("cube40", "raycast 0.5", 0.00155),
    ("cube40", "pbtf splat gaussian compute scale 0.5", 0.046),
    ("cube40", "bricked compute", 0.0197),
    ("cube40", "bricked lod 1px error 0.04 compute", 0.0197),
    ("cube40", "bricked lod 1px compute", 0.0197),
    ("cube40", "bricked lod error 0.1 compute", 0.0197),
    ("plane", "btf splat gaussian", 0.0335),
    ("plane", "pbtf splat gaussian", 0.0335),
    ("plane", "sheet gaussian", 0.0383),
    ("plane", "slab gaussian", 0.00802),
    ("plane", "pbtf splat gaussian compute", 0.0335),
    ("plane", "sheet gaussian compute", 0.0383),
    ("plane", "raycast 1", 0.00424),
    ("plane", "raycast 0.5", 0.00139),
    ("plane", "pbtf splat gaussian compute scale 0.5", 0.249),
    ("plane", "bricked compute", 0.0348),
    ("plane", "bricked lod 1px error 0.04 compute", 0.0348),
    ("plane", "bricked lod 1px compute", 0.193),
    ("plane", "bricked lod error 0.1 compute", 0.0348),
    ("plane-grazing", "pbtf splat gaussian", 0.0798),
    ("plane-grazing", "pbtf splat gaussian aa=swan", 0.106),
    ("plane-grazing", "pbtf splat gaussian aa=ewa", 0.139),
    ("plane-grazing", "bricked compute", 0.0796),
    ("plane-grazing", "bricked lod 1px error 0.04 compute", 0.0796),
    ("plane-grazing", "bricked lod 1px compute", 0.104),
    ("plane-grazing", "bricked lod error 0.03 compute", 0.0796),
    ("plane-grazing", "bricked lod error 0.3 compute", 0.0796),
    ("plane-grazing", "bricked lod error 1 compute", 0.186),
    ("plane-grazing", "bricked lod 2px compute", 0.157),
    ("plane-grazing", "bricked lod 4px compute", 0.195),
    ("plane-grazing", "bricked lod 8px compute", 0.236),
    ("rotating-box", "still", 0.123),
    ("rotating-box", "blurred splats", 0.0633),
    ("rotating-box", "blurred splats sheet", 0.073),
    ("rotating-box", "accum:5", 0.0214),
];

#[test]
fn quick_bench_writes_valid_csv_and_svg() {
    let dir = tmp("bench");
    let results = dir.join("RESULTS.md");
    let out = voxsplat(&[
        "lab",
        "matrix",
        "--quick",
        "--out-dir",
        dir.to_str().unwrap(),
        "--results",
        results.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(dir.join("matrix.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows.len(),
        2 * (9 + 4) + (3 + 9) + 4,
        "two scenes x nine methods (one at a render scale) and four bricked (full detail, levels of detail at \
         1 px with and without the error test, one point of the error curve); three anti-aliasing modes and nine \
         bricked; four motion-blur methods"
    );
    for r in &rows {
        assert_eq!(r.len(), header.len());
        let t: f64 = r[col("time_ms")].parse().unwrap();
        let rmse: f64 = r[col("rmse")].parse().unwrap();
        assert!(t > 0.0 && t.is_finite(), "{r:?}");
        let ceiling = QUICK_RMSE_CEILINGS.iter().find(|c| c.0 == r[0] && c.1 == r[1]).map(|c| c.2);
        let ceiling = ceiling.unwrap_or_else(|| panic!("no RMSE ceiling for {} / {}: add one", r[0], r[1]));
        assert!(rmse <= ceiling, "{} / {}: RMSE {rmse} against the truth, ceiling {ceiling}", r[0], r[1]);
    }
    // The smaller ray-caster step is more accurate.
    let rm = |scene: &str, m: &str| -> f64 {
        rows.iter().find(|r| r[0] == scene && r[1] == m).unwrap()[col("rmse")].parse().unwrap()
    };
    assert!(rm("cube40", "raycast 0.5") < rm("cube40", "raycast 1"));
    // The plane's voxels are a quarter pixel at 128²: half the grid blurs its check edges further.
    assert!(rm("plane", "pbtf splat gaussian compute scale 0.5") > rm("plane", "pbtf splat gaussian compute"));
    for svg in [
        "chart-cube40.svg",
        "chart-plane.svg",
        "chart-plane-grazing.svg",
        "chart-rotating-box.svg",
        "scaling.svg",
        "rates.svg",
        "stability-popping.svg",
        "stability-error.svg",
    ] {
        let text = std::fs::read_to_string(dir.join(svg)).unwrap();
        assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"), "{svg}");
    }
    let chart = std::fs::read_to_string(dir.join("chart-plane.svg")).unwrap();
    assert!(chart.contains("sheet gaussian") && chart.contains("pbtf splat gaussian compute"));
    // The bricked scene draws what its splats draw; the grazing chart carries the error curve.
    for scene in ["cube40", "plane"] {
        let (bricked, dense) = (rm(scene, "bricked compute"), rm(scene, "pbtf splat gaussian compute"));
        assert!((bricked - dense).abs() <= 0.1 * dense, "{scene}: bricked RMSE {bricked} against the splats' {dense}");
    }
    let grazing = std::fs::read_to_string(dir.join("chart-plane-grazing.svg")).unwrap();
    assert!(grazing.contains("levels of detail, error bound swept"), "the levels-of-detail curve");
    let scaling = std::fs::read_to_string(dir.join("scaling.csv")).unwrap();
    assert_eq!(scaling.lines().count(), 1 + 3 * (2 + 2), "three raster variants x four points");
    // The raster sweep: six variants at two footprint sizes, every variant drawing the same picture.
    let rates = std::fs::read_to_string(dir.join("rates.csv")).unwrap();
    let rates: Vec<Vec<&str>> = rates.lines().skip(1).map(|l| l.split(',').collect()).collect();
    assert_eq!(rates.len(), 6 * 2);
    for r in &rates {
        let (per_s, rmse): (f64, f64) = (r[4].parse().unwrap(), r[5].parse().unwrap());
        assert!(per_s > 0.0 && per_s.is_finite(), "{r:?}");
        assert!(rmse < 0.02, "every variant close to the truth: {r:?}");
    }
    let md = std::fs::read_to_string(&results).unwrap();
    // One page: the charts, the targets and a table of the detail pages, each written beside the
    // charts it links.
    assert!(md.contains("## Targets") && md.contains("chart-cube40.svg") && md.contains("## Details"));
    assert!(md.lines().count() < 150, "the results page is one page: {} lines", md.lines().count());
    let page = |file: &str| {
        assert!(md.contains(&format!("]({file})")), "the results page links {file}");
        std::fs::read_to_string(dir.join(file)).unwrap()
    };
    let m = page("matrix.md");
    assert!(m.contains("| cube40 | pbtf splat gaussian |") && m.contains("## Roofline"));
    let r = page("raster.md");
    assert!(r.contains("## Raster variants") && r.contains("](rates.svg)"));
    assert!(page("antialias-plane.md").contains("Swan vs none beyond k"));
    let mb = page("motion.md");
    assert!(mb.contains("## Motion blur") && mb.contains("accumulation"));
    let st = page("stability.md");
    assert!(st.contains("## Stability where methods fail") && st.contains("popping at the switch"));
    let stab = std::fs::read_to_string(dir.join("stability.csv")).unwrap();
    assert_eq!(stab.lines().count(), 1 + 5, "five variants through the axis switch");
    assert!(stab.contains("image-aligned slab 1,") && stab.contains("axis-aligned sheet,"));
}

#[test]
fn compare_prints_metrics_and_rejects_bad_files() {
    let a = tmp("cmp-a.png");
    let b = tmp("cmp-b.exr");
    for (p, comp) in [(&a, "splat"), (&b, "sheet")] {
        let out = voxsplat(&[
            "render",
            "--scene",
            "cube40",
            "--size",
            "48x40",
            "--cpu",
            "--accumulate",
            comp,
            "--out",
            p.to_str().unwrap(),
        ]);
        assert!(out.status.success());
    }
    let out = voxsplat(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    for key in ["rmse:", "psnr:", "max_abs:", "ssim_luma:", "ssim_alpha:"] {
        assert!(text.contains(key), "{text}");
    }
    let same = voxsplat(&["compare", a.to_str().unwrap(), a.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&same.stdout).contains("rmse:       0.000000"));
    // Known values: red off by 0.25 everywhere, the other channels equal: RMSE sqrt(0.25^2 / 4).
    let flat = |r: f32, path: &std::path::Path| {
        let img = voxsplat::image::ImageF32 { width: 20, height: 10, pixels: vec![[r, 0.5, 0.5, 1.0]; 200] };
        voxsplat::output::write_image(&img, path).unwrap();
    };
    let (x, y) = (tmp("known-x.exr"), tmp("known-y.exr"));
    flat(0.5, &x);
    flat(0.25, &y);
    let known = voxsplat(&["compare", x.to_str().unwrap(), y.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&known.stdout);
    for line in ["rmse:       0.125000", "psnr:       18.06 dB", "max_abs:    0.250000"] {
        assert!(text.contains(line), "{line} in {text}");
    }
    let junk = tmp("junk.png");
    std::fs::write(&junk, b"not a png").unwrap();
    for args in [[a.to_str().unwrap(), junk.to_str().unwrap()], [a.to_str().unwrap(), "/nonexistent.exr"]] {
        let out = voxsplat(&["compare", args[0], args[1]]);
        assert_eq!(out.status.code(), Some(2));
        assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    }
}

/// `voxsplat lab peer` times every mode on the peers' scene and writes their images; bad sizes are
/// typed errors.
#[test]
fn peer_subcommand_times_every_mode() {
    let dir = tmp("peer");
    let d = dir.to_str().unwrap();
    let out = voxsplat(&["lab", "peer", "--n", "24", "--size", "48", "--frames", "5", "--warmup", "1", "--out-dir", d]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(
        rows.len(),
        13,
        "splat (quads, points, compute, points with the narrow kernel; four at a render scale), sheet \
         (quads, compute), slab, two ray-caster steps: {csv}"
    );
    for r in rows {
        let (label, ms) = r.rsplit_once(',').unwrap();
        assert!(ms.parse::<f64>().unwrap() > 0.0, "{r}");
        assert!(dir.join(format!("voxsplat-{}-24.png", label.replace(' ', "-"))).exists(), "{label}");
    }
    for args in [["lab", "peer", "--n", "1"], ["lab", "peer", "--frames", "2"]] {
        let out = voxsplat(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("error"));
    }
}

/// `voxsplat slice` writes a plane of the file's voxels, windowed, as grey: each pixel is the
/// file's value there, row 0 at the top, the window by default the plane's own range; a plane or
/// window that cannot apply and an output that is not PNG are refused.
#[test]
fn slice_writes_a_plane_of_the_files_values() {
    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");
    let vol = voxsplat::loaders::load_volume(std::path::Path::new(stent), &Default::default()).unwrap();
    let [nx, ny, _] = vol.dims;
    let png = tmp("slice.png");
    let at = |i: u32, j: u32, k: u32| vol.values[(i + nx * (j + ny * k)) as usize];
    for (axis, index) in [("x", 50u32), ("y", 60)] {
        let args =
            ["--axis", axis, "--index", &index.to_string(), "--window", "100,900", "--out", png.to_str().unwrap()];
        let out = voxsplat(&[&["slice", stent][..], &args].concat());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let img = image::open(&png).unwrap().to_luma8();
        assert_eq!(img.dimensions(), (if axis == "x" { ny } else { nx }, vol.dims[2]));
        let mut lit = 0;
        for (col, row, p) in img.enumerate_pixels() {
            let v = if axis == "x" { at(index, col, row) } else { at(col, index, row) };
            let want = ((v - 100.0) / 800.0 * 255.0).round().clamp(0.0, 255.0);
            assert_eq!(p[0] as f32, want, "{axis} = {index}: ({col}, {row})");
            lit += usize::from(p[0] > 0);
        }
        assert!(lit > 100, "{axis} = {index} cuts the stent ({lit} pixels lit)");
    }
    // The middle z plane by default, over its own range.
    let out = voxsplat(&["slice", stent, "--out", png.to_str().unwrap()]);
    let middle = &vol.values[(128 * nx * ny) as usize..(129 * nx * ny) as usize];
    let (lo, hi) = middle.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    let said = format!("plane z = 128 of the [128, 128, 256] grid, 128 x 128 voxels, values {lo} .. {hi}");
    assert!(String::from_utf8_lossy(&out.stdout).contains(&said), "{said}");
    for (args, says) in [
        (&["--index", "256"][..], "the z axis has 256 voxels (0 to 255)"),
        (&["--window", "5,5"][..], "HI must exceed LO"),
    ] {
        let out = voxsplat(&[&["slice", stent, "--out", png.to_str().unwrap()][..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
    }
    let out = voxsplat(&["slice", stent, "--out", tmp("slice.jpg").to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("slice writes PNG"));
}

/// `voxsplat info` on a file past the dense loader (272 M voxels, streamed into the store, with
/// the progress bar's hook): the store, the histogram and no splat count.
#[test]
fn info_streams_a_file_past_the_dense_loader() {
    let (nx, ny, nz) = (1024usize, 512usize, 520usize);
    let mut bytes =
        format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: {nx} {ny} {nz}\nencoding: raw\n\n").into_bytes();
    let head = bytes.len();
    bytes.resize(head + nx * ny * nz, 0);
    // One 16³ block at 9, one voxel at 200.
    for z in 100..116 {
        for y in 40..56 {
            let at = head + (z * ny + y) * nx + 300;
            bytes[at..at + 16].fill(9);
        }
    }
    bytes[head + (7 * ny + 3) * nx + 5] = 200;
    let path = tmp("big.nrrd");
    std::fs::write(&path, &bytes).unwrap();
    drop(bytes);
    let out = voxsplat(&["info", path.to_str().unwrap(), "--histogram", "2"]);
    let _ = std::fs::remove_file(&path);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("volume: [1024, 512, 520] voxels, spacing [1.0, 1.0, 1.0], values 0 .. 200"), "{text}");
    assert!(text.contains("bricked store: 4097 stored voxels"), "{text}");
    let bins: Vec<&str> = text.lines().skip_while(|l| !l.starts_with("histogram: 2 bins")).skip(1).take(2).collect();
    assert!(bins[0].contains(" 4096 ") && bins[1].contains(" 1 "), "{text}");
    assert!(text.contains("splats: not counted"), "{text}");
}

/// `voxsplat info` counts a file's splats and says when they pass the GPU path's limit.
#[test]
fn info_counts_splats_and_names_the_gpu_limit() {
    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");
    let out = voxsplat(&["info", stent]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("splats: 184675") && !text.contains("over the GPU path"), "{text}");
    // --histogram: its bins hold every stored voxel, the empty ones counted apart, over the range.
    let out = voxsplat(&["info", stent, "--histogram", "5"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let number = |line: &str, after: &str| -> u64 {
        line.split(after).nth(1).and_then(|t| t.split_whitespace().next()).and_then(|n| n.parse().ok()).unwrap()
    };
    let stored = text.lines().find(|l| l.starts_with("bricked store: ")).map(|l| number(l, "store: ")).unwrap();
    let head = text.lines().position(|l| l.starts_with("histogram: 5 bins")).expect(&text);
    let bins: Vec<u64> =
        text.lines().skip(head + 1).take(5).map(|l| l.split_whitespace().nth(3).unwrap().parse().unwrap()).collect();
    assert_eq!(bins.iter().sum::<u64>(), stored, "{text}");
    let empty = number(text.lines().nth(head).unwrap(), "(");
    assert_eq!(stored + empty, 128 * 128 * 256, "the stent's voxels: {text}");
    for bad in ["0", "65537"] {
        let out = voxsplat(&["info", stent, "--histogram", bad]);
        assert_eq!(out.status.code(), Some(2), "--histogram {bad}");
    }
    // A 150^3 block of full-scale voxels but one at zero, so the ramp spans 0..255 (an .npy written
    // here): 3 374 999 splats.
    let n = 150u64;
    let mut data = vec![255u8; (n * n * n) as usize];
    data[0] = 0;
    let bytes = common::npy(&[n, n, n], "|u1", &data);
    let path = tmp("block150.npy");
    std::fs::write(&path, bytes).unwrap();
    let out = voxsplat(&["info", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("splats: 3374999") && text.contains("over the dense GPU path's 3200000 splats"), "{text}");
    assert!(text.contains("bricked store: 3374999 stored voxels in 6859 bricks of 8^3"), "{text}");
    // The dense path refuses it; the bricked store (the default for a volume) renders it on the GPU.
    let png = tmp("block150.png");
    let args = ["render", "--volume", path.to_str().unwrap(), "--size", "48x48", "--validation", "--out"];
    let dense = voxsplat(&[&args[..], &[png.to_str().unwrap(), "--dense"]].concat());
    assert!(!dense.status.success() && String::from_utf8_lossy(&dense.stderr).contains("at most 3200000"));
    let out = voxsplat(&[&args[..], &[png.to_str().unwrap()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = voxsplat::output::read_image(&png).unwrap();
    assert!(img.pixels.iter().any(|p| p[3] > 0.5), "the block is drawn");
}

/// `make-volume` writes NRRD files that the loaders read back: the procedural field, and a volume
/// upsampled 2x (the stent here; the 512³ bonsai the same way) whose samples at the original
/// voxel pairs straddle the original values.
#[test]
fn make_volume_writes_readable_large_test_volumes() {
    let proc_path = tmp("proc.nrrd");
    let out = voxsplat(&["make-volume", "--procedural", "40", "--out", proc_path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let vol = voxsplat::loaders::load_volume(&proc_path, &Default::default()).unwrap();
    assert_eq!(vol.dims, [40, 40, 40]);
    let nonzero = vol.values.iter().filter(|&&v| v > 0.0).count();
    assert!(nonzero > 40 * 40 * 4 && nonzero < 40 * 40 * 40 / 2, "{nonzero} non-empty voxels");

    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");
    let up_path = tmp("stent2x.nrrd");
    let out = voxsplat(&["make-volume", "--from", stent, "--factor", "2", "--out", up_path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let src = voxsplat::loaders::load_volume(stent.as_ref(), &Default::default()).unwrap();
    let up = voxsplat::loaders::load_volume(&up_path, &Default::default()).unwrap();
    assert_eq!(up.dims, [2 * src.dims[0], 2 * src.dims[1], 2 * src.dims[2]]);
    assert_eq!(up.spacing, src.spacing.map(|s| s / 2.0));
    let (lo, hi) = src.values.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let norm = |v: f32| (v - lo) / (hi - lo) * 255.0;
    let [nx, ny, _] = src.dims;
    let (ux, uy) = (up.dims[0], up.dims[1]);
    for (i, j, k) in [(10u32, 20u32, 30u32), (64, 64, 128), (100, 5, 200)] {
        // Output voxel 2i + 1 lies a quarter voxel above source voxel i on each axis: trilinear
        // between the 8 source voxels of the cell from (i, j, k).
        let o = up.values[((2 * i + 1) + ux * ((2 * j + 1) + uy * (2 * k + 1))) as usize];
        let corners: Vec<f32> = (0..8)
            .map(|c| norm(src.values[((i + (c & 1)) + nx * ((j + (c >> 1 & 1)) + ny * (k + (c >> 2)))) as usize]))
            .collect();
        let (cmin, cmax) = corners.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(o >= cmin - 1.0 && o <= cmax + 1.0, "({i},{j},{k}): {o} outside [{cmin}, {cmax}]");
    }
    for bad in [vec!["make-volume", "--procedural", "0", "--out", "x.nrrd"], vec!["make-volume", "--out", "x.nrrd"]] {
        let out = voxsplat(&bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
    }
}

/// `make-volume --from` keeps the source's placement: the upsampled volume shows its object in the
/// same place of the world, so one view frames both (a left-handed, sheared file here). Before, the
/// output had spacing alone and the 512³ bonsai was framed from another view than the 256³ one.
#[test]
fn an_upsampled_volume_keeps_its_placement() {
    let (nx, ny, nz) = (6usize, 5usize, 4usize);
    let mut data = vec![0u8; nx * ny * nz];
    data[1 + nx * (2 + ny * 2)] = 255;
    let src = tmp("placed.nrrd");
    let mut bytes = format!(
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: {nx} {ny} {nz}\nspace: right-anterior-superior\n\
         space directions: (-1,0,0) (0,2,0) (0,0.5,3)\nspace origin: (10,20,30)\nencoding: raw\n\n"
    )
    .into_bytes();
    bytes.extend_from_slice(&data);
    std::fs::write(&src, bytes).unwrap();
    let up = tmp("placed2x.nrrd");
    let out =
        voxsplat(&["make-volume", "--from", src.to_str().unwrap(), "--factor", "2", "--out", up.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let place = |p: &std::path::Path| voxsplat::loaders::load_orientation(p, &Default::default()).unwrap().unwrap();
    let (a, b) = (place(&src), place(&up));
    // The bright voxel's world position, and the value-weighted centroid of the upsampled copy
    // (trilinear spreads it evenly about its centre): both through the files' own affines.
    let world = |o: &voxsplat::orient::Orientation, i: f64, j: f64, k: f64| {
        o.affine().transform_point3(glam::DVec3::new(i, j, k))
    };
    let want = world(&a, 1.0, 2.0, 2.0);
    let v = voxsplat::loaders::load_volume(&up, &Default::default()).unwrap();
    let [ux, uy, uz] = v.dims.map(|d| d as usize);
    let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0);
    for k in 0..uz {
        for j in 0..uy {
            for i in 0..ux {
                let w = v.values[i + ux * (j + uy * k)] as f64;
                // The loader stores a left-handed file with x reversed.
                let fi = if b.flip_x() { ux - 1 - i } else { i };
                sum += world(&b, fi as f64, j as f64, k as f64) * w;
                weight += w;
            }
        }
    }
    let got = sum / weight;
    assert!((got - want).length() < 1e-3, "the upsampled object sits at {got:?}, the source's at {want:?}");
    // Written in the order the loader stores it (x reversed from the left-handed file), so the
    // output's affine is right-handed; the angles between its axes are the source's.
    assert!(a.flip_x() && !b.flip_x());
    let (aa, ba) = (a.angles(), b.angles());
    assert!((0..3).all(|i| (aa[i] - ba[i]).abs() < 1e-9), "{aa:?} {ba:?}");
}

/// A bricked volume through the CLI: a budget below the store and one brick of splats names the
/// minimum, a zero budget is refused, the other orders fall back to host-classified splats, the
/// sheet modes draw the bricks, and
/// `bricks --volume` measures one file.
#[test]
fn bricked_volumes_take_a_budget_and_fall_back_where_they_must() {
    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");
    let png = tmp("stent.png");
    let base = ["render", "--volume", stent, "--tf", "ct", "--size", "40x40", "--out", png.to_str().unwrap()];
    // 1 MiB cannot hold even the images of a 400x400 frame (the store would stream).
    let big = ["render", "--volume", stent, "--tf", "ct", "--size", "400x400", "--out", png.to_str().unwrap()];
    let out = voxsplat(&[&big[..], &["--gpu-budget-mib", "1"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("GPU budget of 1 MiB") && err.contains("the minimum is"), "{err}");
    // Issue 44: the store streams at that budget, and the message says so (it said it could not
    // hold the store, then named a minimum below the store's size).
    assert!(err.contains("cannot stream this volume's bricked store"), "{err}");
    let out = voxsplat(&[&base[..], &["--gpu-budget-mib", "0"]].concat());
    assert!(
        !out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--gpu-budget-mib must be positive")
    );
    // Other orders need host-classified splats: picked without --dense. The sheets draw bricks.
    let out = voxsplat(&[&base[..], &["--order", "btf", "--validation"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("bytes per splat") && !err.contains("stored voxels in"), "{err}");
    let out = voxsplat(&[&base[..], &["--accumulate", "sheet", "--validation"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("stored voxels in"), "{err}");
    let out = voxsplat(&[&base[..], &["--validation"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && err.contains("stored voxels in") && err.contains("bytes per stored voxel"),
        "{err}"
    );
    let out = voxsplat(&["lab", "bricks", "--volume", stent, "--tf", "ct", "--size", "32", "--frames", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("stored") && text.contains("median frame"), "{text}");
}

/// `voxsplat lab kernels` lists every kernel with its ripple and error, and the fitted
/// Crawfis-Max kernel ripples least.
#[test]
fn kernels_subcommand_compares_every_kernel() {
    let chart = tmp("kernels.svg");
    let out =
        voxsplat(&["lab", "kernels", "--n", "32", "--size", "64", "--frames", "1", "--chart", chart.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let ripple = |name: &str| -> f64 {
        let line =
            text.lines().find(|l| l.starts_with(&format!("| {name} |"))).unwrap_or_else(|| panic!("{name}: {text}"));
        line.split('|').nth(4).unwrap().trim().trim_end_matches(" %").parse().unwrap()
    };
    let fitted = ripple("crawfis-max");
    for other in ["gaussian", "cubic", "narrow"] {
        assert!(fitted < ripple(other), "crawfis-max ripples {fitted} %, {other} {} %", ripple(other));
    }
    assert!(std::fs::read_to_string(&chart).unwrap().contains("<svg"));
    assert_eq!(voxsplat(&["lab", "kernels", "--n", "4"]).status.code(), Some(2));
}

/// `voxsplat lab antialias`: the terrain and orthographic figures, every mode measured;
/// the orthographic view lies wholly beyond k and anti-aliasing lowers its shimmer.
#[test]
fn antialias_subcommand_measures_the_terrain_and_orthographic_figures() {
    let out = voxsplat(&["lab", "antialias", "--size", "48", "--factor", "2", "--dolly", "3", "--frames", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<Vec<&str>> =
        text.lines().filter(|l| l.starts_with("| Fig")).map(|l| l.split('|').map(str::trim).collect()).collect();
    assert_eq!(rows.len(), 6, "{text}");
    let ortho: Vec<&Vec<&str>> = rows.iter().filter(|r| r[1].contains("orthographic")).collect();
    assert!(ortho.iter().all(|r| r[3] == "100 %" && r[2] == "48×48"), "{text}");
    let shimmer = |r: &Vec<&str>| r[7].parse::<f64>().unwrap();
    assert!(shimmer(ortho[2]) < shimmer(ortho[0]), "EWA shimmers less than none: {text}");
    assert_eq!(voxsplat(&["lab", "antialias", "--dolly", "1"]).status.code(), Some(2));
}

/// `voxsplat lab motion-orders`: every order on every built-in animation, and the blur shapes
/// against the accumulation buffer; WBTF's nesting follows the sorted order more closely than
/// BTF's on the orthographic box (the seed's reason to draw Fig. 4.5 with it).
#[test]
fn motion_orders_subcommand_measures_orders_and_blur_shapes() {
    let out = voxsplat(&["lab", "motion-orders", "--first", "10", "--frames", "2", "--rounds", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let psnr = |anim: &str, order: &str| -> f64 {
        let line =
            text.lines().find(|l| l.starts_with(&format!("| {anim} | {order} |"))).unwrap_or_else(|| panic!("{text}"));
        line.split('|').nth(3).unwrap().trim().parse().unwrap()
    };
    assert!(psnr("rotating-box", "WBTF") > psnr("rotating-box", "BTF") + 10.0, "{text}");
    // Blur shapes: every method through both raster choices on the three animations; on the fast
    // turn the bent, tapered footprint is nearer the 64 sub-frames than the seed's.
    let rmse = |anim: &str, method: &str, raster: &str| -> f64 {
        let head = format!("| {anim} | {method} | {raster} |");
        let line = text.lines().find(|l| l.starts_with(&head)).unwrap_or_else(|| panic!("{head}: {text}"));
        line.split('|').nth(4).unwrap().trim().parse().unwrap()
    };
    for anim in ["rotating-box", "spinning-box", "rotating-terrain-ortho"] {
        for raster in ["auto", "graphics"] {
            assert!(rmse(anim, "accum:5", raster) < rmse(anim, "still", raster), "{text}");
        }
    }
    assert!(
        rmse("spinning-box", "splat:arc+tapered", "graphics") < rmse("spinning-box", "splat", "graphics"),
        "{text}"
    );
    assert_eq!(voxsplat(&["lab", "motion-orders", "--first", "20", "--frames", "10"]).status.code(), Some(2));
}

/// `--positions` (issue 26 item 6): a raw volume on irregular z slices renders at them, and its
/// order checks clean; wrong counts, non-finite values and unknown keys are refused.
#[test]
fn a_volume_renders_on_the_slice_positions_a_sidecar_gives() {
    let (raw, pos) = (cmd::tmp_in("cli", "rect.raw"), cmd::tmp_in("cli", "rect.toml"));
    // 16 x 16 x 8: a slab of value 200 in the middle slices.
    let mut data = vec![0u8; 16 * 16 * 8];
    for (n, v) in data.iter_mut().enumerate() {
        let (x, y, z) = (n % 16, n / 16 % 16, n / 256);
        if (4..12).contains(&x) && (4..12).contains(&y) && (2..6).contains(&z) {
            *v = 200;
        }
    }
    std::fs::write(&raw, &data).unwrap();
    std::fs::write(&pos, "z = [0.0, 0.5, 1.0, 3.0, 5.0, 5.5, 6.0, 9.0]\n").unwrap();
    let out = cmd::tmp_in("cli", "rect.png");
    let base = ["--volume", raw.to_str().unwrap(), "--dims", "16,16,8", "--dtype", "u8"];
    let with = |extra: &[&str]| {
        let mut a = vec!["render"];
        a.extend_from_slice(&base);
        a.extend_from_slice(extra);
        a.extend_from_slice(&["--size", "64x64", "--out", out.to_str().unwrap()]);
        voxsplat(&a)
    };
    let ok = with(&["--positions", pos.to_str().unwrap()]);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let mut check = vec!["order"];
    check.extend_from_slice(&base);
    check.extend_from_slice(&["--positions", pos.to_str().unwrap(), "--check", "--eye", "3,2,4", "--size", "64x64"]);
    let o = voxsplat(&check);
    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && text.contains("violations: 0"), "{text}");
    for (bad, says) in [
        ("z = [0.0, 1.0]\n", "2 z values for 8 voxels"),
        ("z = [0.0, 0.5, 1.0, 3.0, nan, 5.5, 6.0, 9.0]\n", "not a finite coordinate"),
        ("z = [0.0, 0.5, 1.0, 3.0, 2.0, 5.5, 6.0, 9.0]\n", "must increase strictly"),
        ("w = [1.0]\n", "unknown field"),
    ] {
        std::fs::write(&pos, bad).unwrap();
        let e = with(&["--positions", pos.to_str().unwrap()]);
        let msg = String::from_utf8_lossy(&e.stderr);
        assert_eq!(e.status.code(), Some(2), "{bad}: {msg}");
        assert!(msg.contains(says), "{bad}: {msg}");
    }
}

/// `--clip` and `--crop` (issue 27 item 2): a cut draws less, a cut that keeps nothing draws
/// nothing, and a degenerate plane or more than six are refused.
#[test]
fn clip_planes_and_crop_boxes_from_the_command_line() {
    let out = tmp("clip.png");
    let render = |extra: &[&str]| {
        let mut a = vec!["render", "--scene", "cube40", "--size", "64x64", "--out", out.to_str().unwrap()];
        a.extend_from_slice(extra);
        voxsplat(&a)
    };
    let alpha = || -> usize {
        let img = voxsplat::output::read_image(&out).unwrap();
        img.pixels.iter().filter(|p| p[3] > 0.0).count()
    };
    assert!(render(&[]).status.success());
    let full = alpha();
    assert!(render(&["--clip", "-1,0,0,0"]).status.success());
    let half = alpha();
    assert!(render(&["--crop", "-5,-5,-5,5,5,5"]).status.success());
    let cropped = alpha();
    assert!(half > 100 && half < full && cropped < full, "{full} {half} {cropped}");
    assert!(render(&["--clip", "0,0,1,-1000", "--raycast", "0.5"]).status.success());
    assert_eq!(alpha(), 0);
    for (bad, says) in [
        (vec!["--clip", "0,0,0,1"], "non-zero"),
        (vec!["--crop", "1,1,1,0,2,2"], "below the second"),
        (vec!["--clip", "1,0,0"], "expected 4"),
    ] {
        let o = render(&bad);
        let msg = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {msg}");
        assert!(msg.contains(says), "{bad:?}: {msg}");
    }
    let seven: Vec<&str> = (0..7).flat_map(|_| ["--clip", "1,0,0,0"]).collect();
    assert!(String::from_utf8_lossy(&render(&seven).stderr).contains("at most 6"));
}

/// `--background` (issue 27 item 1): the frame over a colour, opaque everywhere, the colour itself
/// where nothing is drawn, on the splat path and on the ray caster (the present stage's mirror).
#[test]
fn a_background_fills_the_frame() {
    let out = tmp("background.png");
    let render = |extra: &[&str]| {
        let mut a = vec!["render", "--scene", "cube40", "--size", "48x48", "--out", out.to_str().unwrap()];
        a.extend_from_slice(extra);
        voxsplat(&a)
    };
    for extra in [&["--background", "0.2,0.4,0.6"][..], &["--background", "0.2,0.4,0.6,1", "--raycast", "0.5"]] {
        let o = render(extra);
        assert!(o.status.success(), "{extra:?}: {}", String::from_utf8_lossy(&o.stderr));
        let img = voxsplat::output::read_image(&out).unwrap();
        assert!(img.pixels.iter().all(|p| p[3] > 0.999), "{extra:?}: opaque everywhere");
        let corner = img.pixels[0];
        assert!((corner[2] - 0.6).abs() < 0.003 && (corner[0] - 0.2).abs() < 0.003, "{extra:?}: {corner:?}");
        assert!(img.pixels.iter().any(|p| (p[2] - 0.6).abs() > 0.05), "{extra:?}: the cube shows");
    }
    for bad in ["1,2,3", "0,0", "0,0,0,0,0"] {
        let o = render(&["--background", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
    }
}

/// The peers' scene is drawn as a bricked store classified on the device by default, as a
/// --volume is (`--dense` classifies it on the host): the two frames agree within 8-bit rounding.
/// Levels of detail and `--dense` are refused where they cannot apply, not silently ignored.
#[test]
fn the_peer_scene_bricked_draws_the_dense_frame() {
    let (dense, bricked, lod) = (tmp("peer-dense.png"), tmp("peer-bricked.png"), tmp("peer-lod.png"));
    for (out, extra) in [(&dense, vec!["--dense"]), (&bricked, vec!["--lod", "off"]), (&lod, vec![])] {
        let mut a =
            vec!["render", "--scene", "peer128", "--size", "64x64", "--validation", "--out", out.to_str().unwrap()];
        a.extend(extra.iter().copied());
        let o = voxsplat(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let stored = String::from_utf8_lossy(&o.stderr).contains("bricks");
        assert_eq!(stored, extra != ["--dense"], "{}", String::from_utf8_lossy(&o.stderr));
    }
    let read = |p: &std::path::PathBuf| voxsplat::output::read_rgba8(p).unwrap();
    let (a, b) = (read(&dense), read(&bricked));
    let worst = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).max();
    assert!(worst.unwrap() <= 1, "bricked vs dense: {worst:?}");
    assert!(a.pixels().filter(|p| p[3] > 0).count() > 500);
    // The default, levels of detail: at 64x64 the peers' voxels project below a pixel, so bricks
    // draw coarser cells, which keep their voxels' energy: the frame's coverage stays within 3 % of
    // full detail's (measured 2.0 %; its PSNR against the supersampled reference is 38.3 dB against
    // full detail's 55.8 at this thumbnail size, docs/RESULTS.md).
    let c = read(&lod);
    let coverage = |i: &image::RgbaImage| i.pixels().map(|p| p[3] as f64).sum::<f64>();
    let ratio = coverage(&c) / coverage(&b);
    assert!(c != b && (ratio - 1.0).abs() <= 0.03, "levels of detail against full detail: coverage {ratio:.4}");
    for (bad, names) in [
        (vec!["--scene", "cube40", "--lod", "auto"], "--lod auto"),
        (vec!["--scene", "peer128", "--dense", "--lod", "auto"], "--lod auto"),
        (vec!["--scene", "peer128", "--accumulate", "sheet", "--lod", "auto"], "--lod auto"),
        (vec!["--scene", "cube40", "--dense"], "--dense"),
        (vec!["--scene", "cube40", "--lod-nodes"], "--lod-nodes"),
        (vec!["--scene", "peer128", "--lod", "off", "--lod-nodes"], "--lod-nodes"),
    ] {
        let mut a = vec!["render", "--size", "32x32", "--out", "/tmp/never.png"];
        a.extend(bad.iter().copied());
        let o = voxsplat(&a);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        assert!(String::from_utf8_lossy(&o.stderr).contains(names), "{bad:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
}

#[test]
fn projection_modes_and_picking_from_the_command_line() {
    let dir = tmp("modes");
    std::fs::create_dir_all(&dir).unwrap();
    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");
    for mode in ["mip", "minip", "average", "xray"] {
        let out_png = dir.join(format!("{mode}.png"));
        let args = ["render", "--volume", stent, "--tf", "ct", "--size", "96x96", "--validation", "--mode", mode];
        let mut args = args.to_vec();
        let p = out_png.to_str().unwrap();
        args.extend(["--out", p]);
        let out = voxsplat(&args);
        assert!(out.status.success(), "{mode}: {}", String::from_utf8_lossy(&out.stderr));
        let img = image::open(&out_png).unwrap().to_rgba8();
        assert!(img.pixels().filter(|px| px[3] > 128).count() > 200, "{mode}: the stent is drawn");
        // The ray caster in the same mode.
        args.extend(["--raycast", "0.5"]);
        let out = voxsplat(&args);
        assert!(out.status.success(), "{mode} --raycast: {}", String::from_utf8_lossy(&out.stderr));
    }
    // Flags that cannot apply are refused.
    let p = dir.join("x.png");
    let p = p.to_str().unwrap();
    for (extra, says) in [
        (vec!["--mode", "mip", "--accumulate", "sheet"], "visibility order"),
        (vec!["--mode", "mip", "--truth"], "--truth"),
        (vec!["--mode", "mip", "--order", "btf"], "--order"),
        (vec!["--mode", "mip", "--direction", "ftb"], "no visibility order"),
        (vec!["--mode", "average", "--lod", "auto"], "levels of detail"),
        (vec!["--colormap", "ct"], "--colormap colours"),
    ] {
        let mut args = vec!["render", "--volume", stent, "--size", "32x32", "--out", p];
        args.extend(extra.iter().copied());
        let out = voxsplat(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{extra:?}: {err}");
    }
    // The plan says what a projection draws.
    let out = voxsplat(&["render", "--volume", stent, "--mode", "mip", "--size", "64x64", "--plan"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("mip projection"), "{text}");
    // Picking: the centre of the default view shows the stent; a corner shows nothing.
    let out = voxsplat(&["pick", "--volume", stent, "--tf", "ct", "--size", "64x64", "--at", "32,32"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("voxel ") && text.contains("depth"), "{text}");
    let out = voxsplat(&["pick", "--volume", stent, "--tf", "ct", "--size", "64x64", "--at", "0,0"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("nothing"), "{text}");
    let out = voxsplat(&["pick", "--scene", "cube40", "--size", "64x64", "--at", "64,3"]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("outside the 64 x 64 view"));
}

#[test]
fn isosurfaces_from_the_command_line() {
    let dir = tmp("iso");
    std::fs::create_dir_all(&dir).unwrap();
    let stent = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");
    let png = dir.join("iso.png");
    let p = png.to_str().unwrap();
    // The stent's values lie in 0 .. 2000: its surface at 1000, in the file's units.
    let base = ["render", "--volume", stent, "--size", "96x96", "--validation", "--mode", "iso", "--iso", "1000"];
    for extra in [&[][..], &["--raycast", "0.5"][..]] {
        let mut args = base.to_vec();
        args.extend(extra.iter().copied());
        args.extend(["--out", p]);
        let out = voxsplat(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{extra:?}: {err}");
        let img = image::open(&png).unwrap().to_rgba8();
        assert!(img.pixels().filter(|px| px[3] > 128).count() > 100, "{extra:?}: the stent's surface is drawn");
        assert!(extra.is_empty() == err.contains("surface splats"), "{err}");
    }
    // A value the data never crosses draws nothing and says so.
    let out = voxsplat(&["render", "--volume", stent, "--size", "48x48", "--mode", "iso", "--iso", "5000", "--out", p]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("nothing drawn") && err.contains("0 .. 2000"), "{err}");
    let img = image::open(&png).unwrap().to_rgba8();
    assert!(img.pixels().all(|px| px[3] == 0));
    // The plan, and a pick on the surface.
    let out = voxsplat(&["render", "--volume", stent, "--mode", "iso", "--iso", "1000", "--size", "64x64", "--plan"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("isosurface at 0.5"), "{text}");
    let out =
        voxsplat(&["pick", "--volume", stent, "--mode", "iso", "--iso", "1000", "--size", "96x96", "--at", "50,50"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("voxel ") && text.contains("the volume's values"), "{text}");
    // Flags that cannot apply are refused.
    for (extra, says) in [
        (vec!["--mode", "iso"], "--iso VALUE"),
        (vec!["--mode", "mip", "--iso", "3"], "not --mode mip"),
        (vec!["--mode", "iso", "--iso", "3", "--raster", "graphics"], "compute tile compositor"),
        (vec!["--mode", "iso", "--iso", "3", "--dense"], "bricked store"),
        (vec!["--mode", "iso", "--iso", "3", "--truth"], "--truth"),
    ] {
        let mut args = vec!["render", "--volume", stent, "--size", "32x32", "--out", p];
        args.extend(extra.iter().copied());
        let out = voxsplat(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{extra:?}: {err}");
    }
}

#[test]
fn labels_and_channels_from_the_command_line() {
    let dir = tmp("labels");
    std::fs::create_dir_all(&dir).unwrap();
    let n = 16usize;
    // Labels 1 and 2 in two halves of a block, 9 (not in the table) in a corner.
    let seg: Vec<u8> = (0..n * n * n)
        .map(|v| {
            let (i, j, k) = (v % n, v / n % n, v / (n * n));
            match (i, j, k) {
                _ if i < 2 && j < 2 => 9,
                _ if (3..13).contains(&j) && (3..13).contains(&k) && (3..8).contains(&i) => 1,
                _ if (3..13).contains(&j) && (3..13).contains(&k) && (8..13).contains(&i) => 2,
                _ => 0,
            }
        })
        .collect();
    let shape = [n as u64; 3];
    let seg_path = dir.join("seg.npy");
    std::fs::write(&seg_path, common::npy(&shape, "|u1", &seg)).unwrap();
    let table = dir.join("labels.toml");
    std::fs::write(
        &table,
        "[[label]]\nvalue = 1\ncolor = [1, 0, 0]\nopacity = 0.8\n\n[[label]]\nvalue = 2\ncolor = [0, 0, 1]\nopacity = 0.8\n",
    )
    .unwrap();
    let (seg_s, table_s) = (seg_path.to_str().unwrap(), table.to_str().unwrap());
    let out_png = dir.join("labels.png");
    let args = ["render", "--labels", seg_s, "--label-table", table_s, "--size", "64x64", "--cpu"];
    let mut args = args.to_vec();
    args.extend(["--out", out_png.to_str().unwrap()]);
    let out = voxsplat(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("64 voxels hidden: their labels (9)"), "{err}");
    let img = image::open(&out_png).unwrap().to_rgba8();
    assert!(img.pixels().any(|p| p[0] > 150 && p[2] == 0) && img.pixels().any(|p| p[2] > 150 && p[0] == 0));
    assert!(img.pixels().all(|p| p[1] == 0), "no label is green");
    // Over a scalar volume of another size: refused.
    let small: Vec<u8> = vec![100; 8 * 8 * 8];
    let small_path = dir.join("small.npy");
    std::fs::write(&small_path, common::npy(&[8; 3], "|u1", &small)).unwrap();
    let small_s = small_path.to_str().unwrap();
    let p = dir.join("x.png");
    let p = p.to_str().unwrap();
    let out = voxsplat(&["render", "--volume", small_s, "--labels", seg_s, "--label-table", table_s, "--out", p]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("must match"));
    // Channels: the label volume's values as a second channel of itself.
    let ramp: Vec<u8> = (0..n * n * n).map(|v| (v % 251) as u8).collect();
    let ramp_path = dir.join("ramp.npy");
    std::fs::write(&ramp_path, common::npy(&shape, "|u1", &ramp)).unwrap();
    let ramp_s = ramp_path.to_str().unwrap();
    let out = voxsplat(&[
        "render",
        "--volume",
        ramp_s,
        "--channel",
        seg_s,
        "--channel-tf",
        "ct",
        "--size",
        "48x48",
        "--out",
        p,
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // A 4-D NIfTI of two channels (the ramp, then the labels), each with its transfer function.
    let mut four = common::nifti([n as u32; 3], &[ramp.clone(), seg.clone()].concat(), None, None);
    four[40..42].copy_from_slice(&4i16.to_le_bytes());
    four[48..50].copy_from_slice(&2i16.to_le_bytes());
    let four_path = dir.join("two.nii");
    std::fs::write(&four_path, four).unwrap();
    let four_s = four_path.to_str().unwrap();
    let out = voxsplat(&["render", "--volume", four_s, "--channel-tf", "ct", "--size", "48x48", "--out", p]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = voxsplat(&["render", "--volume", four_s, "--size", "48x48", "--out", p]);
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("holds 2 channels"));
    for (extra, says) in [
        (vec!["--channel", seg_s], "give each channel after the first its transfer function"),
        (vec!["--channel", small_s, "--channel-tf", "ramp"], "share one grid"),
        (vec!["--channel-tf", "ramp"], "give each channel after the first"),
    ] {
        let mut args = vec!["render", "--volume", ramp_s, "--size", "32x32", "--out", p];
        args.extend(extra.iter().copied());
        let out = voxsplat(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{extra:?}: {err}");
    }
}

/// `voxsplat bench`: two cases with validation on, the report as a table and as JSON (the score
/// the geometric mean of the frame rates, a PSNR against the cached truth, the device named), the
/// comparison of a report with itself, and the refusals.
#[test]
fn bench_runs_named_cases_and_compares_reports() {
    let (cache, json) = (tmp("bench-cache"), tmp("bench.json"));
    let args = ["bench", "--case", "cube60", "--case", "motion", "--frames", "2", "--warmup", "0", "--validation"];
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--cache", cache.to_str().unwrap(), "--json", json.to_str().unwrap()]);
    let out = voxsplat(&all);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("suite 1") && text.contains("score:") && text.contains("validation was on"), "{text}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let cases = r["cases"].as_array().unwrap();
    assert_eq!(cases.iter().map(|c| c["name"].as_str().unwrap()).collect::<Vec<_>>(), ["cube60", "motion"]);
    let fps: Vec<f64> = cases.iter().map(|c| c["fps"].as_f64().unwrap()).collect();
    let geo = (fps[0] * fps[1]).sqrt();
    assert!((r["score"].as_f64().unwrap() - geo).abs() < 1e-9 * geo, "{r}");
    // cube60 against its volumetric-summation truth (35.1 dB measured); the animation has none.
    let psnr = cases[0]["psnr_db"].as_f64().unwrap();
    assert!(psnr > 30.0, "{psnr}");
    assert!(cases[1]["psnr_db"].is_null());
    assert_eq!(cases[0]["splats"].as_u64(), Some(20888));
    assert!(
        !r["platform"]["device"].as_str().unwrap().is_empty() && !r["platform"]["commit"].as_str().unwrap().is_empty()
    );
    assert!(cache.join("truth-v1-cube60-512x512.exr").exists(), "the truth is cached");
    // A report against itself: every case level, the scores' ratio 1.
    let j = json.to_str().unwrap();
    let out = voxsplat(&["bench", "--compare", j, j]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success() && text.contains("B/A 1.000x") && text.matches("within the noise").count() == 2,
        "{text}"
    );
    // Refusals: an unknown case, a report of another suite version, a case without its data.
    assert!(cmd::refused(&["bench", "--case", "teapot"]).contains("no case 'teapot'"));
    let other = tmp("bench-v99.json");
    std::fs::write(&other, std::fs::read_to_string(&json).unwrap().replacen("\"suite\": 1", "\"suite\": 99", 1))
        .unwrap();
    assert!(cmd::refused(&["bench", "--compare", j, other.to_str().unwrap()]).contains("suite 1 against suite 99"));
    let text =
        cmd::refused(&["bench", "--case", "bonsai", "--data", "/nonexistent", "--cache", cache.to_str().unwrap()]);
    assert!(text.contains("no case ran"), "{text}");
}

/// `voxsplat render --help` lists the options a user sets, each under a heading (scene and file,
/// view, transfer function and mode, quality and speed, output), and none of the research
/// switches; `voxsplat-lab render --help` lists those too, under their own heading, and the user's
/// binary refuses them by name.
#[test]
fn render_s_help_is_the_user_s_and_the_lab_s_adds_the_research_switches() {
    let help = |args: &[&str]| {
        let out = voxsplat(args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    // (heading, the long options under it)
    let sections = |text: &str| -> Vec<(String, Vec<String>)> {
        let mut s: Vec<(String, Vec<String>)> = Vec::new();
        for line in text.lines() {
            if !line.starts_with(' ') && line.ends_with(':') {
                s.push((line.trim_end_matches(':').to_string(), Vec::new()));
            } else if let Some(flag) = line.trim_start().strip_prefix("--").filter(|_| line.starts_with("  ")) {
                let name = flag.split([' ', ',']).next().unwrap().to_string();
                if line.len() - line.trim_start().len() <= 6 {
                    s.last_mut().expect("an option before any heading").1.push(name);
                }
            }
        }
        s
    };
    let user = sections(&help(&["render", "--help"]));
    let headings: Vec<&str> = user.iter().map(|(h, _)| h.as_str()).collect();
    assert_eq!(
        headings,
        ["Options", "Scene and file", "View", "Transfer function and mode", "Quality and speed", "Output"],
        "{user:?}"
    );
    // Under "Options" only what every command takes (and `-h, --help`).
    assert_eq!(user[0].1, ["host-budget-mib"], "options without a heading");
    let all: Vec<&String> = user.iter().flat_map(|(_, o)| o).collect();
    // Issue 77 asks for at most 35 options a user sets; there were 58 before the engine's paths,
    // the reference's settings and the visibility order moved to the lab and --shade took
    // --no-shade's place. This bound only falls.
    assert!(all.len() - 1 <= 47, "voxsplat render has {} options of its own: {all:?}", all.len() - 1);
    for switch in cmd::RESEARCH {
        assert!(!all.iter().any(|o| format!("--{o}") == switch), "{switch} in voxsplat render --help");
        let out = cmd::user_binary(&["render", "--scene", "cube40", switch, "--out", "x.png"]);
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.code() == Some(2) && e.starts_with("error:") && e.contains(switch), "{e}");
    }
    let lab = sections(&help(&["lab", "render", "--help"]));
    let research = &lab.iter().find(|(h, _)| h == "Research").expect("a Research heading").1;
    let mut want: Vec<String> = cmd::RESEARCH.iter().map(|s| s.trim_start_matches("--").to_string()).collect();
    let mut got = research.clone();
    want.sort();
    got.sort();
    assert_eq!(got, want);
    let lab_all: Vec<&String> = lab.iter().flat_map(|(_, o)| o).collect();
    assert_eq!(lab_all.len(), all.len() + cmd::RESEARCH.len(), "the lab's render takes every user option");
}

/// `--shade` takes on or off (alone: on); without it, the preset's own default holds (the bonsai
/// preset shaded, ramp not). It took `--no-shade`'s place (issue 77: one flag for one idea).
#[test]
fn shade_is_on_off_or_the_preset_s_default() {
    let n = 24usize;
    let mut bytes = format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: {n} {n} {n}\nencoding: raw\n\n").into_bytes();
    bytes.extend((0..n * n * n).map(|v| {
        let p = [v % n, v / n % n, v / (n * n)].map(|c| c as f32 - 11.5);
        let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        if d < 10.0 {
            (250.0 - 15.0 * d) as u8
        } else {
            0
        }
    }));
    let vol = tmp("shade.nrrd");
    std::fs::write(&vol, bytes).unwrap();
    let frame = |tf: &str, shade: &[&str]| -> Vec<u8> {
        let out = tmp(&format!("shade-{tf}{}.png", shade.join("-")));
        let mut a = vec!["render", "--volume", vol.to_str().unwrap(), "--tf", tf, "--size", "48x48", "--cpu"];
        a.extend_from_slice(shade);
        a.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = voxsplat(&a);
        assert!(o.status.success(), "{a:?}: {}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(&out).unwrap()
    };
    let bonsai = frame("bonsai", &[]);
    assert_eq!(bonsai, frame("bonsai", &["--shade"]), "the bonsai preset is shaded by default");
    assert_eq!(bonsai, frame("bonsai", &["--shade", "on"]));
    assert_ne!(bonsai, frame("bonsai", &["--shade", "off"]), "--shade off turns the preset's shading off");
    let ramp = frame("ramp", &[]);
    assert_eq!(ramp, frame("ramp", &["--shade", "off"]), "ramp is unshaded by default");
    assert_ne!(ramp, frame("ramp", &["--shade", "on"]));
    let o = voxsplat(&["render", "--shade", "maybe", "--out", "x.png"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.code() == Some(2) && e.contains("--shade") && e.contains("[possible values: on, off]"), "{e}");
}
