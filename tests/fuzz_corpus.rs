//! The fuzz corpus replayed through the fuzz targets' own bodies: the seeds (fuzz/seeds/TARGET) and
//! every input a fuzzer kept or crashed on once (fuzz/corpus/TARGET; scripts/fuzz.sh grows and
//! minimises it; both committed) run here on each CI build, without the sanitizer, so a loader that
//! panics on one again fails the suite.
use std::path::Path;
include!("../fuzz/bodies.rs");

/// A fuzz target's body.
type Body = fn(&[u8]);

const TARGETS: &[(&str, Body)] = &[
    ("nrrd", nrrd),
    ("nifti", nifti),
    ("npy", npy),
    ("tiff", tiff),
    ("raw", raw),
    ("slices", slices),
    ("heights", heights),
    ("tf", tf),
    ("animation", animation),
    ("positions", positions),
    ("sidecar", sidecar),
    ("stacks", stacks),
    ("dicom", dicom),
    ("zarr", zarr),
    ("zarr_meta", zarr_meta),
    ("names", names),
];

/// The seeds of `target` (which must exist), then its corpus.
fn inputs(target: &str) -> Vec<std::path::PathBuf> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let list = |dir: &Path| -> Vec<_> {
        let mut files: Vec<_> = std::fs::read_dir(dir).map_or(vec![], |d| d.map(|e| e.unwrap().path()).collect());
        files.sort();
        files
    };
    let seeds = list(&fuzz.join("seeds").join(target));
    assert!(!seeds.is_empty(), "fuzz/seeds/{target} is empty");
    seeds.into_iter().chain(list(&fuzz.join("corpus").join(target))).collect()
}

#[test]
fn every_fuzz_target_replays_its_corpus_without_a_panic() {
    for &(target, body) in TARGETS {
        for f in &inputs(target) {
            let data = std::fs::read(f).unwrap();
            if std::panic::catch_unwind(|| body(&data)).is_err() {
                panic!("fuzz target {target} panicked on {}", f.display());
            }
        }
    }
}

/// The seeds (fuzz/seeds/make.py, written by independent writers) are files the loaders read (a
/// corpus of files every loader refuses would fuzz only the first check), and the `refused-` ones
/// are refused with an error.
#[test]
fn the_volume_seeds_load() {
    use voxsplat::loaders::{nifti_from_bytes, npy_from_bytes, nrrd_from_bytes, tiff_heights};
    for target in ["nrrd", "nifti", "npy", "tiff"] {
        for f in inputs(target).iter().filter(|f| {
            let name = f.file_name().unwrap().to_string_lossy().into_owned();
            name.starts_with("seed-") || name.starts_with("refused-")
        }) {
            let data = std::fs::read(f).unwrap();
            let what = f.display().to_string();
            let ok = match target {
                "nrrd" => nrrd_from_bytes(&data, None, &what).map(|v| v.values.len()),
                "nifti" => nifti_from_bytes(&data, &what).map(|v| v.values.len()),
                "npy" => npy_from_bytes(&data, &what).map(|v| v.1.len()),
                _ => tiff_heights(&data, &what).map(|h| h.heights.len()),
            };
            if what.contains("refused-") {
                assert!(ok.is_err(), "{what} loaded");
                continue;
            }
            assert_eq!(ok.unwrap_or_else(|e| panic!("{what}: {e}")), if target == "tiff" { 12 } else { 24 }, "{what}");
        }
    }
}

/// The streamed loader's seeds (first byte: the file's kind, as `slices` reads it) load as stores.
#[test]
fn the_streamed_seeds_load_as_stores() {
    for f in inputs("slices") {
        let data = std::fs::read(&f).unwrap();
        let ext = ["nrrd", "nii", "nii.gz"][data[0] as usize % 3];
        let path = std::env::temp_dir().join(format!("voxsplat-corpus-{}.{ext}", std::process::id()));
        std::fs::write(&path, &data[1..]).unwrap();
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        // A series' seed: its last time point (of 3).
        let time = name.contains("series").then_some(2);
        let hints = voxsplat::loaders::VolumeHints { time, ..Default::default() };
        let store = voxsplat::bricks::BrickStore::load(&path, &hints);
        if let (Some(_), Ok(s)) = (time, &store) {
            assert_eq!(voxsplat::loaders::time_points(&path).unwrap(), 3, "{name}");
            assert_eq!(s.range, (2.0, 209.0), "{name}: the last time point's values");
        }
        std::fs::remove_file(&path).unwrap();
        match (name.starts_with("seed-"), store) {
            (true, Ok(s)) => assert_eq!(s.dims, [4, 3, 2], "{name}"),
            (true, Err(e)) => panic!("{name}: {e}"),
            (false, Ok(_)) if name.starts_with("refused-") => panic!("{name} loaded"),
            _ => {}
        }
    }
}

/// The OME-Zarr seeds (written by the ome-zarr package: zstd and blosc on Zarr v2, zstd and
/// sharding on v3) unpack into images whose two levels read.
#[test]
fn the_zarr_seeds_load() {
    for f in inputs("zarr").iter().filter(|f| f.file_name().unwrap().to_string_lossy().starts_with("seed-")) {
        let dir = zarr_image(&std::fs::read(f).unwrap()).unwrap();
        for level in [0, 1] {
            let hints = voxsplat::loaders::VolumeHints { level: Some(level), ..Default::default() };
            let v = voxsplat::loaders::load_volume(&dir, &hints).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            assert_eq!(v.dims, [[8, 6, 4], [4, 3, 2]][level as usize], "{}", f.display());
            if level == 0 {
                assert!(v.values.iter().enumerate().all(|(i, &x)| x == (i * 7) as f32), "{}", f.display());
            }
        }
    }
}

/// DICOM files the fuzzer found after the length walk, and what their refusal says:
/// - Samples per Pixel 9217 on a JPEG 2000 image: the decoder sized 4.7 GB by it;
/// - a stray item, then a sequence delimiter declaring 4 GB: dicom-rs read it as a value;
/// - a JPEG 2000 codestream of 4 x 3 pixels in an image of 4 x 2: dicom-rs's adapter wrote past
///   the frame and panicked;
/// - a header other than an item's inside encapsulated data: dicom-rs read a tag as a 3.7 GB length.
const FOUND_REFUSALS: [(&str, &str); 5] = [
    ("found-j2k-samples-per-pixel.dcm", "Samples per Pixel 9217"),
    ("found-delimiter-length.dcm", "delimiter (FFFE,E0DD) declares"),
    ("found-j2k-larger-than-rows.dcm", "4 x 3 pixels, not Columns x Rows = 4 x 2"),
    // A retired (7FA5,0010) of undefined length: dicom-rs reads it as a sequence, not as
    // fragments, and its item's element declares 3.7 GB.
    ("found-encapsulated-stray-header.dcm", "(0000,0000) declares 3758161918 bytes past the file's end"),
    ("found-ob-undefined-length-item.dcm", "(0000,0000) declares 3758161918 bytes past the file's end"),
];

/// The DICOM seeds (pydicom): a CT image, a multi-frame RT Dose grid (and one whose frames are
/// unevenly spaced, resampled evenly), an enhanced image and a
/// JPEG 2000 image read as series of one file; the `refused-` one, and the files the fuzzer found (`found-`: each made dicom-rs size a
/// buffer of gigabytes by a length the walk before it now checks), are refused.
#[test]
fn the_dicom_seeds_load() {
    for f in inputs("dicom") {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        if !["seed-", "refused-", "found-"].iter().any(|p| name.starts_with(p)) {
            continue;
        }
        let dir = std::env::temp_dir().join(format!("voxsplat-corpus-dicom-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(&f, dir.join("image.dcm")).unwrap();
        let v = voxsplat::loaders::load_volume(&dir, &Default::default());
        std::fs::remove_dir_all(&dir).unwrap();
        let found = FOUND_REFUSALS.iter().find(|(f, _)| *f == name);
        match name.as_str() {
            "seed-ct.dcm" => assert_eq!(v.unwrap().dims, [4, 3, 1]),
            "seed-deflated.dcm" => {
                let v = v.unwrap();
                assert_eq!(v.values, (0..12).map(|k| (k * 100 - 1024) as f32).collect::<Vec<_>>());
            }
            "seed-dose.dcm" => {
                let v = v.unwrap();
                assert_eq!(v.dims, [4, 3, 3]);
                // 1000 k scaled by 1e-4, frame by frame.
                assert!(v.values.iter().enumerate().all(|(k, &x)| (x - k as f32 * 0.1).abs() < 1e-5), "{:?}", v.values);
            }
            "seed-dose-uneven.dcm" => {
                // Frames at 0, 1 and 3.5 mm: five even slices 0.875 mm apart, each linear between
                // the frames around it (frame f holds (12 f + i) / 10).
                let v = v.unwrap();
                assert_eq!(v.dims, [4, 3, 5]);
                assert!((v.spacing[2] - 0.875).abs() < 1e-5, "{:?}", v.spacing);
                let at = [0.0, 0.875, 1.3, 1.65, 2.0];
                let want = (0..60).map(|k| (at[k / 12] * 12.0 + (k % 12) as f32) * 0.1);
                assert!(v.values.iter().zip(want).all(|(x, w)| (x - w).abs() < 1e-4), "{:?}", v.values);
            }
            "seed-enhanced.dcm" => {
                // Its frames are stored top first: frame 2 (z = 0) is the grid's first slice.
                let v = v.unwrap();
                assert_eq!(v.dims, [4, 3, 2]);
                let want: Vec<f32> = (12..24).chain(0..12).map(|k| (k * 50 - 1024) as f32).collect();
                assert_eq!(v.values, want);
            }
            "seed-j2k.dcm" => {
                let v = v.unwrap();
                assert_eq!(v.values, (0..12).map(|k| (k * 100 - 1024) as f32).collect::<Vec<_>>());
            }
            "seed-jpegls.dcm" => {
                // The enhanced image's layout, 16 x 16 frames of k * 7, each frame in two fragments.
                let v = v.unwrap();
                assert_eq!(v.dims, [16, 16, 2]);
                let want: Vec<f32> = (256..512).chain(0..256).map(|k| (k * 7 - 1024) as f32).collect();
                assert_eq!(v.values, want);
            }
            // The later finds, each refused by the check that now stops it.
            _ if found.is_some() => {
                let e = v.unwrap_err().to_string();
                assert!(e.contains(found.unwrap().1), "{name}: {e}");
            }
            _ => assert!(v.is_err(), "{name} loaded"),
        }
    }
}
