// The fuzz targets' bodies, one function per target (fuzz_targets/NAME.rs calls NAME), included
// by the targets and by tests/fuzz_corpus.rs, which replays the committed corpus in CI.

/// NRRD files read whole (`nrrd_from_bytes`; attached data only).
pub fn nrrd(data: &[u8]) {
    let _ = voxsplat::loaders::nrrd_from_bytes(data, None, "fuzz");
}

/// NIfTI-1 files read whole, plain or gzip (`nifti_from_bytes`).
pub fn nifti(data: &[u8]) {
    let _ = voxsplat::loaders::nifti_from_bytes(data, "fuzz");
}

/// `.npy` arrays (`npy_from_bytes`).
pub fn npy(data: &[u8]) {
    let _ = voxsplat::loaders::npy_from_bytes(data, "fuzz");
}

/// TIFF height grids (`tiff_heights`).
pub fn tiff(data: &[u8]) {
    let _ = voxsplat::loaders::tiff_heights(data, "fuzz");
}

/// Raw samples: the first byte picks the sample type and byte order; the rest is the payload of a
/// 4 x 3 x 2 grid.
pub fn raw(data: &[u8]) {
    use voxsplat::loaders::{raw_from_bytes, DType};
    if let Some((&t, rest)) = data.split_first() {
        let dtype = [DType::U8, DType::U16, DType::I16, DType::F32][t as usize % 4];
        let _ = raw_from_bytes(rest, [4, 3, 2], dtype, t & 4 != 0, [1.0; 3], "fuzz");
    }
}

/// The streamed loader a volume file renders from (`BrickStore::load`: NRRD, NIfTI, gzip inflated
/// as it is read; a series' last time point) and the dense loader, through a file: the first byte picks the file's kind, the
/// rest is the file. The host budget bounds what a header may make them allocate.
pub fn slices(data: &[u8]) {
    let Some((&kind, rest)) = data.split_first() else { return };
    voxsplat::options::set_host_budget(Some(256 << 20));
    let ext = ["nrrd", "nii", "nii.gz"][kind as usize % 3];
    let path = std::env::temp_dir().join(format!("voxsplat-fuzz-slices-{}.{ext}", std::process::id()));
    if std::fs::write(&path, rest).is_ok() {
        let hints = voxsplat::loaders::VolumeHints::default();
        let _ = voxsplat::bricks::BrickStore::load(&path, &hints);
        let _ = voxsplat::loaders::load_volume(&path, &hints);
        // A series (a 4-D NIfTI or NRRD): its last time point, the one furthest into the file,
        // as a series plays it (one range for every time point) and as `render --time` reads it.
        if let Ok(times) = voxsplat::loaders::time_points(&path) {
            let last = voxsplat::loaders::VolumeHints { time: Some(times.max(1) - 1), ..hints };
            let _ = voxsplat::bricks::BrickStore::load_in_range(&path, &last, (0.0, 1.0));
            let _ = voxsplat::loaders::load_volume(&path, &last);
        }
    }
}

/// Terrain height files through `load_heights`: the first byte picks PNG, TIFF or npy, the rest is
/// the file.
pub fn heights(data: &[u8]) {
    let Some((&kind, rest)) = data.split_first() else { return };
    voxsplat::options::set_host_budget(Some(256 << 20));
    let ext = ["png", "tif", "npy"][kind as usize % 3];
    let path = std::env::temp_dir().join(format!("voxsplat-fuzz-heights-{}.{ext}", std::process::id()));
    if std::fs::write(&path, rest).is_ok() {
        let _ = voxsplat::loaders::load_heights(&path);
    }
}

/// Transfer-function files (`render --tf`).
pub fn tf(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(tf) = voxsplat::classify::TransferFunction::from_toml(text) {
            // What parses must evaluate to finite colours.
            for d in [-1.0, 0.0, 0.25, 0.5, 1.0, 2.0] {
                assert!(tf.eval(d).iter().all(|c| c.is_finite()), "{text:?} at {d}");
            }
        }
    }
}

/// Animation files (`animate --file`).
pub fn animation(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(a) = voxsplat::animate::Animation::from_toml(text) {
            // What parses gives a valid camera at every frame.
            for t in [0.0, 0.5, a.frames as f32 * 0.5, a.frames as f32] {
                let _ = a.camera_at(t).validate();
            }
        }
    }
}

/// Rectilinear positions files (`--positions`) for a 4 x 3 x 2 grid.
pub fn positions(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let grid = voxsplat::Grid::centered([4, 3, 2], [1.0; 3]).unwrap();
        if let Ok(coords) = voxsplat::loaders::positions_from_text(text, &grid, "fuzz") {
            let set = voxsplat::SplatSet::from_fn(grid, |_, _, _| Some([1.0; 4])).unwrap();
            let _ = set.with_coordinates(coords);
        }
    }
}

/// Raw files' TOML sidecars (dims, type, byte order, spacing).
pub fn sidecar(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = voxsplat::loaders::sidecar_hints(text, "fuzz");
    }
}

/// Image stacks read as volumes (a multipage TIFF through `load_volume` and the streamed store),
/// through a file.
pub fn stacks(data: &[u8]) {
    voxsplat::options::set_host_budget(Some(256 << 20));
    let path = std::env::temp_dir().join(format!("voxsplat-fuzz-stacks-{}.tif", std::process::id()));
    if std::fs::write(&path, data).is_ok() {
        let hints = voxsplat::loaders::VolumeHints::default();
        let _ = voxsplat::bricks::BrickStore::load(&path, &hints);
        let _ = voxsplat::loaders::load_volume(&path, &hints);
        // A series (a 4-D NIfTI or NRRD): its last time point, the one furthest into the file,
        // as a series plays it (one range for every time point) and as `render --time` reads it.
        if let Ok(times) = voxsplat::loaders::time_points(&path) {
            let last = voxsplat::loaders::VolumeHints { time: Some(times.max(1) - 1), ..hints };
            let _ = voxsplat::bricks::BrickStore::load_in_range(&path, &last, (0.0, 1.0));
            let _ = voxsplat::loaders::load_volume(&path, &last);
        }
    }
}

/// DICOM series: the bytes as the one file of a folder read as a series (`load_volume` and the
/// streamed store).
pub fn dicom(data: &[u8]) {
    voxsplat::options::set_host_budget(Some(256 << 20));
    let dir = std::env::temp_dir().join(format!("voxsplat-fuzz-dicom-{}", std::process::id()));
    if std::fs::create_dir_all(&dir).is_ok() && std::fs::write(dir.join("image.dcm"), data).is_ok() {
        let hints = voxsplat::loaders::VolumeHints::default();
        let _ = voxsplat::bricks::BrickStore::load(&dir, &hints);
        let _ = voxsplat::loaders::load_volume(&dir, &hints);
    }
}

/// Writes an OME-Zarr image packed as the `zarr` target takes it into a fresh folder, and returns
/// the folder: the first byte picks Zarr v2 (OME-NGFF 0.4) or v3 (0.5), the rest is the image's
/// files joined by "\n--\n": the root metadata, level 0's array metadata and its first chunk, then
/// level 1's (the levels' paths are 0 and 1).
pub fn zarr_image(data: &[u8]) -> Option<std::path::PathBuf> {
    let (&kind, mut rest) = data.split_first()?;
    let dir = std::env::temp_dir().join(format!("voxsplat-fuzz-zarr-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let names = if kind & 1 == 1 {
        ["zarr.json", "0/zarr.json", "0/c/0/0/0", "1/zarr.json", "1/c/0/0/0"]
    } else {
        [".zattrs", "0/.zarray", "0/0/0/0", "1/.zarray", "1/0/0/0"]
    };
    for name in names {
        let (part, next) = match rest.windows(4).position(|w| w == b"\n--\n") {
            Some(i) => (&rest[..i], &rest[i + 4..]),
            None => (rest, &[][..]),
        };
        let path = dir.join(name);
        std::fs::create_dir_all(path.parent()?).ok()?;
        std::fs::write(&path, part).ok()?;
        rest = next;
    }
    Some(dir)
}

/// OME-Zarr images (`zarr_image` unpacks them) through the streamed and the dense loaders, each
/// level and channel, and a part of one read as `render --crop` and a narrow view read it, with
/// and without a chunk cache.
pub fn zarr(data: &[u8]) {
    voxsplat::options::set_host_budget(Some(256 << 20));
    if let Some(dir) = zarr_image(data) {
        for level in [None, Some(1)] {
            let hints = voxsplat::loaders::VolumeHints { level, ..Default::default() };
            let _ = voxsplat::bricks::BrickStore::load(&dir, &hints);
            let _ = voxsplat::loaders::load_volume(&dir, &hints);
            let _ = voxsplat::loaders::load_channels(&dir, &hints);
        }
        // A part of it (`VolumeHints::crop`), and of that only the chunks a narrow view may see.
        if let Ok(grid) = voxsplat::Grid::centered([8; 3], [1.0; 3]) {
            let camera = voxsplat::Camera {
                projection: voxsplat::camera::Projection::Perspective { fov_y_deg: 10.0 },
                ..voxsplat::Camera::framing(&grid, 16, 16)
            };
            // Without a chunk cache, then twice through one (the second finds the chunks held).
            let cache = voxsplat::loaders::ChunkCache::new(1 << 20).ok();
            for chunk_cache in [None, cache.clone(), cache] {
                for view in [None, Some(camera)] {
                    let crop = Some([[-2.0, -1.0, -3.0], [3.0, 2.0, 1.0]]);
                    let hints = voxsplat::loaders::VolumeHints {
                        crop,
                        view,
                        chunk_cache: chunk_cache.clone(),
                        ..Default::default()
                    };
                    let _ = voxsplat::bricks::BrickStore::load(&dir, &hints);
                }
            }
        }
    }
}

/// OME-Zarr metadata alone (issue 76: the `zarr` target reads chunks at about 50 a second and
/// stopped short of 1 M): the image as `zarr_image` unpacks it, its multiscales, axes and every
/// level's array metadata opened and checked, and the pyramid asked which level and region a view
/// and a crop need. No chunk is decoded.
pub fn zarr_meta(data: &[u8]) {
    voxsplat::options::set_host_budget(Some(256 << 20));
    let Some(dir) = zarr_image(data) else { return };
    let Ok(image) = voxsplat::loaders::OmeZarr::open(&dir) else { return };
    for level in 0..image.levels.len().min(4) as u32 {
        // Opened to be read slice by slice (each level's array, its chunk grid and codecs).
        let hints = voxsplat::loaders::VolumeHints { level: Some(level), ..Default::default() };
        let _ = voxsplat::loaders::SliceReader::open(&dir, &hints);
        let _ = image.region(level, [[-2.0, -1.0, -3.0], [3.0, 2.0, 1.0]]);
    }
    let _ = image.default_level();
    if let Ok(grid) = voxsplat::Grid::centered([8; 3], [1.0; 3]) {
        let camera = voxsplat::Camera::framing(&grid, 16, 16);
        let _ = image.default_level_within(Some([[-2.0, -1.0, -3.0], [3.0, 2.0, 1.0]]), Some(&camera));
        let level = image.level_for(&camera, 1.0);
        let _ = image.voxel_pixels(&camera, level);
    }
}

/// File names and a pattern (issue 76: names that are not UTF-8 panicked, and a pattern of many
/// `*` hung): the first line is a pattern, each later one (at most 16) names an empty file made in
/// a fresh folder; the pattern's series and the folder as slices are then read.
pub fn names(data: &[u8]) {
    use std::os::unix::ffi::OsStrExt;
    let dir = std::env::temp_dir().join(format!("voxsplat-fuzz-names-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    if std::fs::create_dir_all(&dir).is_err() {
        return;
    }
    let usable = |n: &[u8]| !n.is_empty() && n.len() <= 255 && !n.contains(&b'/') && !n.contains(&0) && n != b"." && n != b"..";
    let mut lines = data.split(|&b| b == b'\n');
    let pattern = lines.next().unwrap_or_default();
    for name in lines.take(16).filter(|n| usable(n)) {
        let _ = std::fs::write(dir.join(std::ffi::OsStr::from_bytes(name)), b"");
    }
    if usable(pattern) {
        let path = dir.join(std::ffi::OsStr::from_bytes(pattern));
        let _ = voxsplat::loaders::series_files(&path);
        let _ = voxsplat::loaders::time_points(&path);
    }
    let _ = voxsplat::loaders::is_stack(&dir);
    let _ = voxsplat::loaders::load_volume(&dir, &Default::default());
    let _ = std::fs::remove_dir_all(&dir);
}
