//! Volumes over time (issue 47, item 4): a time point swapped into a bricked scene in place
//! (`BrickStore::patch`, `Renderer::update_volume`) draws what the same store set afresh draws,
//! on the device and on the CPU mirrors, while the device rewrites only the bricks that changed;
//! 4-D NIfTI files read one time point at a time. Validation on: any message fails.
use super::common;
use crate::bricks::{BrickScene, BrickStore, BRICK};
use crate::classify::Shading;
use crate::volume::ScalarVolume;
use crate::{Camera, Error, Mode, RenderOptions};
use common::{assert_clean, assert_mirrors, blob, blob_tf as tf};

const DIMS: [u32; 3] = [61, 53, 47];

/// Time point `t` of a series: the blob, and a bright ball that moves 3 voxels along x per time
/// point (from t = 4 on it also loses its middle, so some bricks lose records or go empty).
fn at(t: u32) -> ScalarVolume {
    ball(t, blob(DIMS))
}

/// `at` on a larger grid (the ball as large), for a store that streams through a budget that
/// holds a frame.
fn large_at(t: u32) -> ScalarVolume {
    ball(t, blob(LARGE))
}

const LARGE: [u32; 3] = [120, 110, 100];

/// The ball of time point `t` over `v`.
fn ball(t: u32, mut v: ScalarVolume) -> ScalarVolume {
    let c = [12.0 + 3.0 * t as f32, 40.0, 30.0];
    let dims = v.dims;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let d = [i as f32 - c[0], j as f32 - c[1], k as f32 - c[2]];
                let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if r < 7.0 && !(t >= 4 && r < 3.0) {
                    v.values[(i + dims[0] * (j + dims[1] * k)) as usize] = 60.0 + 30.0 * (r / 7.0);
                }
            }
        }
    }
    v
}

/// `vol` as a store normalised by `range`.
fn store_in(vol: &ScalarVolume, range: (f32, f32)) -> BrickStore {
    let plane = (vol.dims[0] * vol.dims[1]) as usize;
    BrickStore::from_region(vol.dims, vol.spacing, range, [[0; 3], vol.dims], |z0, n, out| {
        out.clear();
        out.extend_from_slice(&vol.values[z0 as usize * plane..(z0 + n) as usize * plane]);
        Ok(())
    })
    .unwrap()
}

/// The series' range: every time point's values.
fn range(times: &[ScalarVolume]) -> (f32, f32) {
    let all = times.iter().flat_map(|v| v.values.iter().copied());
    all.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// Bricks where `a` and `b` differ in some voxel (counted from the dense volumes).
fn bricks_that_differ(a: &ScalarVolume, b: &ScalarVolume) -> usize {
    let nb = a.dims.map(|d| d.div_ceil(BRICK));
    let mut differ = vec![false; (nb[0] * nb[1] * nb[2]) as usize];
    for (n, (x, y)) in a.values.iter().zip(&b.values).enumerate() {
        if x != y {
            let n = n as u32;
            let (i, j, k) = (n % a.dims[0], n / a.dims[0] % a.dims[1], n / (a.dims[0] * a.dims[1]));
            differ[(i / BRICK + nb[0] * (j / BRICK + nb[1] * (k / BRICK))) as usize] = true;
        }
    }
    differ.iter().filter(|&&d| d).count()
}

#[test]
fn a_patched_store_reads_back_every_value_and_keeps_what_did_not_change() {
    let times: Vec<ScalarVolume> = (0..12).map(at).collect();
    let range = range(&times);
    let mut store = store_in(&times[0], range);
    let mut compacted = false;
    for t in 1..times.len() {
        let next = store_in(&times[t], range);
        let before = store.clone();
        let patch = store.patch(next.clone()).unwrap();
        assert_eq!(patch.changed, bricks_that_differ(&times[t - 1], &times[t]), "t {t}: bricks changed");
        assert!(patch.changed > 0 && patch.changed < store.headers.len() / 2, "t {t}: {} changed", patch.changed);
        for k in 0..DIMS[2] as i64 {
            for j in 0..DIMS[1] as i64 {
                for i in 0..DIMS[0] as i64 {
                    assert_eq!(store.value_at(i, j, k), next.value_at(i, j, k), "t {t}: voxel {i},{j},{k}");
                }
            }
        }
        assert_eq!(store.masks, next.masks);
        assert_eq!(store.index, next.index);
        for (h, n) in store.headers.iter().zip(&next.headers) {
            assert_eq!((h.brick, h.count, h.range), (n.brick, n.count, n.range), "t {t}: headers");
        }
        // A brick that did not change keeps its records where they were.
        let written: Vec<u32> = patch.records.iter().map(|r| r[0]).collect();
        if !patch.compacted {
            for h in &store.headers {
                let old = before.header_of(h.coords().map(|c| c * BRICK));
                if !h.is_uniform() && !written.contains(&h.first) {
                    assert_eq!(before.headers[old as usize].first, h.first, "t {t}: an unchanged brick moved");
                }
            }
        }
        compacted |= patch.compacted;
        let live: usize = store.headers.iter().filter(|h| !h.is_uniform()).map(|h| h.count as usize).sum();
        assert!(store.records.len() <= 2 * live + 512, "t {t}: holes are bounded");
    }
    assert!(!compacted, "the ball's holes stay below the blob's records");
    // The same store again changes nothing.
    let again = store_in(&times[11], range);
    assert_eq!(store.patch(again).unwrap(), crate::bricks::Patch::default());
    // The ball alone: its moves leave holes that pass its records, which are then laid out afresh.
    let empty = ScalarVolume { values: vec![0.0; times[0].values.len()], ..times[0].clone() };
    let mut store = store_in(&ball(0, empty.clone()), range);
    let mut compacted = 0;
    for t in 1..12 {
        let next = store_in(&ball(t, empty.clone()), range);
        let patch = store.patch(next.clone()).unwrap();
        if patch.compacted {
            compacted += 1;
            assert_eq!(patch.records, vec![[0, store.records.len() as u32]]);
            assert_eq!(store.records, next.records, "t {t}: laid out as a fresh store");
        }
        let live: usize = store.headers.iter().filter(|h| !h.is_uniform()).map(|h| h.count as usize).sum();
        assert!(store.records.len() <= 2 * live + 512, "t {t}: holes are bounded");
        assert_eq!(store.masks, next.masks);
    }
    assert!(compacted > 0, "the ball's moves lay its records out afresh");
}

#[test]
fn a_time_point_of_another_grid_or_range_is_refused_and_the_scene_kept() {
    let (a, b) = (at(0), at(1));
    let range = range(&[a.clone(), b.clone()]);
    let mut r = common::cpu();
    let err = r.update_volume(store_in(&a, range)).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument(ref m) if m.contains("bricked volume")), "{err}");
    r.set_bricks(BrickScene::new(store_in(&a, range), tf(), None).unwrap()).unwrap();
    let err = r.update_volume(store_in(&b, (range.0, range.1 + 1.0))).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument(ref m) if m.contains("from_region")), "{err}");
    let small = ScalarVolume { dims: [8, 8, 8], spacing: [1.0; 3], values: vec![1.0; 512] };
    let err = r.update_volume(store_in(&small, range)).unwrap_err();
    assert!(matches!(err, Error::InvalidArgument(ref m) if m.contains("keeps its grid")), "{err}");
    // Still the first time point.
    let cam = Camera::framing(&crate::Grid::centered(DIMS, a.spacing).unwrap(), 48, 48);
    let mut fresh = common::cpu();
    fresh.set_bricks(BrickScene::new(store_in(&a, range), tf(), None).unwrap()).unwrap();
    let o = RenderOptions::default();
    assert!(r.render(&cam, &o).unwrap().image.pixels == fresh.render(&cam, &o).unwrap().image.pixels);
}

/// Plays the series through `update_volume` on `played` and sets each time point afresh on
/// another renderer: the frames agree bit for bit; returns the frames and the updates.
fn play(
    gpu: bool,
    budget: Option<u64>,
    shading: Option<Shading>,
    o: &RenderOptions,
    series: fn(u32) -> ScalarVolume,
) -> (Vec<crate::ImageF32>, Vec<(crate::VolumeUpdate, u64)>) {
    let times: Vec<ScalarVolume> = (0..6).map(series).collect();
    let range = range(&times);
    let cam = Camera::framing(&crate::Grid::centered(times[0].dims, times[0].spacing).unwrap(), 80, 72);
    let renderer = || {
        let mut r = if gpu { common::gpu() } else { common::cpu() };
        if let Some(b) = budget {
            r.set_gpu_budget(b).unwrap();
        }
        r
    };
    let mut played = renderer();
    played.set_bricks(BrickScene::new(store_in(&times[0], range), tf(), shading).unwrap()).unwrap();
    let (mut frames, mut updates) = (Vec::new(), Vec::new());
    for (t, vol) in times.iter().enumerate() {
        if t > 0 {
            let u = played.update_volume(store_in(vol, range)).unwrap();
            // What the device's headers, masks and index take of the bytes written.
            let scene = played.volume().unwrap();
            let tables = if u.layout {
                scene.store.headers.len() * 16 + (scene.store.mask_words().len() + scene.index_words().len()) * 4
            } else {
                u.changed * (16 + scene.store.mask_words().len() * 4 / u.bricks)
            };
            updates.push((u, tables as u64));
        }
        let a = played.render(&cam, o).unwrap().image;
        let mut fresh = renderer();
        fresh.set_bricks(BrickScene::new(store_in(vol, range), tf(), shading).unwrap()).unwrap();
        let b = fresh.render(&cam, o).unwrap().image;
        assert!(common::covered(&a) > 100, "t {t}: something drawn");
        let differ = a.pixels.iter().zip(&b.pixels).filter(|(p, q)| p != q).count();
        assert_eq!(differ, 0, "gpu {gpu} budget {budget:?} t {t}: pixels where the played frame differs");
        if gpu {
            assert_clean(&fresh);
        }
        frames.push(a);
    }
    if gpu {
        assert_clean(&played);
    }
    (frames, updates)
}

#[test]
fn a_played_series_draws_what_each_time_point_draws_set_afresh() {
    let cam = Camera::framing(&crate::Grid::centered(DIMS, [1.0, 1.2, 0.9]).unwrap(), 80, 72);
    let shading = Some(Shading::headlight(cam.forward()));
    let mut mip = RenderOptions::default();
    mip.mode = Mode::Mip;
    for (shading, o, what) in
        [(None, RenderOptions::default(), "plain"), (shading, RenderOptions::default(), "shaded"), (None, mip, "mip")]
    {
        let (g, updates) = play(true, None, shading, &o, at);
        let (c, _) = play(false, None, shading, &o, at);
        for (t, (a, b)) in g.iter().zip(&c).enumerate() {
            assert_mirrors(a, b, &format!("{what} t {t}"));
        }
        // The ball's bricks are written, not the store: their records (at most a brick's each),
        // and their headers and masks, or all headers, masks and the index when bricks appeared
        // or went (`VolumeUpdate::layout`).
        // Bricks appear (the tables rewritten whole) and change in place (theirs alone).
        assert!(updates.iter().any(|u| u.0.layout) && updates.iter().any(|u| !u.0.layout), "{what}: {updates:?}");
        for (t, (u, tables)) in updates.iter().enumerate() {
            assert!(u.changed > 0 && u.uploaded > *tables, "{what} t {}: {u:?}", t + 1);
            assert!(u.uploaded <= tables + u.changed as u64 * 2048, "{what} t {}: {u:?}", t + 1);
            assert!(u.uploaded * 3 < u.store_bytes, "{what} t {}: {u:?}", t + 1);
        }
    }
}

#[test]
fn a_series_streamed_through_a_small_budget_plays_the_same_frames() {
    let vol = large_at(0);
    let store = store_in(&vol, range(std::slice::from_ref(&vol)));
    // Below twice the records: they stream, batch by batch.
    let budget = store.records.len() as u64 * 8 - 1;
    let scene = BrickScene::new(store, tf(), None).unwrap();
    assert!(scene.streams(budget));
    assert!(crate::plan::bricked_min_budget(&scene, budget, 80, 72) < budget);
    let o = RenderOptions::default();
    let (resident, _) = play(true, None, None, &o, large_at);
    let (streamed, updates) = play(true, Some(budget), None, &o, large_at);
    assert!(resident.iter().zip(&streamed).all(|(a, b)| a.pixels == b.pixels), "streaming changes a frame");
    // A streamed store's records stay on the host (they travel batch by batch): only headers,
    // masks and the index are written.
    for (u, tables) in &updates {
        assert!(u.changed > 0 && u.uploaded == *tables, "{u:?}: {tables} bytes of tables");
    }
}

/// A 4-D NIfTI-1 file of u8 samples: `frames` volumes of `dims`, `units` its xyzt_units.
fn nifti4(dims: [u32; 3], frames: u32, units: u8, v: &[u8]) -> Vec<u8> {
    let mut h = common::nifti(dims, &[], None, None);
    let dim: [i16; 5] = [4, dims[0] as i16, dims[1] as i16, dims[2] as i16, frames as i16];
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[123] = units;
    h.extend_from_slice(v);
    h
}

#[test]
fn a_4d_nifti_is_read_one_time_point_at_a_time() {
    use crate::loaders::{load_channels, load_volume, time_points, VolumeHints};
    let dims = [9, 8, 7];
    let n = (dims[0] * dims[1] * dims[2]) as usize;
    let dir = std::env::temp_dir().join(format!("voxsplat-series-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let frames = |t: u32| (0..n).map(|i| ((i as u32 * 7 + t * 31) % 251) as u8).collect::<Vec<u8>>();
    let all = |count: u32| (0..count).flat_map(frames).collect::<Vec<u8>>();
    let at = |t| VolumeHints { time: Some(t), ..Default::default() };
    // Seconds as its units: a series of three time points, not three channels.
    let timed = dir.join("timed.nii");
    std::fs::write(&timed, nifti4(dims, 3, 8, &all(3))).unwrap();
    assert_eq!(time_points(&timed).unwrap(), 3);
    for t in 0..3 {
        let v = load_volume(&timed, &at(t)).unwrap();
        assert_eq!(v.values, frames(t).iter().map(|&b| b as f32).collect::<Vec<_>>(), "time point {t}");
        assert_eq!(load_channels(&timed, &at(t)).unwrap()[0].values, v.values);
        let store = BrickStore::load(&timed, &at(t)).unwrap();
        let (banded, outside) = BrickStore::load_in_range(&timed, &at(t), (0.0, 100.0)).unwrap();
        let beyond = v.values.iter().filter(|&&x| x > 100.0).count() as u64;
        assert_eq!((banded.range, outside), ((0.0, 100.0), beyond));
        assert_eq!(store.len(), v.values.iter().filter(|&&x| x > store.range.0).count());
    }
    let err = load_volume(&timed, &VolumeHints::default()).unwrap_err().to_string();
    assert!(err.contains("holds 3 time points") && err.contains("--time"), "{err}");
    let err = load_volume(&timed, &at(3)).unwrap_err().to_string();
    assert!(err.contains("--time 3") && err.contains("0 to 2"), "{err}");
    // No time units and at most 4 frames: channels, as before; more frames: time points.
    let channels = dir.join("channels.nii");
    std::fs::write(&channels, nifti4(dims, 3, 0, &all(3))).unwrap();
    assert_eq!(time_points(&channels).unwrap(), 1);
    assert_eq!(load_channels(&channels, &VolumeHints::default()).unwrap().len(), 3);
    let long = dir.join("long.nii");
    std::fs::write(&long, nifti4(dims, 6, 0, &all(6))).unwrap();
    assert_eq!(time_points(&long).unwrap(), 6);
    assert_eq!(load_volume(&long, &at(5)).unwrap().values, frames(5).iter().map(|&b| b as f32).collect::<Vec<_>>());
    // Truncated before the last time point: that one is refused, naming the file.
    let cut = dir.join("cut.nii");
    let mut bytes = nifti4(dims, 6, 8, &all(6));
    bytes.truncate(bytes.len() - 10);
    std::fs::write(&cut, bytes).unwrap();
    load_volume(&cut, &at(4)).unwrap();
    let err = load_volume(&cut, &at(5)).unwrap_err().to_string();
    assert!(err.contains("cut.nii") && err.contains("truncated"), "{err}");
    // --time on a file without a time axis.
    let plain = dir.join("plain.nii");
    std::fs::write(&plain, common::nifti(dims, &frames(0), None, None)).unwrap();
    let err = load_volume(&plain, &at(1)).unwrap_err().to_string();
    assert!(err.contains("--time 1") && err.contains("no time axis"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_4d_nrrd_with_a_time_axis_is_read_one_time_point_at_a_time() {
    use crate::loaders::{load_channels, load_volume, time_points, VolumeHints};
    let dir = std::env::temp_dir().join(format!("voxsplat-series-nrrd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n = 5 * 4 * 3;
    let data: Vec<u8> = (0..4 * n).map(|i| (i * 3 % 256) as u8).collect();
    let file = |kinds: &str, sizes: &str, bytes: &[u8]| {
        let kinds = if kinds.is_empty() { String::new() } else { format!("kinds: {kinds}\n") };
        let mut f =
            format!("NRRD0004\ntype: uint8\ndimension: 4\nsizes: {sizes}\n{kinds}encoding: raw\n\n").into_bytes();
        f.extend_from_slice(bytes);
        f
    };
    let at = |t| VolumeHints { time: Some(t), ..Default::default() };
    let path = dir.join("t.nrrd");
    std::fs::write(&path, file("space space space time", "5 4 3 4", &data)).unwrap();
    assert_eq!(time_points(&path).unwrap(), 4);
    for t in 0..4u32 {
        let want: Vec<f32> = data[t as usize * n..(t as usize + 1) * n].iter().map(|&b| b as f32).collect();
        assert_eq!(load_volume(&path, &at(t)).unwrap().values, want, "time point {t}");
        assert_eq!(load_channels(&path, &at(t)).unwrap()[0].values, want);
    }
    let err = load_volume(&path, &VolumeHints::default()).unwrap_err().to_string();
    assert!(err.contains("holds 4 time points"), "{err}");
    // Truncated inside the last time point: the earlier ones read, the last is refused.
    std::fs::write(&path, file("space space space time", "5 4 3 4", &data[..4 * n - 1])).unwrap();
    load_volume(&path, &at(2)).unwrap();
    let err = load_volume(&path, &at(3)).unwrap_err().to_string();
    assert!(err.contains("truncated"), "{err}");
    // Time on the fastest axis interleaves the time points: refused by name.
    std::fs::write(&path, file("time space space space", "4 5 4 3", &data)).unwrap();
    let err = load_volume(&path, &at(0)).unwrap_err().to_string();
    assert!(err.contains("time on axis 0") && err.contains("last"), "{err}");
    // Without kinds a 4-D file keeps the channel reading: four on the first axis are channels.
    std::fs::write(&path, file("", "4 5 4 3", &data)).unwrap();
    assert_eq!((time_points(&path).unwrap(), load_channels(&path, &Default::default()).unwrap().len()), (1, 4));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_pattern_names_a_series_of_files_ordered_by_number() {
    use crate::loaders::{is_pattern, load_volume, series_files, time_points, VolumeHints};
    let dir = std::env::temp_dir().join(format!("voxsplat-series-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dims = [6, 5, 4];
    let frame = |t: u32| (0..120u32).map(|i| ((i + 17 * t) % 200) as u8).collect::<Vec<u8>>();
    for (name, t) in [("scan_2.nii", 0), ("scan_10.nii", 1), ("scan_11.nii", 2), ("notes_1.txt", 9)] {
        std::fs::write(dir.join(name), common::nifti(dims, &frame(t), None, None)).unwrap();
    }
    let pattern = dir.join("scan_*.nii");
    assert!(is_pattern(&pattern) && !is_pattern(&dir.join("scan_2.nii")));
    let names: Vec<String> =
        series_files(&pattern).unwrap().iter().map(|p| p.file_name().unwrap().to_string_lossy().into()).collect();
    assert_eq!(names, ["scan_2.nii", "scan_10.nii", "scan_11.nii"], "by number, not by name");
    assert_eq!(time_points(&pattern).unwrap(), 3);
    for t in 0..3 {
        let v = load_volume(&pattern, &VolumeHints { time: Some(t), ..Default::default() }).unwrap();
        assert_eq!(v.values, frame(t).iter().map(|&b| b as f32).collect::<Vec<_>>(), "time point {t}");
    }
    assert_eq!(time_points(&dir.join("scan_1?.nii")).unwrap(), 2);
    let err = load_volume(&pattern, &Default::default()).unwrap_err().to_string();
    assert!(err.contains("holds 3 time points"), "{err}");
    let err = load_volume(&pattern, &VolumeHints { time: Some(3), ..Default::default() }).unwrap_err().to_string();
    assert!(err.contains("0 to 2"), "{err}");
    let err = time_points(&dir.join("none_*.nii")).unwrap_err().to_string();
    assert!(err.contains("matches no file"), "{err}");
    let err = time_points(&dir.join("*").join("scan_*.nii")).unwrap_err().to_string();
    assert!(err.contains("not folders"), "{err}");
    std::fs::write(dir.join("scan_010.nii"), common::nifti(dims, &frame(3), None, None)).unwrap();
    let err = time_points(&pattern).unwrap_err().to_string();
    assert!(err.contains("share number 10"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 76's fuzzing of patterns: a pattern of many `*` against a long name backtracked through
/// every `*` (`*a*a*a*a*a*a*a*a*b` against 200 letters: past 20 s). It now answers at once, and
/// matches as the shell's globbing does on random patterns and names (a reference matcher by
/// dynamic programming, here).
#[test]
fn a_pattern_matches_as_the_shell_does_in_bounded_time() {
    use crate::loaders::series_files;
    let dir = std::env::temp_dir().join(format!("voxsplat-series-glob-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let long = format!("{}1", "a".repeat(200));
    std::fs::write(dir.join(&long), b"").unwrap();
    let t = std::time::Instant::now();
    let err = series_files(&dir.join("*a*a*a*a*a*a*a*a*b")).unwrap_err().to_string();
    assert!(err.contains("matches no file"), "{err}");
    assert_eq!(series_files(&dir.join("*a*a*a*a*a*a*a*a*1")).unwrap().len(), 1);
    assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
    std::fs::remove_file(dir.join(&long)).unwrap();
    // The reference: does pattern[..i] match name[..j], for every i and j.
    let reference = |p: &[u8], n: &[u8]| {
        let mut m = vec![vec![false; n.len() + 1]; p.len() + 1];
        m[0][0] = true;
        for i in 1..=p.len() {
            for j in 0..=n.len() {
                m[i][j] = match p[i - 1] {
                    b'*' => m[i - 1][j] || j > 0 && m[i][j - 1],
                    c => j > 0 && m[i - 1][j - 1] && (c == b'?' || c == n[j - 1]),
                };
            }
        }
        m[p.len()][n.len()]
    };
    let mut seed = 7u64;
    let mut pick = |k: u64| {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) % k
    };
    let names: Vec<String> = (0..12)
        .map(|i| (0..1 + pick(7)).map(|_| b"ab1"[pick(3) as usize] as char).collect::<String>() + &format!("{i}"))
        .collect();
    for n in &names {
        std::fs::write(dir.join(n), b"").unwrap();
    }
    for _ in 0..200 {
        let pattern: String = (0..1 + pick(6)).map(|_| b"ab1*?"[pick(5) as usize] as char).collect();
        if !pattern.contains(['*', '?']) {
            continue;
        }
        let mut want: Vec<&String> = names.iter().filter(|n| reference(pattern.as_bytes(), n.as_bytes())).collect();
        want.sort();
        let got = match series_files(&dir.join(&pattern)) {
            Ok(files) => {
                let mut got: Vec<String> =
                    files.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
                got.sort();
                got
            }
            Err(e) => {
                let e = e.to_string();
                assert!(e.contains("matches no file") || e.contains("share number"), "{pattern}: {e}");
                if e.contains("share number") {
                    continue;
                }
                Vec::new()
            }
        };
        let want: Vec<String> = want.into_iter().cloned().collect();
        assert_eq!(got, want, "pattern {pattern}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
