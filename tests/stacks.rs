//! Image stacks read as volumes (issue 47): multipage TIFFs written by tifffile (the fuzz seeds,
//! fuzz/seeds/make.py) with ImageJ's and OME-TIFF's spacing, folders of numbered PNG slices, the
//! streamed store built from them, and what they refuse.
use crate::bricks::BrickStore;
use crate::loaders::{is_stack, load_volume, SliceReader, VolumeHints};
use std::path::{Path, PathBuf};

fn seed(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/stacks").join(name)
}

/// The seeds' values: (z, y, x) -> ((z * 4 + y) * 5 + x) * 7 % 251 on a 5 x 4 x 3 grid.
fn seed_values() -> Vec<f32> {
    (0..60u32).map(|i| (i * 7 % 251) as f32).collect()
}

/// A folder of its own under the temporary directory.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("voxsplat-stacks-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn tifffile_s_multipage_tiffs_read_as_the_volume_and_spacing_they_hold() {
    let hints = VolumeHints::default();
    let imagej = load_volume(&seed("seed-imagej.tif"), &hints).unwrap();
    assert_eq!(imagej.dims, [5, 4, 3]);
    assert_eq!(imagej.values, seed_values());
    // ImageJ: x and y from the resolution tags (pixels per unit), z from `spacing=`.
    assert_eq!(imagej.spacing, [0.5, 0.25, 2.0]);
    let ome = load_volume(&seed("seed-ome.tif"), &hints).unwrap();
    assert_eq!(ome.dims, [5, 4, 3]);
    assert_eq!(ome.values, seed_values().iter().map(|v| v / 4.0).collect::<Vec<_>>());
    assert_eq!(ome.spacing, [0.3, 0.4, 1.5]);
    assert!(is_stack(&seed("seed-ome.tif")).unwrap(), "several pages: a volume");
    // The streamed store and the store of the whole volume hold the same voxels.
    let streamed = BrickStore::load(&seed("seed-imagej.tif"), &hints).unwrap();
    let whole = BrickStore::build(&imagej).unwrap();
    assert_eq!((streamed.records, streamed.headers), (whole.records, whole.headers));
    // A part of the slices, as sort-last rendering reads a rank's box.
    let mut reader = SliceReader::open(&seed("seed-imagej.tif"), &hints).unwrap().unwrap();
    let mut part = Vec::new();
    reader.read_part(1, 2, [1, 2], [4, 4], &mut part).unwrap();
    let want: Vec<f32> = (1..3u32)
        .flat_map(|z| (2..4u32).flat_map(move |y| (1..4u32).map(move |x| (((z * 4 + y) * 5 + x) * 7 % 251) as f32)))
        .collect();
    assert_eq!(part, want);
}

#[test]
fn a_tiff_that_is_not_one_volume_s_slices_is_refused_by_name() {
    let hints = VolumeHints::default();
    for (file, says) in [
        ("refused-rgb.tif", "single-channel"),
        ("refused-sizes.tif", "page 1 is 5 x 3, page 0 5 x 4"),
        ("refused-channels.tif", "interleave 3 channels"),
    ] {
        let e = load_volume(&seed(file), &hints).unwrap_err().to_string();
        assert!(e.contains(file) && e.contains(says), "{file}: {e}");
        let e = BrickStore::load(&seed(file), &hints).unwrap_err().to_string();
        assert!(e.contains(says), "{file}, streamed: {e}");
    }
    // Sizes and sample types describe raw files: refused for a TIFF, whose header gives its own.
    let raw = VolumeHints { dims: Some([5, 4, 3]), ..Default::default() };
    let e = load_volume(&seed("seed-imagej.tif"), &raw).unwrap_err().to_string();
    assert!(e.contains("describe raw files"), "{e}");
}

#[test]
fn a_folder_of_numbered_slices_reads_in_the_order_of_its_numbers() {
    let dir = folder("numbered");
    let (w, h) = (6u32, 5u32);
    let value = |z: u32, x: u32, y: u32| (z * 60 + y * 7 + x) as u16 * 40;
    // Numbers out of lexicographic order, 16-bit and 8-bit slices, a file that is not a slice.
    for (z, name) in [(0, "cell_2.png"), (1, "cell_9.png"), (2, "cell_10.png")] {
        let img = image::ImageBuffer::from_fn(w, h, |x, y| image::Luma([value(z, x, y)]));
        img.save(dir.join(name)).unwrap();
    }
    std::fs::write(dir.join("notes.txt"), "not a slice").unwrap();
    let v = load_volume(&dir, &VolumeHints::default()).unwrap();
    assert_eq!((v.dims, v.spacing), ([w, h, 3], [1.0; 3]));
    let want: Vec<f32> =
        (0..3).flat_map(|z| (0..h).flat_map(move |y| (0..w).map(move |x| value(z, x, y) as f32))).collect();
    assert_eq!(v.values, want);
    assert!(is_stack(&dir).unwrap());
    let streamed = BrickStore::load(&dir, &VolumeHints::default()).unwrap();
    let whole = BrickStore::build(&v).unwrap();
    assert_eq!((streamed.records, streamed.headers), (whole.records, whole.headers));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_folder_that_is_not_a_stack_is_refused_naming_the_file() {
    let grey = |w: u32, h: u32| image::GrayImage::from_pixel(w, h, image::Luma([9]));
    let refused = |dir: &Path, says: &str| {
        let e = load_volume(dir, &VolumeHints::default()).unwrap_err().to_string();
        assert!(e.contains(says), "{}: {e}", dir.display());
    };
    let empty = folder("empty");
    refused(&empty, "holds none");
    let unnumbered = folder("unnumbered");
    grey(4, 3).save(unnumbered.join("slice1.png")).unwrap();
    grey(4, 3).save(unnumbered.join("cover.png")).unwrap();
    refused(&unnumbered, "cover.png has no number");
    let twice = folder("twice");
    grey(4, 3).save(twice.join("a_1.png")).unwrap();
    grey(4, 3).save(twice.join("b_01.png")).unwrap();
    refused(&twice, "share slice number 1");
    let sizes = folder("sizes");
    grey(4, 3).save(sizes.join("s0.png")).unwrap();
    grey(4, 4).save(sizes.join("s1.png")).unwrap();
    refused(&sizes, "s1.png: 4 x 4");
    let colour = folder("colour");
    image::RgbImage::from_pixel(4, 3, image::Rgb([1, 2, 3])).save(colour.join("c0.png")).unwrap();
    refused(&colour, "single-channel");
    for d in [empty, unnumbered, twice, sizes, colour] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn names_that_are_not_utf8_order_by_their_numbers() {
    // A byte that is not UTF-8 reads as U+FFFD (three bytes) in a lossy name: the number's start
    // was a byte offset inside it, which panicked in `info`, `render` and `slice`.
    use std::os::unix::ffi::OsStrExt;
    let dir = folder("latin1");
    let raw = |z: u32| {
        let mut b = b"scan_\xff".to_vec();
        b.extend_from_slice(z.to_string().as_bytes());
        b.extend_from_slice(b".png");
        std::ffi::OsString::from(std::ffi::OsStr::from_bytes(&b))
    };
    for z in [2u32, 10, 9] {
        image::GrayImage::from_pixel(4, 3, image::Luma([z as u8])).save(dir.join(raw(z))).unwrap();
    }
    let v = load_volume(&dir, &VolumeHints::default()).unwrap();
    assert_eq!(v.dims, [4, 3, 3]);
    assert_eq!([v.values[0], v.values[12], v.values[24]], [2.0, 9.0, 10.0], "ordered by number");
    // The same files as a pattern of time points.
    let pattern = dir.join("scan_*.png");
    let files = crate::loaders::series_files(&pattern).unwrap();
    assert_eq!(files, [2, 9, 10].map(|z| dir.join(raw(z))));
    let _ = std::fs::remove_dir_all(&dir);
}
