//! DICOM series (issue 47) with files no one here wrote: the real series in pydicom's test data
//! (pip-installed by scripts/setup.sh), read as a folder, a file of it or one series of several,
//! beside `dcm2niix`'s NIfTI conversion of the same series; and what a folder that is not one
//! series is refused for.
use crate::cmd;
use cmd::{python, refused, voxsplat};
use std::path::{Path, PathBuf};
use voxsplat::loaders::{load_orientation, load_volume, VolumeHints};

/// pydicom's test files (`dicomdirtests`: small CT, MR and CR series).
fn pydicom_tests() -> PathBuf {
    let out = std::process::Command::new("python3")
        .args(["-c", "import os, pydicom; print(os.path.dirname(pydicom.__file__))"])
        .output()
        .expect("python3 (scripts/setup.sh installs pydicom)");
    assert!(out.status.success(), "pydicom is missing: scripts/setup.sh installs it");
    Path::new(String::from_utf8(out.stdout).unwrap().trim()).join("data/test_files/dicomdirtests")
}

fn tmp(name: &str) -> PathBuf {
    cmd::tmp_in("dicom", name)
}

fn ok(args: &[&str]) -> String {
    let out = voxsplat(args);
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "voxsplat {args:?}: {text}");
    text
}

#[test]
fn a_ct_series_reads_in_slice_order_and_renders_as_dcm2niix_converts_it() {
    let ct = pydicom_tests().join("98892001/CT5N");
    // Its five images, named against their order along the normal (z falls as the names rise).
    let hints = VolumeHints::default();
    let v = load_volume(&ct, &hints).unwrap();
    assert_eq!((v.dims, v.spacing), ([16, 16, 5], [0.488281, 0.488281, 2.5]));
    let o = load_orientation(&ct, &hints).unwrap().expect("a series is placed in patient space");
    assert_eq!(o.code(), "LPS");
    // pydicom's pixel values with the rescale, slice by slice in position order.
    let script = format!(
        "import glob, pydicom\n\
         ds = sorted((pydicom.dcmread(f) for f in glob.glob('{}/*')), key=lambda d: float(d.ImagePositionPatient[2]))\n\
         print(' '.join(str(float(v) * float(d.get('RescaleSlope', 1)) + float(d.get('RescaleIntercept', 0))) for d in ds for v in d.pixel_array.ravel()))",
        ct.display()
    );
    let out = std::process::Command::new("python3").args(["-c", &script]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let want: Vec<f32> =
        String::from_utf8(out.stdout).unwrap().split_whitespace().map(|s| s.parse().unwrap()).collect();
    // The slices run toward superior (z rises with k): pydicom's, sorted by z, in the same order.
    assert_eq!(v.values, want);
    // Streamed a slice at a time into the bricked store, as the whole volume builds it.
    let streamed = voxsplat::bricks::BrickStore::load(&ct, &hints).unwrap();
    let whole = voxsplat::bricks::BrickStore::build(&v).unwrap();
    assert_eq!((streamed.records, streamed.headers), (whole.records, whole.headers));
    // A file of the series names its series; the folder with another file beside it reads the same.
    let file = std::fs::read_dir(&ct).unwrap().next().unwrap().unwrap().path();
    assert_eq!(load_volume(&file, &hints).unwrap().values, v.values);
    // dcm2niix's NIfTI of the same series: the same frame, placed and valued alike.
    let out = tmp("d2n");
    std::fs::create_dir_all(&out).unwrap();
    let conv = std::process::Command::new("dcm2niix")
        .args(["-o", out.to_str().unwrap(), "-f", "ct5n", "-z", "n"])
        .arg(&ct)
        .output()
        .expect("dcm2niix (scripts/setup.sh installs it)");
    assert!(conv.status.success(), "{}", String::from_utf8_lossy(&conv.stderr));
    let nii = out.join("ct5n.nii");
    let (a, b) = (tmp("series.png"), tmp("nifti.png"));
    for (input, png) in [(&ct, &a), (&nii, &b)] {
        ok(&[
            "render",
            "--volume",
            input.to_str().unwrap(),
            "--tf",
            "ct",
            "--size",
            "96x96",
            "--cpu",
            "--out",
            png.to_str().unwrap(),
        ]);
    }
    let psnr = cmd::psnr(&a, &b);
    assert!(psnr > 60.0, "the series against dcm2niix's NIfTI: {psnr} dB");
}

#[test]
fn a_folder_of_several_series_lists_them_and_reads_the_one_picked() {
    let mr = pydicom_tests().join("98892003/MR2");
    let listed = ok(&["info", mr.to_str().unwrap()]);
    assert!(
        listed.contains("series 2:") && listed.contains("FAST LOCALIZER") && listed.contains("3 series"),
        "{listed}"
    );
    let e = refused(&["render", "--volume", mr.to_str().unwrap(), "--out", tmp("mr.png").to_str().unwrap()]);
    assert!(e.contains("holds 3 series") && e.contains("--series"), "{e}");
    // The localizer alone (one image), by its number and by its UID.
    let one = ok(&["info", mr.to_str().unwrap(), "--series", "2"]);
    assert!(one.contains("volume: [16, 16, 1]"), "{one}");
    let uid = "1.3.6.1.4.1.5962.1.1.0.0.0.1196533885.18148.0.481";
    let hints = VolumeHints { series: Some(uid.into()), ..Default::default() };
    assert_eq!(load_volume(&mr, &hints).unwrap().dims, [16, 16, 1]);
    let hints = VolumeHints { series: Some("7".into()), ..Default::default() };
    let e = load_volume(&mr, &hints).unwrap_err().to_string();
    assert!(e.contains("no series 7"), "{e}");
}

#[test]
fn a_folder_that_is_not_one_even_series_is_refused_by_name() {
    let tests = pydicom_tests();
    let hints = VolumeHints::default();
    for (dir, says) in [("98892003/MR700", "mixed orientations"), ("98892001/CT2N", "mixed orientations")] {
        let e = load_volume(&tests.join(dir), &hints).unwrap_err().to_string();
        assert!(e.contains(says), "{dir}: {e}");
    }
    // A copy of the CT series: another file beside it is left alone; a duplicate position and a
    // truncated image are refused naming the files.
    let ct = tests.join("98892001/CT5N");
    let copy = tmp("ct-copy");
    let _ = std::fs::remove_dir_all(&copy);
    std::fs::create_dir_all(&copy).unwrap();
    let files: Vec<PathBuf> = {
        let mut f: Vec<PathBuf> = std::fs::read_dir(&ct).unwrap().map(|e| e.unwrap().path()).collect();
        f.sort();
        f
    };
    for f in &files {
        std::fs::copy(f, copy.join(f.file_name().unwrap())).unwrap();
    }
    std::fs::write(copy.join("README.txt"), "not DICOM").unwrap();
    assert_eq!(load_volume(&copy, &hints).unwrap().dims, [16, 16, 5]);
    std::fs::copy(&files[0], copy.join("again")).unwrap();
    let e = load_volume(&copy, &hints).unwrap_err().to_string();
    assert!(e.contains("duplicate positions"), "{e}");
    std::fs::remove_file(copy.join("again")).unwrap();
    let bytes = std::fs::read(&files[1]).unwrap();
    let cut = copy.join(files[1].file_name().unwrap());
    std::fs::write(&cut, &bytes[..bytes.len() - 100]).unwrap();
    let e = load_volume(&copy, &hints).unwrap_err().to_string();
    assert!(e.contains(cut.to_str().unwrap()), "{e}");
    // --series picks a DICOM series: refused elsewhere.
    let e = refused(&["info", "--series", "0", copy.join("README.txt").to_str().unwrap()]);
    assert!(e.contains("--series"), "{e}");
    let _ = std::fs::remove_dir_all(&copy);
}

#[test]
fn a_tilted_gantry_s_series_is_placed_as_a_sheared_grid() {
    // Written by pydicom: six slices whose positions step 2 mm along the normal and 0.5 mm along
    // the columns (a gantry tilt), under names that do not follow their order.
    let dir = tmp("tilted");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let script = format!(
        "import numpy as np, pydicom\n\
         from pydicom.dataset import Dataset, FileMetaDataset\n\
         from pydicom.uid import ExplicitVRLittleEndian\n\
         for k, name in enumerate(['f', 'c', 'a', 'e', 'b', 'd']):\n\
         \x20   m = FileMetaDataset(); m.MediaStorageSOPClassUID = '1.2.840.10008.5.1.4.1.1.2'\n\
         \x20   m.MediaStorageSOPInstanceUID = '1.2.3.%d' % (k + 10); m.TransferSyntaxUID = ExplicitVRLittleEndian\n\
         \x20   d = Dataset(); d.file_meta = m; d.SOPClassUID = m.MediaStorageSOPClassUID\n\
         \x20   d.SOPInstanceUID = m.MediaStorageSOPInstanceUID; d.Modality = 'CT'; d.SeriesInstanceUID = '1.2.3.1'\n\
         \x20   d.InstanceNumber = 6 - k; d.Rows, d.Columns = 6, 8\n\
         \x20   d.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]; d.ImagePositionPatient = [0, 0.5 * k, 2.0 * k]\n\
         \x20   d.PixelSpacing = [1, 1]; d.SamplesPerPixel = 1; d.PhotometricInterpretation = 'MONOCHROME2'\n\
         \x20   d.BitsAllocated, d.BitsStored, d.HighBit, d.PixelRepresentation = 16, 16, 15, 0\n\
         \x20   d.PixelData = (np.full((6, 8), 100 * k, np.uint16)).tobytes()\n\
         \x20   pydicom.dcmwrite('{}/' + name, d, enforce_file_format=True)\n",
        dir.display()
    );
    let out = std::process::Command::new("python3").args(["-c", &script]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let hints = VolumeHints::default();
    let v = load_volume(&dir, &hints).unwrap();
    assert_eq!(v.dims, [8, 6, 6]);
    // In position order, whatever the names and instance numbers.
    let firsts: Vec<f32> = (0..6).map(|k| v.values[k * 48]).collect();
    assert_eq!(firsts, [0.0, 100.0, 200.0, 300.0, 400.0, 500.0]);
    let o = load_orientation(&dir, &hints).unwrap().unwrap();
    assert!(o.is_sheared(), "a tilted series places a sheared grid");
    // The slice step (0, 0.5, 2) against the columns' direction (0, 1, 0): 75.96 degrees.
    let jk = o.angles()[2];
    assert!((jk - 75.964).abs() < 0.01, "j-k at {jk} degrees");
    let described = ok(&["info", dir.to_str().unwrap()]);
    assert!(described.contains("sheared"), "{described}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Uneven slice gaps (issue 47 item 1): read as they lie when the caller places the slices
/// (`VolumeHints::rectilinear`); otherwise resampled onto even slices at the smallest gap, each
/// linear between the two images around it, and drawn as a bricked store, or, when that would take
/// over four slices per image, refused by the loaders and drawn by `render` as a rectilinear grid
/// at the slices' positions. pydicom's own CT2 (a slice 202.5 mm before three 1.25 mm apart) is the
/// latter; a ball written here at gaps of 2, 2, 4, 2, 3, 2, 1, 2 and 4 mm the former.
#[test]
fn an_uneven_series_is_resampled_or_drawn_at_its_slices_positions() {
    use voxsplat::loaders::{file_positions, slice_offsets};
    let rect = VolumeHints { rectilinear: true, ..Default::default() };
    // Images 37 mm apart in the middle of a series, too far to resample, are drawn as they lie.
    let gappy = tmp("gappy");
    let zs_gappy = [0, 1, 2, 3, 40, 41, 42, 43];
    ball_series(&gappy, &zs_gappy);
    let got = slice_offsets(&gappy, &rect).unwrap().expect("the gaps are uneven");
    assert!(got.iter().zip(zs_gappy).all(|(a, b)| (a - b as f64).abs() < 1e-3), "{got:?}");
    assert_eq!(load_volume(&gappy, &rect).unwrap().dims, [24, 20, 8]);
    let e = load_volume(&gappy, &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("uneven slice gaps") && e.contains("rectilinear"), "{e}");
    let shot = tmp("gappy.png");
    let said = ok(&[
        "render",
        "--volume",
        gappy.to_str().unwrap(),
        "--size",
        "64x64",
        "--validation",
        "--out",
        shot.to_str().unwrap(),
    ]);
    assert!(said.contains("drawn as a rectilinear grid"), "{said}");
    // `slice` cuts it as stored, one plane per image (refused before issue 76); `make-volume`,
    // which writes an evenly spaced NRRD, refuses it for that reason.
    let plane = tmp("gappy-x.png");
    let said = ok(&["slice", gappy.to_str().unwrap(), "--axis", "x", "--out", plane.to_str().unwrap()]);
    assert!(said.contains("[24, 20, 8] grid, 20 x 8 voxels") && said.contains("cut as stored"), "{said}");
    let e = refused(&["make-volume", "--from", gappy.to_str().unwrap(), "--out", tmp("gappy.nrrd").to_str().unwrap()]);
    assert!(e.contains("too uneven to resample") && e.contains("evenly spaced NRRD"), "{e}");
    let _ = std::fs::remove_dir_all(&gappy);
    // A ball written at uneven slice positions.
    let zs = [0, 2, 4, 8, 10, 13, 15, 16, 18, 22];
    let (uneven, even) = (tmp("uneven"), tmp("even"));
    ball_series(&uneven, &zs);
    ball_series(&even, &[0, 2, 4, 6, 8, 10, 12, 14, 16, 18]);
    let grid = voxsplat::Grid::centered([24, 20, 10], [1.0, 1.0, 22.0 / 9.0]).unwrap();
    let [x, y, z] = file_positions(&uneven, &rect, &grid).unwrap().expect("uneven");
    // x and y the grid's own; z the slices' positions, centred as the grid is (22 mm long).
    assert_eq!((x[0], x[23], y[0], y[19]), (-11.5, 11.5, -9.5, 9.5));
    let centred: Vec<f32> = zs.iter().map(|&z| z as f32 - 11.0).collect();
    assert!(z.iter().zip(&centred).all(|(a, b)| (a - b).abs() < 1e-4), "{z:?}");
    assert!(file_positions(&even, &rect, &grid).unwrap().is_none(), "even gaps need no positions");
    // Resampled: 23 slices 1 mm apart, each the linear blend of the images around it, as this
    // test blends the images read as they lie.
    let images = load_volume(&uneven, &rect).unwrap();
    let resampled = load_volume(&uneven, &VolumeHints::default()).unwrap();
    assert_eq!((images.dims, resampled.dims), ([24, 20, 10], [24, 20, 23]));
    assert!((resampled.spacing[2] - 1.0).abs() < 1e-5, "{:?}", resampled.spacing);
    let plane = 24 * 20;
    for p in 0..23 {
        let k = zs.iter().rposition(|&z| z <= p).unwrap().min(zs.len() - 2);
        let t = (p - zs[k]) as f32 / (zs[k + 1] - zs[k]) as f32;
        for i in 0..plane {
            let (lo, hi) = (images.values[k * plane + i], images.values[(k + 1) * plane + i]);
            let want = lo + t * (hi - lo);
            let got = resampled.values[p as usize * plane + i];
            assert!((got - want).abs() <= 1e-3 * want.abs().max(1.0), "slice {p} voxel {i}: {got}, want {want}");
        }
    }
    let store = voxsplat::bricks::BrickStore::load(&uneven, &VolumeHints::default()).unwrap();
    assert_eq!(store.grid().unwrap().dims, [24, 20, 23]);
    // Drawn as a bricked store, near the same ball written on those 23 slices, and another picture
    // than the images spaced evenly at their mean gap.
    let dense = tmp("dense");
    ball_series(&dense, &(0..23).collect::<Vec<_>>());
    let (a, b, c) = (tmp("uneven.png"), tmp("even.png"), tmp("dense.png"));
    // One transfer function over the files' values: each picture classifies them alike.
    let tf = tmp("ball-tf.toml");
    let tf = cmd::tf_file(&tf, 0.0, 1000.0).to_str().unwrap();
    let view = ["--size", "64x64", "--view", "anterior", "--tf", tf, "--validation", "--out"];
    let said = ok(&[&["render", "--volume", uneven.to_str().unwrap()][..], &view, &[a.to_str().unwrap()]].concat());
    assert!(said.contains("resampled to 23 even slices 1.0000 apart from 10 images"), "{said}");
    assert!(said.contains("bricks"), "a bricked store: {said}");
    ok(&[&["render", "--volume", even.to_str().unwrap()][..], &view, &[b.to_str().unwrap()]].concat());
    ok(&[&["render", "--volume", dense.to_str().unwrap()][..], &view, &[c.to_str().unwrap()]].concat());
    let near = cmd::psnr(&a, &c);
    let apart = cmd::psnr(&b, &c);
    eprintln!("resampled against the ball on 23 slices: {near:.1} dB; the images at their mean gap: {apart:.1} dB");
    // Measured over the covered pixels: 20.6 dB against 15.9 dB (over the whole frame, where this
    // bound was 22 dB: 25.0 against 19.3). The ball's edge (a step from 280 to 0 at r = 9) lies between
    // images 4 mm apart, where no series of these images can know it: the blend draws a chord.
    assert!(near > 18.0 && near > apart + 4.0, "resampled {near} dB, evenly spaced {apart} dB");
    let _ = std::fs::remove_dir_all(&dense);
    let _ = std::fs::remove_dir_all(&uneven);
    let _ = std::fs::remove_dir_all(&even);
}

/// Multi-frame images (issue 47 item 1): pydicom's RT Dose grids, 15 frames of 32-bit samples
/// placed by their Grid Frame Offset Vector and scaled by Dose Grid Scaling, little- and
/// big-endian, read voxel for voxel as pydicom reads them.
#[test]
fn rt_dose_grids_read_frame_by_frame_as_pydicom_reads_them() {
    for name in ["rtdose", "rtdose_expb"] {
        let dir = tmp(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join(format!("{name}.dcm"));
        std::fs::copy(pydicom_tests().join(format!("../{name}.dcm")), &file).unwrap();
        let npy = dir.join("want.npy");
        let script = format!(
            "import numpy as np, pydicom\nd = pydicom.dcmread('{}')\n\
             np.save('{}', (d.pixel_array * float(d.DoseGridScaling)).astype(np.float32))",
            file.display(),
            npy.display()
        );
        let out = std::process::Command::new("python3").args(["-c", &script]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let (shape, want) =
            voxsplat::loaders::npy_from_bytes(&std::fs::read(&npy).unwrap(), &npy.display().to_string()).unwrap();
        assert_eq!(shape, [15, 10, 10], "{name}: frames, rows, columns");
        let v = load_volume(&dir, &VolumeHints::default()).unwrap();
        assert_eq!((v.dims, v.spacing), ([10, 10, 15], [10.0, 10.0, 5.0]), "{name}");
        let worst = v.values.iter().zip(&want).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-6, "{name}: {worst} from pydicom's values");
        // The grid starts at Image Position (Patient), its frames 5 mm apart along +z (RAS x, y
        // are LPS's negated).
        let o = load_orientation(&dir, &VolumeHints::default()).unwrap().unwrap();
        let first = o.to_world(voxsplat::glam::Vec3::new(-45.0, -45.0, -35.0));
        assert!((first - voxsplat::glam::Vec3::new(-189.43125, -199.43125, -761.87)).length() < 1e-2, "{first}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// Voxel `(i, j, k)` of a grid loaded with orientation `o` in world (RAS) coordinates.
fn world(o: &voxsplat::orient::Orientation, dims: [u32; 3], [i, j, k]: [u32; 3]) -> voxsplat::glam::DVec3 {
    let i = if o.flip_x() { dims[0] - 1 - i } else { i };
    o.affine().transform_point3(voxsplat::glam::DVec3::new(i as f64, j as f64, k as f64))
}

/// Enhanced multi-frame images (issue 47 item 1): an enhanced MR whose 12 frames are stored out of
/// order on an oblique plane, placed by per-frame Plane Position and shared Plane Orientation,
/// Pixel Measures and Pixel Value Transformation (cli/tests/data/write_enhanced.py), reads voxel
/// for voxel where dcm2niix's NIfTI of it puts each value; frames of several temporal positions are
/// its time points (`--time`), and a Per-frame Functional Groups Sequence of the wrong length is
/// refused.
#[test]
fn an_enhanced_image_is_placed_by_its_functional_groups_as_dcm2niix_places_it() {
    let dir = tmp("enhanced");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("in")).unwrap();
    let write = |file: &Path, extra: &[&str]| {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/write_enhanced.py");
        let out = std::process::Command::new("python3").arg(script).arg(file).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    let series = dir.join("in");
    write(&series.join("e.dcm"), &[]);
    let hints = VolumeHints::default();
    let v = load_volume(&series, &hints).unwrap();
    assert_eq!((v.dims, v.spacing), ([24, 20, 12], [0.9, 0.8, 2.5]));
    let o = load_orientation(&series, &hints).unwrap().unwrap();
    let conv = std::process::Command::new("dcm2niix")
        .args(["-o", dir.to_str().unwrap(), "-f", "e", "-z", "n"])
        .arg(&series)
        .output()
        .expect("dcm2niix (scripts/setup.sh installs it)");
    assert!(conv.status.success(), "{}", String::from_utf8_lossy(&conv.stderr));
    let nii = dir.join("e.nii");
    let n = load_volume(&nii, &hints).unwrap();
    let no = load_orientation(&nii, &hints).unwrap().unwrap();
    assert_ne!(o.code(), no.code(), "dcm2niix stores the rows the other way up");
    let back = no.affine().inverse();
    let [w, h, d] = v.dims;
    for k in 0..d {
        for j in 0..h {
            for i in 0..w {
                let p = back.transform_point3(world(&o, v.dims, [i, j, k]));
                let q = p.round();
                assert!((p - q).length() < 1e-3, "voxel {i} {j} {k} lands between dcm2niix's voxels: {p}");
                let [a, b, c] = [q.x as u32, q.y as u32, q.z as u32];
                let a = if no.flip_x() { n.dims[0] - 1 - a } else { a };
                let at = |dims: [u32; 3], [i, j, k]: [u32; 3]| (i + dims[0] * (j + dims[1] * k)) as usize;
                assert_eq!(v.values[at(v.dims, [i, j, k])], n.values[at(n.dims, [a, b, c])], "voxel {i} {j} {k}");
            }
        }
    }
    // Streamed frame by frame into the bricked store as the whole volume builds it.
    let streamed = voxsplat::bricks::BrickStore::load(&series, &hints).unwrap();
    let whole = voxsplat::bricks::BrickStore::build(&v).unwrap();
    assert_eq!((streamed.records, streamed.headers), (whole.records, whole.headers));
    // The same frame as the NIfTI's under validation. Sheet compositing: per-splat compositing
    // blends overlapping splats in storage order, and dcm2niix stores the rows the other way up.
    let (a, b) = (dir.join("dicom.png"), dir.join("nifti.png"));
    for (input, png) in [(&series, &a), (&nii, &b)] {
        let s = input.to_str().unwrap();
        ok(&[
            "render",
            "--volume",
            s,
            "--accumulate",
            "sheet",
            "--size",
            "64x64",
            "--validation",
            "--out",
            png.to_str().unwrap(),
        ]);
    }
    let compared = ok(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    assert!(compared.contains("psnr:       inf dB"), "{compared}");
    // Frames of three temporal positions, interleaved in the file: three time points, each the
    // volume above plus 100 t stored (200 t rescaled).
    let times = dir.join("times");
    std::fs::create_dir_all(&times).unwrap();
    write(&times.join("e.dcm"), &["--times", "3"]);
    assert_eq!(voxsplat::loaders::time_points(&times).unwrap(), 3);
    for t in 0..3u32 {
        let at = VolumeHints { time: Some(t), ..Default::default() };
        let vt = load_volume(&times, &at).unwrap();
        assert_eq!(vt.dims, v.dims);
        assert!(vt.values.iter().zip(&v.values).all(|(a, b)| *a == b + 200.0 * t as f32), "time point {t}");
        assert_eq!(load_orientation(&times, &at).unwrap().unwrap().affine(), o.affine(), "time point {t}");
    }
    let e = load_volume(&times, &hints).unwrap_err().to_string();
    assert!(e.contains("3 time points"), "{e}");
    let e = load_volume(&times, &VolumeHints { time: Some(3), ..Default::default() }).unwrap_err().to_string();
    assert!(e.contains("time points 0 to 2"), "{e}");
    let e = load_volume(&series, &VolumeHints { time: Some(1), ..Default::default() }).unwrap_err().to_string();
    assert!(e.contains("one volume"), "{e}");
    let listed = ok(&["info", times.to_str().unwrap()]);
    assert!(listed.contains("[24, 20, 12] (columns, rows, images), 3 time points"), "{listed}");
    // animate --volume plays them (issue 76: it was refused, telling the user to run animate).
    let played = dir.join("played");
    let said =
        ok(&["animate", "--volume", times.to_str().unwrap(), "--size", "32x32", "--out-dir", played.to_str().unwrap()]);
    assert!(said.contains("3 time points") && played.join("frame0002.png").exists(), "{said}");
    // Refused: per-frame items that are not one per frame.
    let bad = dir.join("items");
    std::fs::create_dir_all(&bad).unwrap();
    write(&bad.join("e.dcm"), &["--items", "5"]);
    let e = load_volume(&bad, &hints).unwrap_err().to_string();
    assert!(e.contains("holds 5 items for 12 frames") && e.contains("e.dcm"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// JPEG 2000 (issue 47 item 1) through dicom-pixeldata's pure-Rust OpenJPEG port: pydicom's
/// lossless JPEG 2000 copy of its MR image reads value for value as the uncompressed one (and as
/// the RLE copy).
#[test]
fn jpeg_2000_images_read_as_their_uncompressed_originals() {
    let files = pydicom_tests().join("..");
    let read = |name: &str| {
        let dir = tmp(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(files.join(format!("{name}.dcm")), dir.join("a.dcm")).unwrap();
        let v = load_volume(&dir, &VolumeHints::default());
        let _ = std::fs::remove_dir_all(&dir);
        v
    };
    let plain = read("MR_small").unwrap();
    assert_eq!(plain.dims, [64, 64, 1]);
    for name in ["MR_small_jp2klossless", "MR_small_RLE"] {
        assert_eq!(read(name).unwrap().values, plain.values, "{name}");
    }
}

/// JPEG-LS (issue 47 item 1), which dicom-rs decodes only through the C++ CharLS, decoded by the
/// pure-Rust `pure_jpegls`:
/// - pydicom's lossless JPEG-LS copy of its signed MR image reads value for value as the
///   uncompressed one;
/// - an enhanced MR compressed by CharLS (through pydicom and pyjpegls), unsigned 16-bit and signed
///   12-bit, each frame in one or in three fragments, reads as its uncompressed original;
/// - pydicom's near-lossless images (8 and 16 bits) read value for value as CharLS decodes them;
/// - a codestream cut short, one whose size is not Rows x Columns, and a transfer syntax no
///   decoder takes are refused naming the file.
#[test]
fn jpeg_ls_images_read_as_charls_reads_them() {
    let files = pydicom_tests().join("..");
    let dir = tmp("jpegls");
    let _ = std::fs::remove_dir_all(&dir);
    let hints = VolumeHints::default();
    let one = |name: &str, file: &Path| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::copy(file, d.join("a.dcm")).unwrap();
        d
    };
    let plain = load_volume(&one("plain", &files.join("MR_small.dcm")), &hints).unwrap();
    let jls = load_volume(&one("mr", &files.join("MR_small_jpeg_ls_lossless.dcm")), &hints).unwrap();
    assert!(plain.values.iter().any(|v| *v < 0.0) || plain.values.iter().any(|v| *v > 0.0));
    assert_eq!(jls.values, plain.values, "MR_small_jpeg_ls_lossless");

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/write_enhanced.py");
    let write = |name: &str, extra: &[&str]| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        let out = std::process::Command::new("python3").arg(&script).arg(d.join("e.dcm")).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        d
    };
    let original = load_volume(&write("enhanced", &[]), &hints).unwrap();
    for (name, extra) in [
        ("u16-1", &["--jpegls", "1"][..]),
        ("u16-3", &["--jpegls", "3"]),
        ("s12", &["--signed"]),
        ("s12-1", &["--signed", "--jpegls", "1"]),
        ("s12-3", &["--signed", "--jpegls", "3"]),
    ] {
        let v = load_volume(&write(name, extra), &hints).unwrap();
        assert_eq!((v.dims, &v.values), (original.dims, &original.values), "{name}");
    }
    // Streamed into the bricked store as the whole volume builds it.
    let streamed = voxsplat::bricks::BrickStore::load(&dir.join("s12-3"), &hints).unwrap();
    let whole = voxsplat::bricks::BrickStore::build(&original).unwrap();
    assert_eq!((streamed.records, streamed.headers), (whole.records, whole.headers));

    // Near-lossless: placed (pydicom's files carry no plane), then CharLS's values as the truth.
    for bits in ["08", "16"] {
        let d = dir.join(format!("near{bits}"));
        std::fs::create_dir_all(&d).unwrap();
        let (file, npy) = (d.join("a.dcm"), dir.join(format!("near{bits}.npy")));
        python(
            "import numpy as np, pydicom\n\
             d = pydicom.dcmread('{}')\n\
             d.ImagePositionPatient, d.ImageOrientationPatient = [0, 0, 0], [1, 0, 0, 0, 1, 0]\n\
             d.PixelSpacing, d.SliceThickness = [1, 1], 1\n\
             d.save_as('{}')\n\
             np.save('{}', pydicom.dcmread('{}').pixel_array.astype(np.float32))",
            &[&files.join(format!("JPEGLSNearLossless_{bits}.dcm")), &file, &npy, &file],
        );
        let (shape, want) =
            voxsplat::loaders::npy_from_bytes(&std::fs::read(&npy).unwrap(), &npy.display().to_string()).unwrap();
        let v = load_volume(&d, &hints).unwrap();
        assert_eq!(v.dims, [shape[1] as u32, shape[0] as u32, 1], "near-lossless {bits}");
        assert_eq!(v.values, want, "near-lossless {bits}");
    }

    // Refused, naming the file: a codestream cut short, a size that is not Rows x Columns, and a
    // transfer syntax no decoder takes.
    let u16 = dir.join("u16-1/e.dcm");
    let broken = |name: &str, edit: &str| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        python(
            &format!(
                "import pydicom\nfrom pydicom.encaps import encapsulate, generate_frames\n\
                 d = pydicom.dcmread('{{}}')\n\
                 f = list(generate_frames(d.PixelData, number_of_frames=int(d.NumberOfFrames)))\n{edit}\n\
                 d.save_as('{{}}')"
            ),
            &[&u16, &d.join("e.dcm")],
        );
        load_volume(&d, &hints).unwrap_err().to_string()
    };
    let e = broken("cut", "f[4] = f[4][: len(f[4]) // 2]\nd.PixelData = encapsulate(f, has_bot=True)");
    assert!(e.contains("e.dcm") && e.contains("JPEG-LS codestream 5"), "{e}");
    let e = broken("wide", "d.Columns = 25");
    assert!(e.contains("e.dcm") && e.contains("JPEG-LS codestream 1") && e.contains("Columns x Rows = 25 x 20"), "{e}");
    let e = broken("mpeg", "d.file_meta.TransferSyntaxUID = '1.2.840.10008.1.2.4.100'");
    assert!(e.contains("e.dcm") && e.contains("1.2.840.10008.1.2.4.100") && e.contains("not decoded"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Deflated data sets (issue 47 item 1, Deflated Explicit VR Little Endian), which dicom-rs 0.8
/// does not inflate: pydicom's deflated image (placed, as it carries no plane, and written deflated
/// again by pydicom) reads value for value as pydicom reads it; a deflated stream cut short is
/// refused naming the file.
#[test]
fn a_deflated_data_set_reads_as_pydicom_reads_it() {
    let dir = tmp("deflated");
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.join("in");
    std::fs::create_dir_all(&d).unwrap();
    let (file, npy) = (d.join("a.dcm"), dir.join("want.npy"));
    python(
        "import numpy as np, pydicom\n\
         d = pydicom.dcmread('{}')\n\
         assert d.file_meta.TransferSyntaxUID == '1.2.840.10008.1.2.1.99'\n\
         d.ImagePositionPatient, d.ImageOrientationPatient = [0, 0, 0], [1, 0, 0, 0, 1, 0]\n\
         d.PixelSpacing, d.SliceThickness = [0.5, 0.5], 1\n\
         d.save_as('{}')\n\
         e = pydicom.dcmread('{}')\n\
         assert e.file_meta.TransferSyntaxUID == '1.2.840.10008.1.2.1.99'\n\
         np.save('{}', e.pixel_array.astype(np.float32))",
        &[&pydicom_tests().join("../image_dfl.dcm"), &file, &file, &npy],
    );
    let (shape, want) =
        voxsplat::loaders::npy_from_bytes(&std::fs::read(&npy).unwrap(), &npy.display().to_string()).unwrap();
    let v = load_volume(&d, &VolumeHints::default()).unwrap();
    assert_eq!(v.dims, [shape[1] as u32, shape[0] as u32, 1]);
    assert_eq!(v.values, want);
    assert!(want.iter().any(|&x| x != want[0]), "the image is not flat");
    // Its deflated stream cut short.
    let bytes = std::fs::read(&file).unwrap();
    let cut = dir.join("cut");
    std::fs::create_dir_all(&cut).unwrap();
    std::fs::write(cut.join("a.dcm"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    let e = load_volume(&cut, &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("a.dcm") && e.contains("deflated data set"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A Rescale Slope of 0 (pydicom writes it) maps every stored value to the intercept: it drew a
/// constant volume and an empty frame; now refused naming the file and the field.
#[test]
fn a_rescale_slope_of_0_is_refused_by_name() {
    let ct = pydicom_tests().join("98892001/CT5N");
    let copy = tmp("ct-slope0");
    let _ = std::fs::remove_dir_all(&copy);
    std::fs::create_dir_all(&copy).unwrap();
    python(
        "import pydicom, pathlib\nfor f in sorted(pathlib.Path('{}').iterdir()):\n    d = pydicom.dcmread(f)\n    \
         d.RescaleSlope = 0\n    d.save_as(pathlib.Path('{}') / f.name)",
        &[&ct, &copy],
    );
    let e = load_volume(&copy, &VolumeHints::default()).unwrap_err().to_string();
    assert!(e.contains("Rescale Slope is 0") && e.contains(copy.to_str().unwrap()), "{e}");
    let _ = std::fs::remove_dir_all(&copy);
}

/// Issue 76: a localizer filed in the series, or a slice far from the rest (pydicom's own CT2:
/// one slice 202 mm from three 1.25 mm apart), is left out with a note, as a clinical viewer
/// does, and the rest draws as it would alone. Before, CT2 was refused, and a far slice drew
/// a rectilinear grid whose footprints spanned its gap: an empty frame.
#[test]
fn a_localizer_or_a_far_slice_is_left_out_with_a_note() {
    let ct2 = pydicom_tests().join("77654033/CT2");
    let said = ok(&["info", ct2.to_str().unwrap()]);
    assert!(said.contains("volume: [16, 16, 3]"), "{said}");
    assert!(said.contains("note: left out") && said.contains("17106") && said.contains("202.5000 mm"), "{said}");
    let hints = VolumeHints::default();
    assert_eq!(load_volume(&ct2, &hints).unwrap().dims, [16, 16, 3]);
    // A ball's even series, then the same with a slice 5 m away and with a localizer beside it.
    let zs: Vec<i32> = (0..10).map(|k| 2 * k).collect();
    let (even, far, scout) = (tmp("left-even"), tmp("left-far"), tmp("left-scout"));
    ball_series(&even, &zs);
    ball_series(&far, &[&zs[..], &[5000]].concat());
    ball_series(&scout, &zs);
    let script = "import pydicom\n\
                  d = pydicom.dcmread('{}/s0')\n\
                  d.ImageOrientationPatient = [0, 1, 0, 0, 0, -1]\n\
                  d.SOPInstanceUID = d.file_meta.MediaStorageSOPInstanceUID = '1.2.3.99'\n\
                  d.Rows = 24; d.Columns = 20\n\
                  pydicom.dcmwrite('{}/scout', d, enforce_file_format=True)\n";
    python(script, &[&scout, &scout]);
    let want = load_volume(&even, &hints).unwrap();
    for (dir, says) in [(&far, "lies 4982.0000 mm from the next slice"), (&scout, "a localizer")] {
        let left = voxsplat::loaders::left_out(dir, &hints).unwrap();
        assert!(left.len() == 1 && left[0].contains(says), "{}: {left:?}", dir.display());
        let got = load_volume(dir, &hints).unwrap();
        assert_eq!((got.dims, &got.values), (want.dims, &want.values), "{}", dir.display());
    }
    // Drawn, the series with a far slice is the series without it, and says what it left out.
    let tf = tmp("left-tf.toml");
    let tf = cmd::tf_file(&tf, 0.0, 1000.0).to_str().unwrap();
    let (a, b) = (tmp("left-even.png"), tmp("left-far.png"));
    let view = ["--size", "48x48", "--tf", tf, "--validation", "--out"];
    ok(&[&["render", "--volume", even.to_str().unwrap()][..], &view, &[a.to_str().unwrap()]].concat());
    let said = ok(&[&["render", "--volume", far.to_str().unwrap()][..], &view, &[b.to_str().unwrap()]].concat());
    assert!(said.contains("note: left out") && said.contains("s10"), "{said}");
    let psnr = cmd::psnr(&b, &a);
    assert!(psnr > 60.0, "the series with its far slice left out against the series alone: {psnr} dB");
    for d in [&even, &far, &scout] {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// A series of a ball (24 x 20 pixels, 1 mm, centred at z = 11 mm) with its slices at `zs` mm,
/// written by pydicom into `dir`.
fn ball_series(dir: &Path, zs: &[i32]) {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    let script = format!(
        "import numpy as np, pydicom\n\
         from pydicom.dataset import Dataset, FileMetaDataset\n\
         from pydicom.uid import ExplicitVRLittleEndian\n\
         x, y = np.meshgrid(np.arange(24), np.arange(20))\n\
         for k, z in enumerate({zs:?}):\n\
         \x20   m = FileMetaDataset(); m.MediaStorageSOPClassUID = '1.2.840.10008.5.1.4.1.1.2'\n\
         \x20   m.MediaStorageSOPInstanceUID = '1.2.3.%d' % (k + 10); m.TransferSyntaxUID = ExplicitVRLittleEndian\n\
         \x20   d = Dataset(); d.file_meta = m; d.SOPClassUID = m.MediaStorageSOPClassUID\n\
         \x20   d.SOPInstanceUID = m.MediaStorageSOPInstanceUID; d.Modality = 'CT'; d.SeriesInstanceUID = '1.2.3.1'\n\
         \x20   d.InstanceNumber = k + 1; d.Rows, d.Columns = 20, 24\n\
         \x20   d.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]; d.ImagePositionPatient = [0, 0, z]\n\
         \x20   d.PixelSpacing = [1, 1]; d.SamplesPerPixel = 1; d.PhotometricInterpretation = 'MONOCHROME2'\n\
         \x20   d.BitsAllocated, d.BitsStored, d.HighBit, d.PixelRepresentation = 16, 16, 15, 0\n\
         \x20   r = np.sqrt((x - 12) ** 2 + (y - 10) ** 2 + (z - 11) ** 2)\n\
         \x20   d.PixelData = np.where(r < 9, 1000 - 80 * r, 0).astype(np.uint16).tobytes()\n\
         \x20   pydicom.dcmwrite('{}/s%d' % k, d, enforce_file_format=True)\n",
        dir.display()
    );
    let out = std::process::Command::new("python3").args(["-c", &script]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

/// A deflate bomb (issue 76): pydicom's deflated image with 1.1 GiB of zeros deflated after its
/// data set (1 MiB on disk; each 64 MiB flushed whole, so one block serves for all) took 1 GB of memory before its refusal at 1 GiB. Its length is
/// now learnt inflating into nothing: refused naming the file within 512 MiB of address space.
#[test]
fn a_deflate_bomb_is_refused_before_it_is_held() {
    let dir = tmp("bomb");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bomb.dcm");
    python(
        "import struct, zlib\n\
         b = open('{}', 'rb').read()\n\
         start = 144 + struct.unpack('<I', b[140:144])[0]\n\
         data = zlib.decompress(b[start:], -15)\n\
         c = zlib.compressobj(6, zlib.DEFLATED, -15)\n\
         out = [b[:start], c.compress(data) + c.flush(zlib.Z_FULL_FLUSH)]\n\
         zeros = c.compress(bytes(64 << 20)) + c.flush(zlib.Z_FULL_FLUSH)\n\
         out += [zeros] * 18 + [c.flush()]\n\
         open('{}', 'wb').write(b''.join(out))",
        &[&pydicom_tests().join("../image_dfl.dcm"), &file],
    );
    assert!(std::fs::metadata(&file).unwrap().len() < 2 << 20);
    let out = std::process::Command::new("bash")
        .args(["-c", &format!("ulimit -v 524288; exec '{}' info '{}'", env!("CARGO_BIN_EXE_voxsplat"), file.display())])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && e.starts_with("error:"), "{:?}: {e}", out.status);
    assert!(e.contains("bomb.dcm") && e.contains("inflates past 1024 MiB"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 76: one DICOM file cut short hid every series of its folder (`info`, `render` and
/// `slice` refused the folder for it). Now it is left out with a note naming it: the folder's
/// series are listed, and another series (its UID is found in the file's bytes) is described and
/// drawn. Its own series, the file itself, and a folder of nothing else are refused for its fault.
#[test]
fn a_file_that_does_not_read_leaves_its_folders_other_series_readable() {
    let dir = tmp("one-bad");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (series, prefix) in [("98892001/CT5N", "a"), ("77654033/CT2", "b")] {
        for f in std::fs::read_dir(pydicom_tests().join(series)).unwrap() {
            let f = f.unwrap().path();
            std::fs::copy(&f, dir.join(format!("{prefix}{}", f.file_name().unwrap().to_string_lossy()))).unwrap();
        }
    }
    let mut names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    names.sort();
    let cut = names.last().unwrap().clone();
    let bytes = std::fs::read(&cut).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() - 100]).unwrap();
    let d = dir.to_str().unwrap();
    let said = ok(&["info", d]);
    assert!(said.contains("series 0:") && said.contains("series 1:") && said.contains("2 series"), "{said}");
    assert!(
        said.contains("note: 1 DICOM file(s) of the folder left out") && said.contains(cut.to_str().unwrap()),
        "{said}"
    );
    cmd::assert_user_words(&said);
    let said = ok(&["info", d, "--series", "0"]);
    assert!(said.contains("volume: [16, 16, 5]") && said.contains(cut.to_str().unwrap()), "{said}");
    let e = refused(&["info", d, "--series", "1"]);
    assert!(e.contains(cut.to_str().unwrap()), "{e}");
    let png = tmp("one-bad.png");
    let said = ok(&["render", "--volume", d, "--series", "0", "--size", "32x32", "--out", png.to_str().unwrap()]);
    assert!(said.contains("left out") && said.contains(cut.to_str().unwrap()), "{said}");
    assert!(voxsplat::output::read_image(&png).unwrap().pixels.iter().any(|p| p[3] > 0.0));
    // The file itself, and a folder holding it alone.
    let e = refused(&["info", cut.to_str().unwrap()]);
    assert!(e.contains(cut.to_str().unwrap()), "{e}");
    let alone = dir.join("alone");
    std::fs::create_dir_all(&alone).unwrap();
    std::fs::copy(&cut, alone.join("x.dcm")).unwrap();
    let e = refused(&["info", alone.to_str().unwrap()]);
    assert!(e.contains("x.dcm"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
