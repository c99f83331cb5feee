//! `voxsplat render` under mpirun (issue 28; a build with `--features mpi`): 1, 2 and 4 ranks on
//! this machine (oversubscribed) draw the single-process frame, the eye outside the volume and
//! inside it; ranks with empty boxes take part; a rank that cannot read its part makes every rank
//! exit with the same error, not hang; the sheet modes and scenes without a file are refused on
//! every rank.
#![cfg(feature = "mpi")]
use crate::cmd;
use crate::common;
use cmd::voxsplat;
use std::process::{Command, Output};

const STENT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/stent/stent.nrrd");

fn tmp(name: &str) -> std::path::PathBuf {
    cmd::tmp_in("distributed", name)
}

/// `mpirun -n RANKS voxsplat ARGS` (`voxsplat-lab` for a render with research switches: both take
/// the `mpi` feature), killed after two minutes (a hang fails the test).
fn mpirun(ranks: u32, args: &[&str]) -> Output {
    let mut c = Command::new("timeout");
    c.args(["120", "mpirun", "--allow-run-as-root", "--oversubscribe", "-n", &ranks.to_string()]);
    c.arg(cmd::binary_for(args)).args(args);
    c.output().expect("run mpirun (scripts/setup.sh --mpi installs OpenMPI)")
}

/// The largest difference of two EXR frames (`voxsplat compare`).
fn max_abs(a: &std::path::Path, b: &std::path::Path) -> f64 {
    let out = voxsplat(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let line = text.lines().find(|l| l.starts_with("max_abs:")).unwrap_or_else(|| panic!("{text}"));
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

fn ok(out: &Output, what: &str) {
    assert!(out.status.success(), "{what}: {}", String::from_utf8_lossy(&out.stderr));
}

/// `voxsplat ARGS` in one process and under mpirun on `ranks` ranks (with validation), both
/// succeeding: the ranks' run and the largest difference of the two frames.
fn beside_one_process(args: &[&str], ranks: u32, tag: &str) -> (Output, f64) {
    let single = tmp(&format!("{tag}-single.exr"));
    let mut a = args.to_vec();
    a.extend(["--out", single.to_str().unwrap()]);
    ok(&voxsplat(&a), "single process");
    let out = tmp(&format!("{tag}-{ranks}.exr"));
    let mut a = args.to_vec();
    a.extend(["--out", out.to_str().unwrap(), "--validation"]);
    let run = mpirun(ranks, &a);
    ok(&run, &format!("{ranks} ranks"));
    let d = max_abs(&single, &out);
    (run, d)
}

#[test]
fn one_two_and_four_ranks_draw_the_single_process_frame() {
    let views: [(&str, &[&str]); 2] = [("outside", &[]), ("inside", &["--eye", "5,-10,40", "--target", "0,0,-100"])];
    for (view, extra) in views {
        let single = tmp(&format!("{view}-single.exr"));
        // Sort-last composites the ranks' boxes in the k-d tree's order: the single-process frame
        // it equals draws its bricks in that order, without early termination (with it, front to
        // back, a frame draws them in shells around the eye, which interleave the boxes).
        let mut args = vec![
            "render",
            "--volume",
            STENT,
            "--tf",
            "ct",
            "--size",
            "192x192",
            "--validation",
            "--early-termination",
            "0",
        ];
        args.extend_from_slice(extra);
        let mut a = args.clone();
        a.extend(["--out", single.to_str().unwrap()]);
        ok(&voxsplat(&a), "single process");
        for (ranks, scheme) in [(1, "auto"), (2, "auto"), (4, "binary-swap"), (4, "direct-send")] {
            let out = tmp(&format!("{view}-{ranks}-{scheme}.exr"));
            let mut a = args.clone();
            a.extend(["--exchange", scheme, "--out", out.to_str().unwrap()]);
            let run = mpirun(ranks, &a);
            ok(&run, &format!("{view}, {ranks} ranks, {scheme}"));
            let err = String::from_utf8_lossy(&run.stderr);
            assert!(err.contains(&format!("on {ranks} ranks")), "{err}");
            let d = max_abs(&single, &out);
            assert!(d <= 2e-3, "{view}, {ranks} ranks by {scheme}: {d} from the single-process frame");
        }
    }
}

#[test]
fn every_per_splat_mode_draws_the_single_process_frame_on_four_ranks() {
    // The compute tile raster, point sprites, levels of detail, shading (gradients across the
    // boxes' faces read the voxel layer each rank holds around its box), quads back to front (the
    // graphics raster's order), a background laid under the composite at rank 0.
    let modes: [&[&str]; 6] = [
        &["--raster", "compute"],
        &["--raster", "points", "--kernel", "narrow"],
        &["--lod", "auto"],
        &["--shade"],
        &["--raster", "graphics"],
        &["--background", "0.1,0.2,0.3"],
    ];
    for (i, mode) in modes.iter().enumerate() {
        let mut args = vec!["render", "--volume", STENT, "--tf", "ct", "--size", "160x160", "--validation"];
        args.extend_from_slice(mode);
        let (single, out) = (tmp(&format!("mode{i}-single.exr")), tmp(&format!("mode{i}-4.exr")));
        let mut a = args.clone();
        a.extend(["--out", single.to_str().unwrap()]);
        ok(&voxsplat(&a), "single process");
        let mut a = args.clone();
        a.extend(["--out", out.to_str().unwrap()]);
        ok(&mpirun(4, &a), &format!("{mode:?}"));
        let d = max_abs(&single, &out);
        assert!(d <= 2e-3, "{mode:?}: {d} from the single-process frame");
    }
}

#[test]
fn ranks_whose_boxes_are_empty_take_part() {
    // 8 x 8 x 16 voxels (two bricks along z), something only in the lower one: with four ranks,
    // one box holds nothing to draw (only the voxel layer it reads for gradients) and two ranks
    // have no brick at all.
    let raw = tmp("half.raw");
    let data: Vec<u8> = (0..8 * 8 * 16).map(|i| if i / 64 < 8 && (i % 8) > 1 { 200 } else { 0 }).collect();
    std::fs::write(&raw, data).unwrap();
    let args = [
        "render",
        "--volume",
        raw.to_str().unwrap(),
        "--dims",
        "8,8,16",
        "--dtype",
        "u8",
        "--tf",
        "ramp",
        "--size",
        "64x64",
    ];
    let (run, d) = beside_one_process(&args, 4, "half");
    let err = String::from_utf8_lossy(&run.stderr);
    let line = err.lines().find(|l| l.contains("stored voxels on 4 ranks")).unwrap_or_else(|| panic!("{err}"));
    let per_rank = &line[line.find('(').unwrap() + 1..line.find(')').unwrap()];
    assert_eq!(per_rank.split(" + ").filter(|n| *n == "0").count(), 2, "two ranks without a box: {line}");
    assert!(d <= 2e-3);
}

#[test]
fn a_rank_that_cannot_read_its_part_stops_every_rank_with_the_same_error() {
    // The stent's gzip stream cut short: the ranks that read its last slices fail, the others
    // do not; all four report the first failing rank's error and exit.
    let bytes = std::fs::read(STENT).unwrap();
    let cut = tmp("cut.nrrd");
    std::fs::write(&cut, &bytes[..bytes.len() * 3 / 5]).unwrap();
    let out = tmp("cut.png");
    let run =
        mpirun(4, &["render", "--volume", cut.to_str().unwrap(), "--size", "64x64", "--out", out.to_str().unwrap()]);
    assert!(!run.status.success() && run.status.code() != Some(124), "exits, does not hang: {:?}", run.status);
    let err = String::from_utf8_lossy(&run.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(lines.len(), 4, "every rank reports: {err}");
    assert!(lines.iter().all(|l| *l == lines[0]), "the same error: {lines:?}");
    assert!(lines[0].contains("of 4") && lines[0].contains("truncated"), "{}", lines[0]);
    assert!(!out.exists());
}

#[test]
fn what_cannot_be_split_is_refused_on_every_rank() {
    let out = tmp("refused.png");
    let o = out.to_str().unwrap();
    let cases: [(&[&str], &str); 2] = [
        (&["render", "--volume", STENT, "--accumulate", "sheet", "--size", "64x64", "--out", o], "SCALE.md"),
        (&["render", "--scene", "cube40", "--size", "64x64", "--out", o], "--volume file"),
    ];
    for (args, why) in cases {
        let run = mpirun(2, args);
        assert!(!run.status.success() && run.status.code() != Some(124), "{args:?}: {:?}", run.status);
        let err = String::from_utf8_lossy(&run.stderr);
        let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
        assert_eq!(lines.len(), 2, "{args:?}: both ranks report: {err}");
        assert!(lines.iter().all(|l| *l == lines[0] && l.contains(why)), "{args:?}: {lines:?}");
    }
    assert!(!out.exists());
}

#[test]
fn ranks_read_a_left_handed_or_sheared_file_as_one_process_does() {
    // Superior at low k (a negative k column): stored x-reversed on every path, each rank's box too.
    // Longest along x, so the ranks' boxes split x and each reads the mirrored span of its rows.
    let dims = [24, common::DIMS[1], common::DIMS[2]];
    let nz = dims[2] as i64;
    let v = common::samples(dims, |[i, j, k]| [i / 2, j, nz - 1 - k]);
    // And the same with a 30-degree gantry tilt: each rank's store on the sheared grid.
    for (name, tilt) in [("rai", 0.0), ("rai-tilted", 30f64.to_radians().tan())] {
        let affine = glam::DMat4::from_cols(
            glam::DVec4::X,
            glam::DVec4::Y,
            glam::DVec4::new(0.0, tilt, -1.0, 0.0),
            glam::DVec4::new(0.0, 0.0, (nz - 1) as f64, 1.0),
        );
        let file = tmp(&format!("{name}.nii"));
        std::fs::write(&file, common::nifti(dims, &v, Some(affine), None)).unwrap();
        // In the tree's order, as the ranks composite (see above).
        let args = [
            "render",
            "--volume",
            file.to_str().unwrap(),
            "--tf",
            "ramp",
            "--view",
            "anterior",
            "--size",
            "64x64",
            "--early-termination",
            "0",
        ];
        let (run, d) = beside_one_process(&args, 2, name);
        assert!(String::from_utf8_lossy(&run.stderr).contains("on 2 ranks"));
        assert!(d <= 2e-3, "{name}, two ranks: {d} from the single-process frame");
    }
}
