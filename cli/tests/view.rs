//! `voxsplat view` end to end (issue 48 item 7): under Xvfb on lavapipe with the validation layer,
//! a scripted session opens the bonsai, edits the transfer function with synthetic pointer events
//! (a point dragged, one added), switches to MIP by key and clicks a voxel (the slices' crosshair
//! follows). The window's screenshot
//! shows the panel and the image; the image equals `render --session` of the saved session within
//! one 8-bit step, as does `view --session` of it; the picked value is the file's value at the
//! picked voxel (nibabel reads it). The crop box's handles draw under the volume with their depth,
//! a grip dragged moves its face, and a click in a slice pane moves the crosshair.
mod cmd;
use cmd::{tmp_in, voxsplat};
use std::path::Path;
use std::process::Command;

fn rgba(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8()
}

#[test]
fn a_scripted_session_edits_picks_and_draws_what_render_draws() {
    let volume = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/bonsai/bonsai.nii.gz");
    assert!(volume.exists(), "{} (../shared/data beside the clone)", volume.display());
    let volume = volume.to_str().unwrap();
    let [script, shot, view, session, reference, plain, handles] =
        ["script.txt", "window.png", "view.png", "session.toml", "reference.png", "plain.png", "handles.png"]
            .map(|f| tmp_in("view", f));
    // The crop box's handles (key b) on the composite frame, its z+ grip dragged down, a click in the
    // z slice; then MIP, a pick, the saved frame.
    let text = format!(
        "wait 1\ndrag-tf 1 0.23 0.6\nadd-tf 0.9 0.5\nview {}\nkey b\nstate\nview {}\ngrip z+ 0 20\nwait 1\nstate\n\
         key b\nslice z 0.25 0.25\nkey m\npick 0.5 0.45\nshot {}\nview {}\nsession {}\n",
        plain.display(),
        handles.display(),
        shot.display(),
        view.display(),
        session.display()
    );
    std::fs::write(&script, text).unwrap();
    let mut run = Command::new("xvfb-run");
    run.args(["-a", "-s", "-screen 0 800x600x24", env!("CARGO_BIN_EXE_voxsplat"), "view", "--volume", volume]);
    run.args(["--tf", "bonsai", "--size", "160x480", "--panel", "340", "--validation", "--script"]).arg(&script);
    let out = run.output().expect("xvfb-run (scripts/setup.sh installs xvfb)");
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "view failed:\n{stdout}\n{stderr}");

    // The window: the panel at the left, the view's image at the right, pixel for pixel.
    let (window, image) = (rgba(&shot), rgba(&view));
    assert_eq!(window.dimensions(), (500, 480), "the window is the panel beside --size");
    assert_eq!(image.dimensions(), (160, 480));
    let x0 = window.width() - image.width();
    let same = image.enumerate_pixels().all(|(x, y, p)| window.get_pixel(x0 + x, y).0[..3] == p.0[..3]);
    assert!(same, "the window's right part is the view's image");
    let panel_text = (0..x0).flat_map(|x| (0..window.height()).map(move |y| (x, y)));
    let bright = panel_text.filter(|&(x, y)| window.get_pixel(x, y).0[0] > 150).count();
    assert!(bright > 2000, "the panel shows its labels ({bright} bright pixels)");

    // The edits are in the session: point 1 dragged to 0.23 at opacity 0.6, a point added, MIP.
    let saved = voxsplat_cli::session::Session::load(&session).expect("the saved session");
    assert_eq!(saved.mode, "mip");
    assert_eq!(saved.tf.points.len(), 7, "six points of the preset and the one added: {:?}", saved.tf.points);
    let (x, c) = saved.tf.points[1];
    assert!((x - 0.23).abs() < 0.01 && (c[3] - 0.6).abs() < 0.01, "point 1 at {x}, opacity {}", c[3]);
    let (x, c) = saved.tf.points[5];
    assert!((x - 0.9).abs() < 0.01 && (c[3] - 0.5).abs() < 0.01, "the added point at {x}, opacity {}", c[3]);

    // The image is what render draws from the session.
    let (session, reference_path) = (session.to_str().unwrap(), reference.to_str().unwrap());
    let out = voxsplat(&[
        "render",
        "--volume",
        volume,
        "--session",
        session,
        "--size",
        "160x480",
        "--validation",
        "--out",
        reference_path,
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reference = rgba(Path::new(reference_path));
    let worst = image.pixels().zip(reference.pixels()).map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap());
    let worst = worst.max().unwrap();
    let lit = reference.pixels().filter(|p| p[0] as u32 + p[1] as u32 + p[2] as u32 > 60).count();
    assert!(lit > 3000, "the reference shows the bonsai ({lit} pixels lit)");
    assert!(worst <= 1, "the view differs from render --session by {worst}/255");

    // The window opens the saved session again: the same image.
    let (again, script2) = (tmp_in("view", "again.png"), tmp_in("view", "again.txt"));
    std::fs::write(&script2, format!("wait 1\nview {}\n", again.display())).unwrap();
    let mut run = Command::new("xvfb-run");
    run.args(["-a", "-s", "-screen 0 800x600x24", env!("CARGO_BIN_EXE_voxsplat"), "view", "--volume", volume]);
    run.args(["--session", session, "--size", "160x480", "--validation", "--script"]).arg(&script2);
    let out = run.output().expect("xvfb-run");
    assert!(out.status.success(), "view --session failed:\n{}", String::from_utf8_lossy(&out.stderr));
    let again = rgba(&again);
    let worst = image.pixels().zip(again.pixels()).map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap());
    assert!(worst.max().unwrap() <= 1, "view --session draws the session's frame again");

    // The handles go under the volume with their depth: they show, the volume hides some of
    // them, and no pixel they do not cover changes (the box holds the whole grid: it cuts nothing).
    let states: Vec<&str> = stdout.lines().filter(|l| l.starts_with("state: ")).collect();
    assert_eq!(states.len(), 2, "{stdout}");
    let covered: usize = states[0].rsplit(' ').next().unwrap().parse().unwrap();
    assert!(states[0].contains("crop Some([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])"), "{}", states[0]);
    let (plain, handles) = (rgba(&plain), rgba(&handles));
    let near = |p: &image::Rgba<u8>, c: [u8; 3]| (0..3).all(|k| p[k].abs_diff(c[k]) <= 2);
    let shown = handles.pixels().filter(|p| near(p, [255, 170, 0]) || near(p, [255, 255, 255])).count();
    let changed = plain.pixels().zip(handles.pixels()).filter(|(a, b)| (0..3).any(|k| a[k].abs_diff(b[k]) > 1)).count();
    assert!(shown > 200, "the box's edges and grips show ({shown} pixels)");
    assert!(shown < covered, "the volume hides the handles behind it ({shown} of {covered} pixels shown)");
    assert!(changed <= covered, "{changed} pixels changed, the handles cover {covered}");
    // The z+ grip (the top face's, the one in this narrow view) dragged down: that face moved in,
    // nothing else.
    let moved = states[1].strip_prefix("state: crop Some([[0.0, 0.0, 0.0], [1.0, 1.0, ").expect(states[1]);
    let hi_z: f32 = moved.split(']').next().unwrap().parse().unwrap();
    assert!((0.5..0.99).contains(&hi_z), "{}", states[1]);
    // The click in the z slice, a quarter across and down it: x a quarter of 256, y three.
    let slice = stdout.lines().find(|l| l.starts_with("slice: ")).unwrap_or_else(|| panic!("{stdout}"));
    assert_eq!(slice, "slice: crosshair Some([64, 192, 128])");

    // The pick: the file's value at the voxel, read by nibabel.
    let line = stdout.lines().find(|l| l.starts_with("pick: value")).unwrap_or_else(|| panic!("no pick:\n{stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let value: f64 = words[2].parse().unwrap();
    let at = words.iter().position(|w| *w == "voxel").unwrap();
    let voxel: Vec<u32> = words[at + 1..at + 4].iter().map(|w| w.trim_end_matches(',').parse().unwrap()).collect();
    let script = format!(
        "import nibabel; d = nibabel.load('{volume}').get_fdata(); print(d[{}, {}, {}])",
        voxel[0], voxel[1], voxel[2]
    );
    let out = Command::new("python3").args(["-c", &script]).output().expect("python3 with nibabel");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let file: f64 = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
    let crosshair = format!("crosshair [{}, {}, {}]", voxel[0], voxel[1], voxel[2]);
    assert!(line.contains(&crosshair), "the click moved the slices' crosshair to the picked voxel: {line}");
    assert!((value - file).abs() < 1e-3, "picked {value} at {voxel:?}, the file holds {file}");
}

#[test]
fn view_refuses_what_cannot_apply_before_opening_a_window() {
    let script = tmp_in("view", "bad-script.txt");
    std::fs::write(&script, "wait 1\nwiggle 3 4\n").unwrap();
    for (args, says) in [
        (vec!["view", "--scene", "cube40", "--cpu"], "--cpu does not apply"),
        (vec!["view", "--scene", "cube40", "--session", "s.toml"], "--volume"),
        (vec!["view", "--scene", "cube40", "--panel", "50"], "--panel 50"),
        (vec!["view", "--scene", "cube40", "--drag-ms", "0"], "--drag-ms 0"),
        (vec!["view", "--scene", "cube40", "--script", script.to_str().unwrap()], "script line 2: unknown command"),
    ] {
        let out = voxsplat(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
    }
}
