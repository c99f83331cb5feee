//! `voxsplat view` end to end (issue 48 item 7): under Xvfb on lavapipe with the validation layer,
//! a scripted session opens the bonsai, edits the transfer function with synthetic pointer events
//! (a point dragged, one added), switches to MIP by key and clicks a voxel (the slices' crosshair
//! follows). The window's screenshot
//! shows the panel and the image; the image equals `render --session` of the saved session within
//! one 8-bit step, as does `view --session` of it; the picked value is the file's value at the
//! picked voxel (nibabel reads it). The crop box's handles draw under the volume with their depth,
//! a grip dragged moves its face or plane, the session keeps two clip planes and the crop box (so
//! `render --session` cuts the same), and a click in a slice pane moves the crosshair.
use crate::cmd;
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
    let (loaded_tf, saved_tf) = (tmp_in("view", "loaded-tf.toml"), tmp_in("view", "saved-tf.toml"));
    // The crop box's handles (key b) on the composite frame, its z+ grip dragged down; two clip
    // planes (key c), the first pushed away by its grip, the second added after an orbit, a third
    // added and removed (shift+c); a click in the z slice; then MIP, a pick, the handles hidden
    // (key g) and the saved frame.
    let text = format!(
        "wait 1\ndrag-tf 1 0.23 0.6\nadd-tf 0.9 0.5\nview {}\nkey b\nstate\nview {}\ngrip z+ 0 20\nwait 1\nstate\n\
         key c\ngrip plane 0 -15\ndrag 345 470 375 470\nkey c\nkey c\nkey shift+c\nwait 1\nstate\n\
         slice z 0.25 0.25\nkey m\npick 0.5 0.45\nkey g\nshot {}\nview {}\nsession {}\nload-tf {}\ntf {}\n",
        plain.display(),
        handles.display(),
        shot.display(),
        view.display(),
        session.display(),
        loaded_tf.display(),
        saved_tf.display()
    );
    // A transfer function loaded from a file (as the panel's load), saved again (its save).
    let three = "points = [[0.0, [0, 0, 0, 0]], [0.5, [1, 0.5, 0.25, 0.25]], [1.0, [1, 1, 1, 0.75]]]\n";
    std::fs::write(&loaded_tf, three).unwrap();
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
    // The clipping too: two planes facing two views, and the crop box with its top face moved in.
    assert_eq!(saved.clip.len(), 2, "{:?}", saved.clip);
    let [a, b] = [saved.clip[0], saved.clip[1]].map(|p| voxsplat::glam::Vec4::from(p).truncate());
    assert!(a.dot(b) < 0.9999 && (a.length() - 1.0).abs() < 1e-5, "two planes facing two views: {a} {b}");
    let crop = saved.crop.expect("the crop box");
    assert!(crop[0][2] < crop[1][2] && crop[1][2] < crop[1][0], "the crop box's top face moved in: {crop:?}");

    let read_tf =
        |p: &Path| voxsplat::classify::TransferFunction::from_toml(&std::fs::read_to_string(p).unwrap()).unwrap();
    assert_eq!(read_tf(&saved_tf).points, read_tf(&loaded_tf).points, "the loaded transfer function saved again");
    assert_eq!(read_tf(&saved_tf).points.len(), 3);

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
    assert_eq!(states.len(), 3, "{stdout}");
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
    // The first plane pushed away from the eye (beyond the centre), the second through the centre.
    let offsets = states[2].split("plane offsets [").nth(1).and_then(|r| r.split(']').next()).expect(states[2]);
    let offsets: Vec<f32> = offsets.split(", ").map(|o| o.parse().unwrap()).collect();
    assert!(offsets.len() == 2 && offsets[0] > 1.0 && offsets[1].abs() < 1e-3, "{}", states[2]);
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

/// A `n`^3 uint8 NRRD of `values` (x fastest).
fn nrrd(path: &Path, n: usize, values: impl Fn(usize, usize, usize) -> u8) {
    let mut bytes = format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: {n} {n} {n}\nencoding: raw\n\n").into_bytes();
    bytes.extend((0..n * n * n).map(|v| values(v % n, v / n % n, v / (n * n))));
    std::fs::write(path, bytes).unwrap();
}

/// `voxsplat view ARGS --script` of `lines` under Xvfb, with validation; its stdout.
fn view_script(args: &[&str], lines: &str, tag: &str) -> String {
    let script = tmp_in("view", &format!("{tag}.txt"));
    std::fs::write(&script, lines).unwrap();
    let mut run = Command::new("xvfb-run");
    run.args(["-a", "-s", "-screen 0 800x600x24", env!("CARGO_BIN_EXE_voxsplat"), "view"]).args(args);
    run.args(["--validation", "--script"]).arg(&script);
    let out = run.output().expect("xvfb-run");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "view {args:?} failed:\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    stdout
}

/// The largest difference of two images' colour channels, in 8-bit steps.
fn worst(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap()).max().unwrap()
}

#[test]
fn the_panel_hides_a_label_and_a_channel_as_render_leaves_them_out() {
    // Labels 1 and 2 in two halves of a block; the second channel is the label volume.
    let n = 24;
    let (seg, ramp, table, hidden, green) = (
        tmp_in("view", "seg.nrrd"),
        tmp_in("view", "ramp.nrrd"),
        tmp_in("view", "labels.toml"),
        tmp_in("view", "labels-hidden.toml"),
        tmp_in("view", "green.toml"),
    );
    // The first channel faint, the second (the labels) green.
    let faint = tmp_in("view", "faint.toml");
    std::fs::write(&faint, "points = [[0.0, [0, 0, 0, 0]], [1.0, [1, 0.5, 0.5, 0.02]]]\nrange = [0.0, 255.0]\n")
        .unwrap();
    std::fs::write(
        &green,
        "points = [[0.0, [0, 0, 0, 0]], [0.4, [0, 1, 0, 0.8]], [1.0, [0, 1, 0, 0.8]]]\nrange = [0.0, 2.0]\n",
    )
    .unwrap();
    nrrd(&seg, n, |i, j, k| match (i, j, k) {
        _ if !((4..20).contains(&j) && (4..20).contains(&k)) => 0,
        _ if (4..12).contains(&i) => 1,
        _ if (12..20).contains(&i) => 2,
        _ => 0,
    });
    nrrd(&ramp, n, |i, j, k| ((i + 2 * j + 3 * k) * 255 / (6 * n)) as u8);
    let label = |v: u32, rgb: &str, shown: bool| {
        format!("[[label]]\nvalue = {v}\ncolor = [{rgb}]\nopacity = 0.8\nvisible = {shown}\n\n")
    };
    std::fs::write(&table, label(1, "1, 0, 0", true) + &label(2, "0, 0, 1", true)).unwrap();
    std::fs::write(&hidden, label(1, "1, 0, 0", true) + &label(2, "0, 0, 1", false)).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let size = ["--size", "120x480"];
    let shots =
        ["labels-both.png", "labels-one.png", "channels-both.png", "channels-one.png"].map(|f| tmp_in("view", f));
    let labels = [vec!["--labels".to_string(), s(&seg), "--label-table".into(), s(&table)]];
    let args: Vec<&str> = labels[0].iter().map(String::as_str).chain(size).collect();
    view_script(
        &args,
        &format!("wait 1\nview {}\nlabel 2 off\nview {}\n", shots[0].display(), shots[1].display()),
        "labels",
    );
    let channels = [vec![
        "--volume".to_string(),
        s(&ramp),
        "--tf".into(),
        s(&faint),
        "--channel".into(),
        s(&seg),
        "--channel-tf".into(),
        s(&green),
    ]];
    let args: Vec<&str> = channels[0].iter().map(String::as_str).chain(size).collect();
    view_script(
        &args,
        &format!("wait 1\nview {}\nchannel 1 off\nview {}\n", shots[2].display(), shots[3].display()),
        "channels",
    );

    // What render draws: the table with label 2 hidden; the first channel alone.
    let render = |args: &[&str], out: &Path| {
        let mut all = vec!["render"];
        all.extend(args);
        all.extend(["--size", "120x480", "--background", "0,0,0,1", "--validation", "--out", out.to_str().unwrap()]);
        let out = voxsplat(&all);
        assert!(out.status.success(), "{all:?}: {}", String::from_utf8_lossy(&out.stderr));
    };
    let refs = ["ref-labels.png", "ref-channel.png"].map(|f| tmp_in("view", f));
    render(&["--labels", &s(&seg), "--label-table", &s(&hidden)], &refs[0]);
    render(&["--volume", &s(&ramp), "--tf", &s(&faint)], &refs[1]);
    let [both, one, ch_both, ch_one] = shots.map(|p| rgba(&p));
    let (ref_labels, ref_channel) = (rgba(&refs[0]), rgba(&refs[1]));
    let blue = |img: &image::RgbaImage| img.pixels().filter(|p| p[2] > 60 && p[0] < 30).count();
    assert!(blue(&both) > 300, "label 2 (blue) is drawn at first ({} pixels)", blue(&both));
    assert_eq!(blue(&one), 0, "hidden, label 2 draws nothing");
    assert!(
        worst(&one, &ref_labels) <= 1,
        "the view without label 2 differs from render by {}",
        worst(&one, &ref_labels)
    );
    let greener = |img: &image::RgbaImage| img.pixels().filter(|p| p[1] as i32 > p[0] as i32 + 40).count();
    assert!(greener(&ch_both) > 300, "the second channel draws green ({} pixels)", greener(&ch_both));
    assert_eq!(greener(&ch_one), 0, "without it, no green");
    let w = worst(&ch_one, &ref_channel);
    assert!(w <= 1, "the view without channel 1 differs from render of the first channel alone by {w}/255");
}
