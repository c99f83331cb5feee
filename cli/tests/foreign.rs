//! Issue 76: files as other tools write them, which read as something other than they hold (a
//! spacing of 1, a constant volume) and now read right or are refused naming the file, the field
//! and the value. Each file is written by the tool its users have: pynrrd, pydicom, tifffile.
use crate::cmd;
use std::path::{Path, PathBuf};
use voxsplat::loaders::{load_volume, VolumeHints};

fn tmp(name: &str) -> PathBuf {
    cmd::tmp_in("foreign", name)
}

/// Runs a Python script with `{}` replaced by `args` in turn.
fn python(script: &str, args: &[&Path]) {
    let script = args.iter().fold(script.to_string(), |s, a| s.replacen("{}", &a.display().to_string(), 1));
    let out = std::process::Command::new("python3").args(["-c", &script]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// A 4 x 5 x 6 NRRD of `u8` with the header lines `fields` (written here: pynrrd writes only
/// well-formed spacings).
fn nrrd(name: &str, fields: &str) -> PathBuf {
    let p = tmp(name);
    let header = format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 5 6\nencoding: raw\n{fields}\n\n");
    std::fs::write(&p, [header.as_bytes(), &[7u8; 120][..]].concat()).unwrap();
    p
}

#[test]
fn nrrd_spacing_is_read_from_space_directions_and_malformed_spacings_are_refused() {
    // pynrrd's `space dimension` with directions (no named space): spacing [1, 1, 1] before.
    let sd = tmp("space-dimension.nrrd");
    python(
        "import nrrd, numpy as np\nnrrd.write('{}', np.zeros((4, 5, 6), np.uint8) + 7, \
         {'space dimension': 3, 'space directions': np.diag([2.0, 3.0, 4.0])})",
        &[&sd],
    );
    let text = std::fs::read_to_string(&sd).unwrap_or_default();
    let v = load_volume(&sd, &VolumeHints::default()).unwrap();
    assert_eq!(
        (v.dims, v.spacing),
        ([4, 5, 6], [2.0, 3.0, 4.0]),
        "{}",
        text.lines().take(9).collect::<Vec<_>>().join("; ")
    );
    assert_eq!(
        load_volume(&nrrd("plain.nrrd", "spacings: 2 3 4"), &VolumeHints::default()).unwrap().spacing,
        [2.0, 3.0, 4.0]
    );
    for (name, field, says) in [
        ("units.nrrd", "spacings: 2mm 3mm 4mm", "'2mm' is not a number"),
        ("commas.nrrd", "spacings: 2,3,4", "holds 1 values for 3 axes"),
        ("word.nrrd", "spacings: 2 3 abc", "'abc' is not a number"),
        ("short.nrrd", "spacings: 2 3", "holds 2 values for 3 axes"),
    ] {
        let p = nrrd(name, field);
        let e = load_volume(&p, &VolumeHints::default()).unwrap_err().to_string();
        assert!(e.contains(says) && e.contains(p.to_str().unwrap()), "{name}: {e}");
    }
}
