//! OME-Zarr images (issue 47) with files no one here wrote: pyramids the `ome-zarr` package writes
//! from the shared bonsai (0.4 on Zarr v2 with zstd, 0.5 on Zarr v3 sharded), and a series of time
//! points and channels compressed with blosc, each level checked against what zarr-python reads
//! back; then files broken one way each, refused by name.
use crate::cmd;
use cmd::{refused, voxsplat};
use std::path::{Path, PathBuf};
use voxsplat::loaders::{load_channels, load_volume, npy_from_bytes, OmeZarr, VolumeHints};

fn tmp(name: &str) -> PathBuf {
    cmd::tmp_in("zarr", name)
}

/// Runs tests/data/write_ome_zarr.py (the ome-zarr package, pip-installed by scripts/setup.sh).
fn write_with_python(args: &[&str]) {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/write_ome_zarr.py");
    let out = std::process::Command::new("python3").arg(script).args(args).output().expect("python3");
    assert!(
        out.status.success(),
        "write_ome_zarr.py {args:?} (scripts/setup.sh installs ome-zarr): {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn level(l: u32) -> VolumeHints {
    VolumeHints { level: Some(l), ..Default::default() }
}

fn npy(path: &Path) -> (Vec<u64>, Vec<f32>) {
    npy_from_bytes(&std::fs::read(path).unwrap(), &path.display().to_string()).unwrap()
}

fn render(args: &[&str], out: &Path) -> image::RgbaImage {
    render_at("64x64", args, out)
}

fn render_at(size: &str, args: &[&str], out: &Path) -> image::RgbaImage {
    let mut all = vec!["render", "--size", size, "--validation", "--out", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = voxsplat(&all);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    image::open(out).unwrap().to_rgba8()
}

#[test]
fn the_ome_zarr_packages_pyramids_read_as_zarr_python_reads_them() {
    let dir = tmp("bonsai");
    std::fs::create_dir_all(&dir).unwrap();
    let bonsai = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/bonsai/bonsai.nii.gz");
    write_with_python(&["bonsai", bonsai, dir.to_str().unwrap()]);
    for (name, version) in [("v04.zarr", "0.4"), ("v05.zarr", "0.5")] {
        let path = dir.join(name);
        let image = OmeZarr::open(&path).unwrap();
        assert_eq!((image.version.as_str(), image.levels.len(), image.times, image.channels), (version, 3, 1, 1));
        for l in 0..3u32 {
            let v = load_volume(&path, &level(l)).unwrap();
            let (shape, want) = npy(&dir.join(format!("{name}.level{l}.npy")));
            let side = 256 >> l;
            assert_eq!((shape, v.dims), (vec![side as u64; 3], [side; 3]), "{name} level {l}");
            assert!(v.values == want, "{name} level {l}: the values zarr-python reads");
            // The file's scale: 1.5 along z at level 0, doubling with each level.
            let s = (1 << l) as f32;
            assert_eq!(v.spacing, [s, s, 1.5 * s], "{name} level {l}");
        }
        // Streamed a row of chunks at a time into the bricked store, as the whole volume builds it.
        let streamed = voxsplat::bricks::BrickStore::load(&path, &level(0)).unwrap();
        let whole = voxsplat::bricks::BrickStore::build(&load_volume(&path, &level(0)).unwrap()).unwrap();
        assert!(streamed.records == whole.records && streamed.headers == whole.headers, "{name}");
    }
    // The CLI draws a level as it draws the same samples from zarr-python's .npy, spaced alike.
    let (a, b) = (tmp("level1.png"), tmp("level1-npy.png"));
    let zarr = dir.join("v05.zarr");
    let level1 = dir.join("v05.zarr.level1.npy");
    let from_zarr = render(&["--volume", zarr.to_str().unwrap(), "--tf", "bonsai", "--level", "1"], &a);
    let from_npy = render(&["--volume", level1.to_str().unwrap(), "--tf", "bonsai", "--spacing", "2,2,3"], &b);
    assert!(from_zarr == from_npy, "the level's frame");
    assert!(from_zarr.pixels().any(|p| p[3] > 0), "something drawn");
    // By default the finest level; the coarsest the host budget holds when it cannot hold that
    // (level 0's store may take 67 MiB, level 1's 8.4), said on stderr.
    let z = zarr.to_str().unwrap();
    let finest = render(&["--volume", z, "--tf", "bonsai"], &tmp("default.png"));
    assert!(finest == render(&["--volume", z, "--tf", "bonsai", "--level", "0"], &tmp("level0.png")));
    let out = tmp("budget.png");
    let o = voxsplat(&[
        "--host-budget-mib",
        "32",
        "render",
        "--volume",
        z,
        "--tf",
        "bonsai",
        "--size",
        "64x64",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && err.contains("OME-Zarr level 1 of 0..2 drawn"), "{err}");
    // Level 1's 16 shards, 4 a row of 16 slices, read row by row once (the store's brick pass
    // takes what its range pass kept); no chunk of level 0.
    assert!(err.contains("the store read 32 chunks (0 read before it"), "{err}");
    assert!(image::open(&out).unwrap().to_rgba8() == from_zarr, "the budget's level is level 1");
    // `auto` reads the coarsest level whose voxels span at most 0.75 px: level 1 at 64 x 64
    // (0.65 px), level 0 at 256 x 256 (level 1's would span 1.3).
    let auto = ["--volume", z, "--tf", "bonsai", "--level", "auto"];
    assert!(render(&auto, &tmp("auto.png")) == from_zarr, "auto at 64 x 64");
    let level0 = render_at("256x256", &["--volume", z, "--tf", "bonsai", "--level", "0"], &tmp("l0-256.png"));
    assert!(render_at("256x256", &auto, &tmp("auto-256.png")) == level0, "auto at 256 x 256");
    let err = refused(&["render", "--volume", z, "--level", "auto", "--dense", "--out", out.to_str().unwrap()]);
    assert!(err.contains("--level auto picks a level of an OME-Zarr --volume drawn from its bricked store"), "{err}");
    // `info` lists the pyramid; a level past it and a level of a file without one are refused.
    let out = voxsplat(&["info", zarr.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("OME-Zarr 0.5") && text.contains("level 2 's2': [64, 64, 64]"),
        "{text}"
    );
    let err = refused(&["info", zarr.to_str().unwrap(), "--level", "3"]);
    assert!(err.contains("no level 3: the pyramid has 3"), "{err}");
    let err = refused(&["render", "--volume", level1.to_str().unwrap(), "--level", "1", "--out", a.to_str().unwrap()]);
    assert!(err.contains("--level picks a level of an OME-Zarr image; this is none"), "{err}");
}

#[test]
fn time_points_and_channels_are_picked_and_blosc_decodes() {
    let dir = tmp("series");
    std::fs::create_dir_all(&dir).unwrap();
    write_with_python(&["series", dir.to_str().unwrap()]);
    let path = dir.join("tczyx.zarr");
    let image = OmeZarr::open(&path).unwrap();
    assert_eq!((image.times, image.channels, image.levels[0].dims), (3, 2, [28, 24, 20]));
    // Several time points need one picked; several channels are read together.
    let err = load_channels(&path, &VolumeHints::default()).unwrap_err().to_string();
    assert!(err.contains("holds 3 time points: pick one with --time N"), "{err}");
    let err = load_volume(&path, &VolumeHints { time: Some(0), ..Default::default() }).unwrap_err().to_string();
    assert!(err.contains("holds 2 channels"), "{err}");
    for (l, file) in [(0u32, "tczyx.npy"), (1, "tczyx.zarr.level1.npy")] {
        let (shape, all) = npy(&dir.join(file));
        // Saved as 3-D: the six volumes of (time, channel) one after another along z.
        let block = (shape[0] / 6 * shape[1] * shape[2]) as usize;
        for t in 0..3u32 {
            let hints = VolumeHints { time: Some(t), level: Some(l), ..Default::default() };
            let channels = load_channels(&path, &hints).unwrap();
            assert_eq!(channels.len(), 2);
            for (c, v) in channels.iter().enumerate() {
                let at = (t as usize * 2 + c) * block;
                assert!(v.values == all[at..at + block], "level {l}, time {t}, channel {c}");
            }
        }
    }
    let err = load_channels(&path, &VolumeHints { time: Some(3), ..Default::default() }).unwrap_err().to_string();
    assert!(err.contains("no time point 3: the image has 3"), "{err}");
    // The CLI draws the two channels of a time point, each by its transfer function.
    let png = tmp("channels.png");
    let p = path.to_str().unwrap();
    let img = render(&["--volume", p, "--time", "2", "--tf", "ramp", "--channel-tf", "ramp", "--mode", "mip"], &png);
    assert!(img.pixels().any(|p| p[3] > 0));
    let err = refused(&["render", "--volume", p, "--out", png.to_str().unwrap()]);
    assert!(err.contains("time points"), "{err}");
}

/// A hand-written OME-NGFF 0.4 image of two levels (raw chunks, no compressor): 12 x 10 x 8
/// voxels of u16 in chunks of 4 x 4 x 4, and its 6 x 5 x 4 half.
fn small_image(dir: &Path) {
    let _ = std::fs::remove_dir_all(dir);
    let level = |path: &str, shape: [u64; 3], scale: f64| {
        let d = dir.join(path);
        std::fs::create_dir_all(&d).unwrap();
        let zarray = format!(
            r#"{{"zarr_format": 2, "shape": [{}, {}, {}], "chunks": [4, 4, 4], "dtype": "<u2", "compressor": null,
               "fill_value": 0, "order": "C", "filters": null, "dimension_separator": "/"}}"#,
            shape[0], shape[1], shape[2]
        );
        std::fs::write(d.join(".zarray"), zarray).unwrap();
        let chunks = shape.map(|s| s.div_ceil(4));
        for cz in 0..chunks[0] {
            for cy in 0..chunks[1] {
                for cx in 0..chunks[2] {
                    let mut bytes = Vec::new();
                    for z in 0..4 {
                        for y in 0..4 {
                            for x in 0..4 {
                                let v = ((cz * 4 + z) * 100 + (cy * 4 + y) * 10 + cx * 4 + x) as u16 + scale as u16;
                                bytes.extend_from_slice(&v.to_le_bytes());
                            }
                        }
                    }
                    let c = d.join(format!("{cz}/{cy}"));
                    std::fs::create_dir_all(&c).unwrap();
                    std::fs::write(c.join(cx.to_string()), bytes).unwrap();
                }
            }
        }
    };
    level("0", [8, 10, 12], 1.0);
    level("1", [4, 5, 6], 2.0);
    let axes = r#"[{"name": "z", "type": "space"}, {"name": "y", "type": "space"}, {"name": "x", "type": "space"}]"#;
    let zattrs = format!(
        r#"{{"multiscales": [{{"version": "0.4", "axes": {axes}, "datasets": [
            {{"path": "0", "coordinateTransformations": [{{"type": "scale", "scale": [1, 1, 1]}}]}},
            {{"path": "1", "coordinateTransformations": [{{"type": "scale", "scale": [2, 2, 2]}}]}}]}}]}}"#
    );
    std::fs::write(dir.join(".zattrs"), zattrs).unwrap();
    std::fs::write(dir.join(".zgroup"), r#"{"zarr_format": 2}"#).unwrap();
}

/// `path`'s text with `from` replaced by `to` (which must occur).
fn edit(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains(from), "{from} in {}", path.display());
    std::fs::write(path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn broken_images_are_refused_by_file_and_field() {
    let dir = tmp("small.zarr");
    small_image(&dir);
    let v = load_volume(&dir, &VolumeHints::default()).unwrap();
    assert_eq!((v.dims, v.values[0], v.values[12 * 10 * 8 - 1]), ([12, 10, 8], 1.0, 7.0 * 100.0 + 90.0 + 11.0 + 1.0));
    let l1 = load_volume(&dir, &level(1)).unwrap();
    assert_eq!((l1.dims, l1.spacing), ([6, 5, 4], [2.0; 3]));
    type Break = fn(&Path);
    let cases: [(&str, Break, &str); 12] = [
        (
            // Issue 76: a 24 KB image declaring 2048^3 with no chunk ran for minutes in `info`.
            "no chunk stored",
            |d| {
                std::fs::remove_dir_all(d.join("0")).unwrap();
                std::fs::create_dir_all(d.join("0")).unwrap();
                let zarray = r#"{"zarr_format": 2, "shape": [2048, 2048, 2048], "chunks": [64, 64, 64],
                    "dtype": "<u2", "compressor": null, "fill_value": 0, "order": "C", "filters": null,
                    "dimension_separator": "/"}"#;
                std::fs::write(d.join("0/.zarray"), zarray).unwrap();
                std::fs::remove_dir_all(d.join("1")).unwrap();
                edit(
                    &d.join(".zattrs"),
                    r#",
            {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [2, 2, 2]}]}"#,
                    "",
                );
            },
            "stores no chunk: every voxel is the array's fill value",
        ),
        (
            "truncated chunk",
            |d| std::fs::write(d.join("0/1/1/2"), [0u8; 17]).unwrap(),
            "chunk 0/1/1/2: the size of a decoded chunk is 17",
        ),
        (
            "chunks that disagree with the data",
            |d| edit(&d.join("0/.zarray"), r#""chunks": [4, 4, 4]"#, r#""chunks": [4, 4, 8]"#),
            "level 0",
        ),
        (
            "a level whose shape disagrees with its scale",
            |d| edit(&d.join(".zattrs"), r#""scale": [2, 2, 2]"#, r#""scale": [2, 2, 3]"#),
            "disagrees with its scale",
        ),
        (
            "levels coarsest first",
            |d| edit(&d.join(".zattrs"), r#""scale": [1, 1, 1]"#, r#""scale": [4, 4, 4]"#),
            "finer than level 0",
        ),
        (
            "a path out of the image",
            |d| edit(&d.join(".zattrs"), r#""path": "1""#, r#""path": "../1""#),
            "not a folder inside",
        ),
        ("a missing level", |d| std::fs::remove_file(d.join("1/.zarray")).unwrap(), "missing"),
        (
            "a chunk past the limit",
            |d| edit(&d.join("0/.zarray"), r#""chunks": [4, 4, 4]"#, r#""chunks": [4096, 4096, 4096]"#),
            "decodes to more than",
        ),
        (
            "a shape past the limit",
            |d| edit(&d.join("0/.zarray"), r#""shape": [8, 10, 12]"#, r#""shape": [8000000, 10000000, 12]"#),
            "voxels",
        ),
        (
            "another version",
            |d| edit(&d.join(".zattrs"), r#""version": "0.4""#, r#""version": "0.3""#),
            "0.3 is not read",
        ),
        ("a 2-D image", |d| edit(&d.join(".zattrs"), r#"{"name": "z", "type": "space"}, "#, ""), "three spatial axes"),
        ("a sample type not read", |d| edit(&d.join("0/.zarray"), r#""<u2""#, r#""<c8""#), "sample type"),
    ];
    for (case, damage, expect) in cases {
        small_image(&dir);
        damage(&dir);
        let err = match load_volume(&dir, &level(0)) {
            Ok(_) => panic!("{case}: read"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(expect) && err.contains("small.zarr"), "{case}: {err}");
        let text = refused(&["info", dir.to_str().unwrap(), "--level", "0"]);
        assert!(text.contains(expect), "{case}: {text}");
    }
}

/// `level_for` takes the coarsest level whose voxels span at most the given pixels at the point
/// nearest the eye: a far view takes level 1, a near one level 0, and an eye inside the image
/// level 0 (measured at the near plane).
#[test]
fn the_level_for_a_view_follows_the_voxels_projected_size() {
    let dir = tmp("levels.zarr");
    small_image(&dir);
    let image = OmeZarr::open(&dir).unwrap();
    let grid = voxsplat::Grid::centered([12, 10, 8], [1.0; 3]).unwrap();
    let mut cam = voxsplat::Camera::framing(&grid, 64, 64);
    let (near, far) = (image.voxel_pixels(&cam, 0), image.voxel_pixels(&cam, 1));
    assert!((far / near - 2.0).abs() < 1e-4, "level 1's voxels are twice level 0's: {near} {far}");
    assert_eq!(image.level_for(&cam, far * 1.01), 1);
    assert_eq!(image.level_for(&cam, far * 0.99), 0);
    assert_eq!(image.level_for(&cam, near * 0.5), 0, "none fine enough: the finest");
    // Twice as far from the target: the nearest corner more than twice as far.
    let further = voxsplat::Camera { eye: cam.target + (cam.eye - cam.target) * 2.0, ..cam };
    let ratio = image.voxel_pixels(&cam, 0) / image.voxel_pixels(&further, 0);
    assert!(ratio > 2.0 && ratio < 4.0, "{ratio}");
    let outside = far * 1.01;
    cam.eye = glam::Vec3::new(0.1, 0.2, 0.3);
    assert_eq!(image.level_for(&cam, outside), 0, "the eye inside the image: measured at the near plane");
}

/// `render --crop` on an OME-Zarr image (issue 47 item 2): the bricked store reads only the chunks
/// of the voxels its box needs (the bricks the box touches and one brick around them): every chunk
/// of level 0 farther out is corrupted and never read, while the image read whole is refused
/// naming one. It holds zarr-python's values in the box, nothing outside its region, and the
/// default level within the box is the finest whose region fits the host budget.
#[test]
fn a_cropped_image_reads_only_the_chunks_its_box_needs() {
    let dir = tmp("crop");
    std::fs::create_dir_all(&dir).unwrap();
    let bonsai = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/bonsai/bonsai.nii.gz");
    write_with_python(&["bonsai", bonsai, dir.to_str().unwrap()]);
    let path = dir.join("v04.zarr");
    let (_, want) = npy(&dir.join("v04.zarr.level0.npy"));
    // Voxels 100..140 along x, 90..150 along y, 60..100 along z of the 256³ level 0 (spacing 1, 1,
    // 1.5, in chunks of 64, 64, 32), as a box in the grid's centred frame around their centres.
    let (lo, hi, spacing) = ([100u32, 90, 60], [140u32, 150, 100], [1.0f32, 1.0, 1.5]);
    let at = |v: u32, a: usize, off: f32| (v as f32 - 127.5 + off) * spacing[a];
    let crop = [[0, 1, 2].map(|a| at(lo[a], a, -0.25)), [0, 1, 2].map(|a| at(hi[a] - 1, a, 0.25))];
    // A narrow view along x reads only what it sees: the same frame as the whole image read, up to
    // the quantisation of values normalised by the part's range instead of the whole level's (a
    // transfer function over the file's values, 0 to 255; sheets: per-splat compositing blends in
    // the order of the bricks stored).
    let tf = dir.join("tf.toml");
    cmd::tf_file(&tf, 0.0, 255.0);
    let view =
        ["--eye", "300,0,0", "--target", "0,0,0", "--fov", "10", "--accumulate", "sheet", "--tf", tf.to_str().unwrap()];
    let draw = |args: &[&str], out: &str| -> (u32, String) {
        let base = ["render", "--volume", path.to_str().unwrap(), "--size", "48x48", "--validation", "--out"];
        let o = voxsplat(&[&base[..], &[dir.join(out).to_str().unwrap()], args].concat());
        let said = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "{said}");
        (said.split("the store read ").nth(1).and_then(|s| s.split(' ').next()).unwrap().parse().unwrap(), said)
    };
    let psnr = |a: &str, b: &str| -> (f64, String) {
        let db = cmd::psnr(&dir.join(a), &dir.join(b));
        (db, format!("{a} against {b}: {db} dB"))
    };
    let (read, said) = draw(&view, "seen.png");
    assert!(said.contains("the view sees"), "{said}");
    // It sees |y|, |z| < 44 at the far face (5° either side at 428 units, and the margin): along
    // y 2 of the 4 chunks of 64, along z 4 of the 8 chunks of 32 (z spacing 1.5), every x.
    assert!(read <= 32, "{read} of level 0's 128 chunks read for a view along x: {said}");
    let all = ["--crop", "-128,-128,-192,128,128,192"];
    // Every chunk the level stores (ome-zarr writes none that is all fill value: 90 of 128 here).
    assert_eq!(draw(&[&view[..], &all].concat(), "all.png").0, chunk_files(&path.join("s0")) as u32);
    let (db, text) = psnr("seen.png", "all.png");
    assert!(db > 70.0, "the part the view sees against the whole image: {text}");
    // A narrow view along a diagonal: its bounds hold nearly the whole image, and only the
    // chunks it may see are read, drawing the same frame.
    let diagonal = [&view[6..], &["--eye", "300,250,350", "--target", "0,0,0", "--fov", "8"]].concat();
    let (read, said) = draw(&diagonal, "diagonal.png");
    assert!(read < 80, "{read} chunks read: {said}");
    assert_eq!(draw(&[&diagonal[..], &all].concat(), "diagonal-all.png").0, chunk_files(&path.join("s0")) as u32);
    let (db, text) = psnr("diagonal.png", "diagonal-all.png");
    assert!(db > 70.0, "the chunks a diagonal view sees against the whole image: {text}");
    a_moving_view_reads_through_a_chunk_cache(&path);
    an_orbit_reads_each_chunk_once_through_the_cache(&path);
    // Corrupt every chunk wholly farther than 16 voxels (two bricks) from the box.
    let chunk = [64u32, 64, 32];
    let mut kept = 0;
    for entry in walk(&path.join("s0")) {
        let rel = entry.strip_prefix(path.join("s0")).unwrap().to_string_lossy().into_owned();
        if rel.starts_with('.') {
            continue;
        }
        let zyx: Vec<u32> = rel.split(['/', '.']).map(|s| s.parse().unwrap()).collect();
        let c = [zyx[2], zyx[1], zyx[0]];
        let near = (0..3).all(|a| c[a] * chunk[a] < hi[a] + 16 && (c[a] + 1) * chunk[a] + 16 > lo[a]);
        if near {
            kept += 1;
        } else {
            std::fs::write(&entry, b"not a zstd frame").unwrap();
        }
    }
    assert!(kept > 0 && kept < 24, "{kept} of level 0's 128 chunks kept");
    let hints = VolumeHints { crop: Some(crop), ..Default::default() };
    let store = voxsplat::bricks::BrickStore::load(&path, &hints).unwrap();
    assert_eq!(store.dims, [256; 3]);
    let (rlo, rhi) = store.range;
    let step = (rhi - rlo) / 65535.0;
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                let got = rlo + store.value_at(x as i64, y as i64, z as i64) * (rhi - rlo);
                let w = want[(x + 256 * (y + 256 * z)) as usize];
                assert!((got - w).abs() <= step, "voxel {x} {y} {z}: {got} against zarr-python's {w}");
            }
        }
    }
    // Nothing of the pot's rim far below the box is stored.
    let far = (0..256u32 * 256 * 40).filter(|&i| want[i as usize] > rlo).count();
    assert!(far > 0 && (0..256 * 256 * 40).all(|i: i64| store.value_at(i % 256, i / 256 % 256, i / 65536) == 0.0));
    let e = voxsplat::bricks::BrickStore::load(&path, &level(0)).unwrap_err().to_string();
    assert!(e.contains("chunk"), "{e}");
    // Through the CLI, under a host budget that holds level 1 whole but not level 0: the box's
    // region is read from level 0; without the box, level 1 is drawn.
    let c = format!("{},{},{},{},{},{}", crop[0][0], crop[0][1], crop[0][2], crop[1][0], crop[1][1], crop[1][2]);
    let cropped = voxsplat(&[
        "--host-budget-mib",
        "48",
        "render",
        "--volume",
        path.to_str().unwrap(),
        "--crop",
        &c,
        "--size",
        "48x48",
        "--validation",
        "--out",
        dir.join("crop.png").to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&cropped.stderr);
    assert!(cropped.status.success() && !said.contains("OME-Zarr level"), "{said}");
    let read: u32 = said.split("the store read ").nth(1).and_then(|s| s.split(' ').next()).unwrap().parse().unwrap();
    assert!(read > 0 && read <= kept, "{said}");
    assert!(image::open(dir.join("crop.png")).unwrap().to_rgba8().pixels().any(|p| p[3] > 0), "the box is drawn");
    let whole = voxsplat(&[
        "--host-budget-mib",
        "48",
        "render",
        "--volume",
        path.to_str().unwrap(),
        "--size",
        "48x48",
        "--out",
        dir.join("whole.png").to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&whole.stderr);
    assert!(whole.status.success() && said.contains("OME-Zarr level 1 of 0..2 drawn"), "{said}");
    // A box that holds no voxel of the image is refused.
    let out = dir.join("none.png");
    let far_box = ["--crop", "500,500,500,600,600,600", "--out", out.to_str().unwrap()];
    let e = refused(&[&["render", "--volume", path.to_str().unwrap()][..], &far_box].concat());
    assert!(e.contains("holds no voxel"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Views that turn about the bonsai's z axis (narrow, along x at first), each store read through
/// one `ChunkCache`: each equals the store read without it, and each view reads from the file
/// only the chunks the views before it did not, while the cache holds them.
fn a_moving_view_reads_through_a_chunk_cache(path: &Path) {
    use voxsplat::glam::Vec3;
    use voxsplat::loaders::{ChunkCache, VIEW_MARGIN_PX};
    let view = |deg: f32| {
        let a = deg.to_radians();
        voxsplat::Camera {
            eye: Vec3::new(a.cos(), a.sin(), 0.0) * 300.0,
            target: Vec3::ZERO,
            up: Vec3::Z,
            projection: voxsplat::camera::Projection::Perspective { fov_y_deg: 10.0 },
            near: 1.0,
            far: 1000.0,
            width: 48,
            height: 48,
            window: None,
        }
    };
    let half = Vec3::new(128.0, 128.0, 192.0);
    let load = |camera: voxsplat::Camera, cache: Option<&ChunkCache>| {
        let [lo, hi] = camera.box_in_view(-half, half, VIEW_MARGIN_PX).unwrap();
        let hints = VolumeHints {
            level: Some(0),
            crop: Some([lo.to_array(), hi.to_array()]),
            view: Some(camera),
            chunk_cache: cache.cloned(),
            ..Default::default()
        };
        voxsplat::bricks::BrickStore::load(path, &hints).unwrap()
    };
    let same = |a: &voxsplat::bricks::BrickStore, b: &voxsplat::bricks::BrickStore| {
        a.records == b.records && a.headers == b.headers && a.range == b.range
    };
    // Level 0's chunks are 64 x 64 x 32 samples, 512 KiB as f32: 64 MiB holds all 128.
    let cache = ChunkCache::new(64 << 20).unwrap();
    let mut reads = Vec::new();
    for deg in [0.0, 10.0, 20.0] {
        let before = cache.stats();
        assert!(same(&load(view(deg), Some(&cache)), &load(view(deg), None)), "the view at {deg} degrees");
        let alone = ChunkCache::new(64 << 20).unwrap();
        load(view(deg), Some(&alone));
        let (s, seen) = (cache.stats(), alone.stats().reads);
        reads.push((s.reads - before.reads, seen));
        assert!(s.reads - before.reads <= seen && s.evicted == 0, "{deg} degrees: {s:?}, {seen} chunks seen");
    }
    // The first view reads what it sees; each turn reads some chunks new to it, and not the rest.
    assert!(reads[0].0 == reads[0].1 && reads[0].1 > 0, "{reads:?}");
    assert!(reads[1..].iter().all(|&(new, seen)| new > 0 && new < seen), "{reads:?}");
    // Looking back reads nothing from the file.
    let before = cache.stats();
    load(view(0.0), Some(&cache));
    assert_eq!(cache.stats().reads, before.reads);
    // A cache smaller than a view's chunks (16 of level 0's 8-bit ones) still reads the same
    // stores, and the second view finds held the chunks of the first's that it needs (pinned
    // when its read begins, they are not let go before it reaches them).
    let small = ChunkCache::new(2 << 20).unwrap();
    for deg in [0.0, 10.0] {
        assert!(same(&load(view(deg), Some(&small)), &load(view(deg), None)), "{deg} degrees, a small cache");
    }
    let s = small.stats();
    // Each chunk the two views see is read or found held once (the first cache's counts).
    assert!(s.hits > 0 && s.reads + s.hits == reads[0].1 + reads[1].1 && s.held_bytes <= 2 << 20, "{s:?}");
}

/// `voxsplat lab bricks --orbit N --fov DEG` of an OME-Zarr image: each frame reads its own part;
/// through the chunk cache no chunk is read twice, and without it each frame reads every chunk it
/// uses (those the cache held for it).
fn an_orbit_reads_each_chunk_once_through_the_cache(path: &Path) {
    let orbit = |cache: &str| -> Vec<(u64, u64)> {
        let args = ["lab", "bricks", "--volume", path.to_str().unwrap(), "--orbit", "4", "--fov", "10", "--size", "48"];
        let o = voxsplat(&[&args[..], &["--tf", "bonsai", "--chunk-cache-mib", cache]].concat());
        let said = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(o.status.success(), "{said}{}", String::from_utf8_lossy(&o.stderr));
        let rows: Vec<(u64, u64)> = said
            .lines()
            .filter(|l| l.starts_with("| ") && l.as_bytes()[2].is_ascii_digit())
            .map(|l| {
                let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                (cells[4].parse().unwrap(), cells[5].parse().unwrap())
            })
            .collect();
        assert_eq!(rows.len(), 4, "{said}");
        rows
    };
    let (cached, anew) = (orbit("64"), orbit("0"));
    let read: u64 = cached.iter().map(|r| r.0).sum();
    assert!(read > 0 && read <= 128, "{cached:?}: level 0 has 128 chunks");
    assert!(cached.iter().skip(1).any(|r| r.1 > 0), "{cached:?}");
    for (c, a) in cached.iter().zip(&anew) {
        assert_eq!((c.0 + c.1, 0), *a, "each frame's chunks, read or held: {cached:?} against {anew:?}");
    }
    let bonsai = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/bonsai/bonsai.nii.gz");
    let e = refused(&["lab", "bricks", "--volume", bonsai, "--orbit", "2", "--fov", "10"]);
    assert!(e.contains("--fov orbits an OME-Zarr image"), "{e}");
}

/// Issue 76: an image that stores few of its chunks (zarr-python writes no chunk that is all fill
/// value) decoded every missing chunk of each row it read: one chunk of a 1024^3 array took 18 s.
/// Now only stored chunks are decoded and the rest read as the fill value, here 7, not 0: the
/// values are what zarr-python reads, the streamed store is the dense one's, and `render` reads as
/// many chunks as the image stores.
#[test]
fn an_image_of_few_chunks_reads_only_those_and_the_fill_value_elsewhere() {
    let dir = tmp("sparse");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sparse.zarr");
    let npy_path = dir.join("sparse.npy");
    let script = r#"
import numpy as np, zarr
path, npy = "{}", "{}"
root = zarr.open_group(path, mode="w", zarr_format=2)
a = root.create_array("0", shape=(40, 36, 44), chunks=(8, 8, 8), dtype="u2", fill_value=7)
z, y, x = np.mgrid[0:12, 0:14, 0:10]
a[9:21, 3:17, 30:40] = (((x - 5) ** 2 + (y - 7) ** 2 + (z - 6) ** 2 < 30) * 900 + 20).astype("u2")
a[33:35, 30:32, 0:2] = 3
root.attrs["multiscales"] = [{"version": "0.4", "axes": [{"name": n, "type": "space"} for n in "zyx"],
    "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1, 1, 1]}]}]}]
np.save(npy, a[:])
"#;
    cmd::python(script, &[&path, &npy_path]);
    let stored = chunk_files(&path.join("0"));
    // 2 x 3 x 2 chunks for the ball's box (along z, y, x), 1 for the corner.
    assert_eq!(stored, 13, "chunks zarr-python stored");
    let v = load_volume(&path, &level(0)).unwrap();
    let (_, want) = npy(&npy_path);
    assert!(v.values == want, "the values zarr-python reads");
    assert_eq!(v.values.iter().filter(|&&x| x == 7.0).count(), 40 * 36 * 44 - 12 * 14 * 10 - 8);
    let streamed = voxsplat::bricks::BrickStore::load(&path, &level(0)).unwrap();
    let whole = voxsplat::bricks::BrickStore::build(&v).unwrap();
    assert!(streamed.records == whole.records && streamed.headers == whole.headers);
    assert_eq!(streamed.range, (3.0, 920.0));
    let o = voxsplat(&[
        "render",
        "--size",
        "32x32",
        "--volume",
        path.to_str().unwrap(),
        "--out",
        tmp("sparse.png").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(e.contains(&format!("the store read {stored} chunks")), "{e}");
}

/// The chunk files under `dir`: every file but the metadata.
fn chunk_files(dir: &Path) -> usize {
    let meta = |p: &PathBuf| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.') || n == "zarr.json");
    walk(dir).iter().filter(|p| !meta(p)).count()
}

/// Every file under `dir`.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(walk(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// A series played from one view that sees part of the image (`animate --volume` with --eye and
/// --target) reads each time point's part only, as `render` reads one: the bonsai moved along x
/// over 3 time points, seen along x at 10°, reads 24 of level 0's 128 chunks per time point, and
/// each frame is the frame `render` draws of that time point read whole (sheets: per-splat
/// compositing blends in the order the bricks are stored).
#[test]
fn a_series_seen_in_part_reads_only_that_part_at_each_time_point() {
    let dir = tmp("series-part");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let bonsai = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/bonsai/bonsai.nii.gz");
    write_with_python(&["bonsai-t", bonsai, dir.to_str().unwrap()]);
    let path = dir.join("t.zarr");
    let tf = dir.join("tf.toml");
    cmd::tf_file(&tf, 0.0, 255.0);
    let (p, t) = (path.to_str().unwrap(), tf.to_str().unwrap());
    let view =
        ["--eye", "300,0,0", "--target", "0,0,0", "--fov", "10", "--tf", t, "--size", "48x48", "--accumulate", "sheet"];
    let frames = dir.join("frames");
    let o = voxsplat(
        &[&["animate", "--volume", p, "--validation", "--out-dir", frames.to_str().unwrap()], &view[..]].concat(),
    );
    let said = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{said}");
    assert!(said.contains("the view sees"), "{said}");
    let per_time: f64 = said
        .split("; ")
        .find_map(|s| s.strip_suffix(" OME-Zarr chunks read per time point"))
        .unwrap_or_else(|| panic!("{said}"))
        .parse()
        .unwrap();
    assert!(per_time <= 32.0, "{per_time} of level 0's 128 chunks read per time point: {said}");
    for k in 0..3 {
        let whole = dir.join(format!("whole{k}.png"));
        let crop = ["--time", &k.to_string(), "--crop", "-128,-128,-192,128,128,192", "--out", whole.to_str().unwrap()];
        let o = voxsplat(&[&["render", "--volume", p], &view[..], &crop].concat());
        let text = String::from_utf8_lossy(&o.stderr).into_owned();
        let stored = chunk_files(&path.join("s0").join(k.to_string()));
        assert!(o.status.success() && text.contains(&format!("the store read {stored} chunks")), "{text}");
        let frame = frames.join(format!("frame{k:04}.png"));
        let db = cmd::psnr(&frame, &whole);
        assert!(db > 70.0, "time point {k} seen in part against whole: {db} dB");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
