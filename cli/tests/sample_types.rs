//! Sample types others write (issue 47): NIfTI from nibabel and NRRD from pynrrd in signed 8-bit,
//! signed 32-bit and 64-bit float samples (nibabel's default for float arrays) read value for
//! value, whole and streamed into the bricked store; a double past f32's range is refused.
use crate::cmd;
use std::path::Path;
use voxsplat::loaders::{load_volume, VolumeHints};

/// Writes `name` with `writer` (Python: `a` is the array, `path` the file) and returns the values
/// numpy holds, x fastest.
fn write(dir: &Path, name: &str, dtype: &str, writer: &str) -> Vec<f32> {
    let path = dir.join(name);
    let script = format!(
        "import numpy as np, nibabel, nrrd\n\
         z, y, x = np.mgrid[0:5, 0:6, 0:7]\n\
         a = ((x * 37 + y * 11 - z * 29) * {{'int8': 1, 'int32': 99991, 'float64': 0.123456789}}['{dtype}'] - \
         {{'int8': 60, 'int32': 0, 'float64': 0}}['{dtype}']).astype('{dtype}').transpose(2, 1, 0)\n\
         path = '{}'\n{writer}\n\
         print(' '.join(repr(float(v)) for v in a.transpose(2, 1, 0).ravel()))",
        path.display()
    );
    let out = std::process::Command::new("python3").args(["-c", &script]).output().unwrap();
    assert!(out.status.success(), "nibabel and pynrrd (scripts/setup.sh): {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap().split_whitespace().map(|s| s.parse::<f64>().unwrap() as f32).collect()
}

#[test]
fn signed_and_double_samples_read_as_numpy_holds_them() {
    let dir = cmd::tmp_in("sample_types", "files");
    std::fs::create_dir_all(&dir).unwrap();
    let nifti = "nibabel.Nifti1Image(a, np.eye(4)).to_filename(path)";
    let nrrd = "nrrd.write(path, a)";
    for dtype in ["int8", "int32", "float64"] {
        for (ext, writer) in [("nii.gz", nifti), ("nii", nifti), ("nrrd", nrrd)] {
            let name = format!("{dtype}.{ext}");
            let want = write(&dir, &name, dtype, writer);
            let path = dir.join(&name);
            let v = load_volume(&path, &VolumeHints::default()).unwrap();
            assert_eq!(v.dims, [7, 6, 5], "{name}");
            assert_eq!(v.values, want, "{name}");
            assert!(want.iter().any(|&x| x < 0.0), "{name} holds negative values");
            let streamed = voxsplat::bricks::BrickStore::load(&path, &VolumeHints::default()).unwrap();
            let whole = voxsplat::bricks::BrickStore::build(&v).unwrap();
            assert_eq!((streamed.records, streamed.headers), (whole.records, whole.headers), "{name}");
        }
    }
    // A double f32 cannot hold: refused, naming the sample, not read as infinity.
    write(&dir, "huge.nii", "float64", "a[1, 2, 3] = 1e300\nnibabel.Nifti1Image(a, np.eye(4)).to_filename(path)");
    let e = load_volume(&dir.join("huge.nii"), &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("inf") && e.contains("finite"), "{e}");
    let e = voxsplat::bricks::BrickStore::load(&dir.join("huge.nii"), &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("inf") && e.contains("finite"), "streamed: {e}");
    let _ = std::fs::remove_dir_all(&dir);
}
