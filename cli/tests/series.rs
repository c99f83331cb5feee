//! Time series (issue 47, item 4) written by others: a 4-D NIfTI from nibabel, a 4-D NRRD from
//! pynrrd and an OME-Zarr image with a time axis from the ome-zarr package
//! (tests/data/write_series.py). `animate
//! --volume` plays every time point, each frame the one `render --time T` draws from the same
//! view, while the device is sent only what changed; flags that cannot apply are refused.
use crate::cmd;
use cmd::{refused, voxsplat};
use std::path::{Path, PathBuf};

/// The series files, written once per test process (its tests share them).
fn series() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let dir = cmd::tmp_in("series", "files");
        std::fs::create_dir_all(&dir).unwrap();
        let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/write_series.py");
        let out = std::process::Command::new("python3").arg(script).arg(&dir).output().expect("python3");
        assert!(
            out.status.success(),
            "write_series.py (scripts/setup.sh installs nibabel and ome-zarr): {}",
            String::from_utf8_lossy(&out.stderr)
        );
        dir
    })
    .clone()
}

fn ok(args: &[&str]) -> String {
    let o = voxsplat(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "voxsplat {args:?}: {err}");
    String::from_utf8_lossy(&o.stdout).into_owned() + &err
}

fn png(p: &Path) -> image::RgbaImage {
    image::open(p).unwrap().to_rgba8()
}

#[test]
fn animate_plays_each_time_point_as_render_draws_it() {
    let dir = series();
    let view = ["--size", "72x64", "--eye", "60,50,80", "--target", "0,0,0", "--validation"];
    for (name, tag) in [("series.nii.gz", "nii"), ("series.nrrd", "nrrd"), ("series.zarr", "zarr")] {
        let file = dir.join(name);
        let file = file.to_str().unwrap();
        assert!(ok(&["info", file]).contains("6 time points"), "{name}");
        let out = dir.join(format!("anim-{tag}"));
        let mut args = vec!["animate", "--volume", file, "--out-dir", out.to_str().unwrap()];
        args.extend_from_slice(&view);
        let report = ok(&args);
        assert!(report.contains("6 time points (values (0.0, 250.0)"), "{report}");
        // The ball's bricks change each time point, not the blob's.
        assert!(report.contains("bricks changed") && report.contains("written to the device"), "{report}");
        assert!(out.join("anim.gif").exists());
        for t in 0..6 {
            let want = dir.join(format!("{tag}-t{t}.png"));
            let time = t.to_string();
            let mut args = vec!["render", "--volume", file, "--time", &time, "--out", want.to_str().unwrap()];
            args.extend_from_slice(&view);
            ok(&args);
            let got = png(&out.join(format!("frame{t:04}.png")));
            assert!(got.pixels().any(|p| p[3] > 0), "{name} t {t}: something drawn");
            assert!(got == png(&want), "{name} t {t}: the played frame differs from render --time {t}");
        }
    }
    // Time points differ: the ball moved.
    let (a, b) = (png(&dir.join("anim-nii/frame0000.png")), png(&dir.join("anim-nii/frame0005.png")));
    assert!(a != b);
    // The same series as numbered files (vol_t0, vol_t4, .. vol_t20: by number, not by name) plays
    // the same frames.
    let pattern = dir.join("vol_t*.nii.gz");
    let out = dir.join("anim-files");
    let mut args = vec!["animate", "--volume", pattern.to_str().unwrap(), "--out-dir", out.to_str().unwrap()];
    args.extend_from_slice(&view);
    assert!(ok(&args).contains("6 time points"));
    for t in 0..6 {
        let frame = format!("frame{t:04}.png");
        assert!(png(&out.join(&frame)) == png(&dir.join("anim-nii").join(&frame)), "time point {t} of the files");
    }
    let e = refused(&["render", "--volume", pattern.to_str().unwrap(), "--out", out.join("x.png").to_str().unwrap()]);
    assert!(e.contains("holds 6 time points"), "{e}");
}

#[test]
fn flags_that_cannot_apply_to_a_series_are_refused() {
    let dir = series();
    let nii = dir.join("series.nii.gz");
    let nii = nii.to_str().unwrap();
    let out = dir.join("refused");
    let out = out.to_str().unwrap();
    let frame = dir.join("refused.png");
    let frame = frame.to_str().unwrap();
    // One time point of a series needs --time; a 3-D file is no series.
    let e = refused(&["render", "--volume", nii, "--out", frame]);
    assert!(e.contains("holds 6 time points") && e.contains("--time N"), "{e}");
    let e = refused(&["render", "--volume", nii, "--time", "6", "--out", frame]);
    assert!(e.contains("--time 6") && e.contains("0 to 5"), "{e}");
    let bonsai = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/bonsai/bonsai.nii.gz");
    let e = refused(&["animate", "--volume", bonsai, "--out-dir", out]);
    assert!(e.contains("no time axis"), "{e}");
    for (flag, value, why) in [
        ("--time", "2", "animate plays them all"),
        ("--anim", "rotating-box", "time points are the frames"),
        ("--blur", "none", "time points are the frames"),
        // (The visibility order is the lab's: `voxsplat animate` has no --order.)
        ("--order", "btf", "unexpected argument"),
    ] {
        let mut args = vec!["animate", "--volume", nii, "--out-dir", out, flag];
        if !value.is_empty() {
            args.push(value);
        }
        let e = refused(&args);
        assert!(e.contains(flag) && e.contains(why), "{flag}: {e}");
    }
    // An animation sets its own scene and camera.
    for args in [["--tf", "ct"], ["--size", "64x64"], ["--view", "framing"], ["--scene", "sphere"]] {
        let e = refused(&[&["animate", "--out-dir", out][..], &args[..]].concat());
        assert!(e.contains("sets its own scene and camera"), "{args:?}: {e}");
    }
}
