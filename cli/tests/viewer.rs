//! The embedding path end to end (issue 27 item 4): the windowed viewer (examples/viewer.rs) runs
//! under Xvfb on lavapipe with the validation layer, owning its device and swapchain, for a scripted
//! orbit and transfer-function edit; the frame it reads back from the swapchain image must match
//! `voxsplat render` with the same camera and transfer function within 1/255.
use crate::cmd;
use cmd::{tmp_in, voxsplat};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The viewer beside the `voxsplat` binary (built by `cargo test`; built here when a single test
/// target was asked for).
fn viewer() -> PathBuf {
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_voxsplat"));
    let dir = bin.parent().expect("target dir");
    let path = dir.join("examples").join("viewer");
    if !path.exists() {
        let mut build = Command::new(env!("CARGO"));
        build.args(["build", "-p", "voxsplat-cli", "--example", "viewer"]);
        if dir.ends_with("release") {
            build.arg("--release");
        }
        assert!(build.status().expect("cargo").success(), "building the viewer");
    }
    path
}

fn rgba(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8()
}

#[test]
fn the_viewer_under_xvfb_shows_what_render_draws() {
    let volume = "../../shared/data/stent/stent.nrrd";
    let volume = Path::new(env!("CARGO_MANIFEST_DIR")).join(volume);
    assert!(volume.exists(), "{} (../shared/data beside the clone)", volume.display());
    let volume = volume.to_str().unwrap();
    for (tag, extra) in [("srgb", None), ("unorm", Some("--unorm"))] {
        let (shot, tf, reference) = (
            tmp_in("viewer", &format!("{tag}.png")),
            tmp_in("viewer", &format!("{tag}.toml")),
            tmp_in("viewer", &format!("{tag}-ref.png")),
        );
        let mut run = Command::new("xvfb-run");
        run.args(["-a", "-s", "-screen 0 640x480x24"]).arg(viewer());
        run.args(["--volume", volume, "--tf", "ct", "--size", "192x160", "--frames", "6", "--orbit", "120"]);
        run.args(["--tf-range", "100,1500", "--opacity", "0.8", "--validation"]);
        run.arg("--screenshot").arg(&shot).arg("--save-tf").arg(&tf);
        run.args(extra);
        let out = run.output().expect("xvfb-run (scripts/setup.sh installs xvfb)");
        let log = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{tag}: the viewer failed:\n{log}");
        assert!(String::from_utf8_lossy(&out.stdout).contains("6 frames"), "{tag}: {log}");
        let out = voxsplat(&[
            "render",
            "--volume",
            volume,
            "--tf",
            tf.to_str().unwrap(),
            "--size",
            "192x160",
            "--background",
            "0,0,0",
            "--validation",
            "--out",
            reference.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let (a, b) = (rgba(&shot), rgba(&reference));
        assert_eq!(a.dimensions(), b.dimensions(), "{tag}");
        let worst = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        let lit = b.pixels().filter(|p| p[0] as u32 + p[1] as u32 + p[2] as u32 > 30).count();
        assert!(lit > 1000, "{tag}: the reference shows the stent ({lit} pixels lit)");
        assert!(worst <= 1, "{tag}: the screenshot differs from render by {worst}/255");
        // The edit took: the saved transfer function has the scripted window.
        assert!(std::fs::read_to_string(&tf).unwrap().contains("range = [100.0, 1500.0]"), "{tag}");
    }
}

/// The host's geometry through the volume (issue 46 item 5): the viewer draws a bounding box and a
/// slice plane with depth before each frame, and `render_to` reads both (`HostTarget::with_depth`
/// and `over`). The plane hides the volume behind it and the volume in front of it shows over it;
/// where the viewer drew only its background the frame is the frame without the mesh, exactly.
#[test]
fn the_viewers_mesh_and_the_volume_intermix_by_depth() {
    let volume = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/bonsai/bonsai.nii.gz");
    let shot = |tag: &str, extra: &[&str]| {
        let path = tmp_in("viewer", &format!("mesh-{tag}.png"));
        let mut run = Command::new("xvfb-run");
        run.args(["-a", "-s", "-screen 0 640x480x24"]).arg(viewer()).arg("--volume").arg(&volume);
        run.args(["--tf", "bonsai", "--size", "128x112", "--frames", "2", "--orbit", "0", "--validation"]);
        run.arg("--screenshot").arg(&path).args(extra);
        let out = run.output().expect("xvfb-run");
        assert!(out.status.success(), "{tag}: {}", String::from_utf8_lossy(&out.stderr));
        rgba(&path)
    };
    // Both, the mesh alone (the volume made transparent before the last frame), the volume alone.
    let (both, mesh, volume) =
        (shot("both", &["--mesh"]), shot("mesh", &["--mesh", "--opacity", "0"]), shot("volume", &[]));
    let is = |p: &image::Rgba<u8>, c: [u8; 3]| p[0] == c[0] && p[1] == c[1] && p[2] == c[2];
    let (plane, edge) = ([70, 80, 96], [255, 200, 40]);
    let n = |f: &dyn Fn(usize) -> bool| (0..mesh.pixels().len()).filter(|&i| f(i)).count();
    let px = |img: &image::RgbaImage, i: usize| *img.get_pixel(i as u32 % 128, i as u32 / 128);
    let on_plane = |i: usize| is(&px(&mesh, i), plane);
    let lit = |i: usize| px(&volume, i).0[..3].iter().map(|&v| v as u32).sum::<u32>() > 30;
    assert!(n(&on_plane) > 1000 && n(&|i| is(&px(&mesh, i), edge)) > 300, "the mesh is drawn");
    let hidden = n(&|i| on_plane(i) && lit(i) && is(&px(&both, i), plane));
    let shown = n(&|i| on_plane(i) && lit(i) && !is(&px(&both, i), plane));
    assert!(hidden > 100, "the plane hides the volume behind it ({hidden} pixels)");
    assert!(shown > 100, "the volume in front of the plane shows over it ({shown} pixels)");
    let background = |i: usize| is(&px(&mesh, i), [0, 0, 0]);
    assert!(n(&background) > 5000);
    let worst = (0..mesh.pixels().len())
        .filter(|&i| background(i))
        .map(|i| px(&both, i).0.iter().zip(px(&volume, i).0).map(|(a, b)| a.abs_diff(b)).max().unwrap())
        .max()
        .unwrap();
    assert_eq!(worst, 0, "beside the mesh the frame is the frame without it");
}

/// A session the viewer saves (issue 48 item 6) draws the same frame with `render --session`: the
/// shaded bonsai seen from another eye, its transfer function edited (which keeps the shading) and
/// its mode switched to MIP by key; within one 8-bit step. `--session` takes the place of the flags
/// it holds (given with them, refused), needs the --volume, and a file that is not one is refused.
#[test]
fn a_saved_session_draws_again_with_render() {
    let bonsai = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/bonsai/bonsai.nii.gz");
    let bonsai = bonsai.to_str().unwrap();
    for (tag, keys) in [("composite", ""), ("mip", "m")] {
        let (shot, session, reference) = (
            tmp_in("viewer", &format!("session-{tag}.png")),
            tmp_in("viewer", &format!("session-{tag}.toml")),
            tmp_in("viewer", &format!("session-{tag}-ref.png")),
        );
        let mut run = Command::new("xvfb-run");
        run.args(["-a", "-s", "-screen 0 640x480x24"]).arg(viewer());
        run.args(["--volume", bonsai, "--tf", "bonsai", "--size", "160x128", "--frames", "4", "--eye", "-300,120,260"]);
        run.args(["--tf-range", "20,200", "--keys", keys, "--validation"]);
        run.arg("--screenshot").arg(&shot).arg("--save-session").arg(&session);
        let out = run.output().expect("xvfb-run (scripts/setup.sh installs xvfb)");
        assert!(out.status.success(), "{tag}: the viewer failed:\n{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(&session).unwrap();
        assert!(text.contains(&format!("mode = \"{tag}\"")) && text.contains("range = [20.0, 200.0]"), "{text}");
        assert!(text.contains("[light]"), "{tag}: the edit kept the preset's shading:\n{text}");
        let args = ["render", "--volume", bonsai, "--session", session.to_str().unwrap(), "--size", "160x128"];
        let out = voxsplat(&[&args[..], &["--validation", "--out", reference.to_str().unwrap()]].concat());
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let (a, b) = (rgba(&shot), rgba(&reference));
        let worst = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        let lit = b.pixels().filter(|p| p[0] as u32 + p[1] as u32 + p[2] as u32 > 30).count();
        assert!(lit > 500, "{tag}: the reference shows the bonsai ({lit} pixels lit)");
        assert!(worst <= 1, "{tag}: the screenshot differs from render --session by {worst}/255");
        if tag == "mip" {
            let refused =
                voxsplat(&[&args[..], &["--mode", "composite", "--out", reference.to_str().unwrap()]].concat());
            assert!(String::from_utf8_lossy(&refused.stderr).contains("cannot be used with"));
            let out =
                voxsplat(&["render", "--session", session.to_str().unwrap(), "--out", reference.to_str().unwrap()]);
            assert!(String::from_utf8_lossy(&out.stderr).contains("--volume"));
            std::fs::write(&session, "mode = 3\n").unwrap();
            let out = voxsplat(&[&args[..], &["--out", reference.to_str().unwrap()]].concat());
            assert!(String::from_utf8_lossy(&out.stderr).contains("not a session"));
        }
    }
}

#[test]
fn the_viewer_refuses_what_render_refuses() {
    let out = Command::new("xvfb-run")
        .args(["-a"])
        .arg(viewer())
        .args(["--volume", "/nonexistent.nrrd", "--frames", "1"])
        .output()
        .expect("xvfb-run");
    assert!(!out.status.success());
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(log.contains("viewer:") && log.contains("nonexistent"), "{log}");
}

/// The keyboard's path, scripted: every mode key on a dense scene and on a bricked volume (where
/// the other orders are refused and the viewer falls back to the defaults), validation clean.
#[test]
fn every_key_draws_validation_clean() {
    let stent = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/stent/stent.nrrd");
    for (scene, keys) in [
        // m cycles the modes (the fifth is iso, whose value , and . move), back to composite.
        // b shows the box and slice plane, 9 and 0 move the plane (first said to need b).
        (vec!["--scene", "cube40"], "ocrlp[]rrcoooommmmm.,m9b90cb"),
        (vec!["--volume", stent.to_str().unwrap(), "--tf", "ct"], "lpr[ocmmmmm..m,b0mmb"),
    ] {
        let frames = (keys.len() + 1).to_string();
        let out = Command::new("xvfb-run")
            .args(["-a"])
            .arg(viewer())
            .args(&scene)
            .args(["--size", "96x80", "--frames", &frames, "--keys", keys, "--validation"])
            .output()
            .expect("xvfb-run");
        let log = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{scene:?}: {log}");
        assert_eq!(log.matches(": key ").count(), keys.len(), "{scene:?}: {log}");
        if scene[0] == "--volume" {
            assert!(log.contains("back to the default modes"), "the bricked volume refuses WBTF: {log}");
        }
    }
}

/// A series in the viewer (issue 47 item 4): `t` swaps in the next time point
/// (`Renderer::update_volume`), and the frame after three presses is `render --time 3`'s.
#[test]
fn the_viewer_steps_through_a_series() {
    let dir = tmp_in("viewer", "series");
    std::fs::create_dir_all(&dir).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/write_series.py");
    let out = Command::new("python3").arg(script).arg(&dir).output().expect("python3");
    assert!(out.status.success(), "write_series.py: {}", String::from_utf8_lossy(&out.stderr));
    let volume = dir.join("series.nii.gz");
    let (shot, reference) = (dir.join("shot.png"), dir.join("ref.png"));
    let view = ["--size", "96x80", "--eye", "60,50,80", "--target", "0,0,0"];
    let mut run = Command::new("xvfb-run");
    run.args(["-a", "-s", "-screen 0 640x480x24"]).arg(viewer()).arg("--volume").arg(&volume).args(view);
    run.args(["--frames", "4", "--orbit", "0", "--keys", "ttt", "--validation"]).arg("--screenshot").arg(&shot);
    let out = run.output().expect("xvfb-run");
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the viewer failed:\n{log}");
    assert!(log.contains("frame 2: key t time point 3 of 0..5"), "{log}");
    let mut args = vec!["render", "--volume", volume.to_str().unwrap(), "--time", "3", "--background", "0,0,0"];
    args.extend_from_slice(&view);
    args.extend_from_slice(&["--validation", "--out", reference.to_str().unwrap()]);
    let out = voxsplat(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (a, b) = (rgba(&shot), rgba(&reference));
    assert!(b.pixels().filter(|p| p[0] as u32 + p[1] as u32 + p[2] as u32 > 30).count() > 300, "something drawn");
    let worst = a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
    assert!(worst <= 1, "the screenshot differs from render --time 3 by {worst}/255");
}
