//! The bricked store (issue 23, host side): every value comes back through it (up to its 16-bit
//! quantisation), it takes at most 8 bytes per stored voxel on the real volumes, and classifying
//! through it (values and gradients by neighbour lookups) gives the dense classification.
use super::common;
use crate::bricks::{BrickStore, BRICK};
use crate::classify::{classify, Shading, TransferFunction};
use crate::volume::ScalarVolume;
use common::Rng;

#[test]
fn every_value_comes_back_through_the_store() {
    let mut rng = Rng(23);
    let dims = [19, 8, 13]; // not multiples of the brick side
    let n = (dims[0] * dims[1] * dims[2]) as usize;
    let values: Vec<f32> = (0..n)
        .map(|v| match v % 7 {
            0 => 2.0,      // the minimum: empty, not stored
            1 => f32::NAN, // non-finite: empty
            _ => 2.0 + 10.0 * rng.f32(),
        })
        .collect();
    let vol = ScalarVolume { dims, spacing: [1.0, 0.5, 2.0], values };
    let store = BrickStore::build(&vol).unwrap();
    let (lo, hi) = store.range;
    assert_eq!(lo, 2.0);
    let mut stored = 0;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let v = vol.values[(i + dims[0] * (j + dims[1] * k)) as usize];
                let want = if v.is_finite() && v > lo { (v - lo) / (hi - lo) } else { 0.0 };
                stored += usize::from(v.is_finite() && v > lo);
                let got = store.value_at(i as i64, j as i64, k as i64);
                assert!((got - want).abs() <= 0.5 / 65535.0 + 1e-7, "({i},{j},{k}): {got} for {want}");
            }
        }
    }
    assert_eq!(store.len(), stored);
    // Out-of-grid reads clamp, as the dense classification's do.
    assert_eq!(store.value_at(-3, 0, 0), store.value_at(0, 0, 0));
    assert_eq!(store.value_at(100, 7, 12), store.value_at(18, 7, 12));
    // Each header's records lie in its brick and its range holds their values.
    let total: u32 = store.headers.iter().map(|h| h.count).sum();
    assert_eq!(total as usize, store.len());
    for (h, mask) in store.headers.iter().zip(&store.masks) {
        let (qmin, qmax) = (h.range & 0xFFFF, h.range >> 16);
        let records = &store.records[h.first as usize..(h.first + h.count) as usize];
        // The mask marks exactly the records' local positions, which ascend.
        assert_eq!(mask.iter().map(|w| w.count_ones()).sum::<u32>(), h.count);
        for (i, r) in records.iter().enumerate() {
            let l = (r & 0x1FF) as usize;
            assert!(mask[l / 64] >> (l % 64) & 1 == 1);
            assert!(i == 0 || (records[i - 1] & 0x1FF) < r & 0x1FF);
            assert!((qmin..=qmax).contains(&(r >> 16)));
        }
    }
    let too_wide = ScalarVolume { dims: [BRICK * 1024 + 1, 1, 1], spacing: [1.0; 3], values: vec![0.0; 8193] };
    assert!(BrickStore::build(&too_wide).is_err());
}

/// The masks as the device reads them: per brick its 16 mask words, then per word the stored voxels
/// before it, so `stored_at` finds a voxel's record with one count and one popcount.
#[test]
fn the_device_masks_count_the_stored_voxels_before_each_word() {
    let mut rng = Rng(71);
    let dims = [21u32, 17, 13];
    let values: Vec<f32> =
        (0..dims.iter().product::<u32>()).map(|_| if rng.f32() < 0.4 { 0.0 } else { rng.f32() }).collect();
    let store = BrickStore::build(&ScalarVolume { dims, spacing: [1.0; 3], values }).unwrap();
    let words = store.mask_words();
    assert_eq!(words.len(), store.masks.len() * 24);
    for (h, m) in store.masks.iter().enumerate() {
        let mask: &[u32] = bytemuck::cast_slice(m);
        let brick = &words[h * 24..h * 24 + 24];
        assert_eq!(&brick[..16], mask, "brick {h}: its mask words");
        // Two 16-bit counts to a word, the even word's low.
        let below = |w: usize| brick[16 + w / 2] >> (16 * (w % 2)) & 0xffff;
        for w in 0..16 {
            let before: u32 = mask[..w].iter().map(|x| x.count_ones()).sum();
            assert_eq!(below(w), before, "brick {h}, word {w}");
        }
        // Every stored voxel's rank: the records below it in local index order.
        let mut rank = 0;
        for l in 0..512usize {
            if mask[l / 32] >> (l % 32) & 1 == 1 {
                let got = below(l / 32) + (mask[l / 32] & ((1u32 << (l % 32)) - 1)).count_ones();
                assert_eq!(got, rank, "brick {h}, voxel {l}");
                rank += 1;
            }
        }
        assert!(rank > 0, "brick {h} stores a voxel");
    }
}

#[test]
fn real_volumes_take_under_8_bytes_a_voxel_and_classify_alike_through_the_store() {
    let data = crate::loaders::data_dir();
    assert!(data.join("bonsai/bonsai.nii.gz").exists(), "../shared/data is needed (see README)");
    for (file, tf) in [("bonsai/bonsai.nii.gz", "bonsai"), ("stent/stent.nrrd", "ct")] {
        let vol = crate::loaders::load_volume(&data.join(file), &Default::default()).unwrap();
        let store = BrickStore::build(&vol).unwrap();
        let per_voxel = store.bytes() as f64 / store.len() as f64;
        eprintln!("{file}: {} stored voxels in {} bricks, {per_voxel:.2} bytes each", store.len(), store.headers.len());
        assert!(per_voxel <= 8.0, "{file}: {per_voxel} bytes per stored voxel");
        let tf = TransferFunction::preset(tf).unwrap();
        let shading = Some(Shading::headlight(glam::Vec3::new(0.3, -0.2, -1.0)));
        let dense = classify(&vol, &tf, shading).unwrap();
        let bricked = store.classify(&tf, shading).unwrap();
        // Quantisation may move a voxel across a transfer-function edge: count those, compare the rest.
        let key = |s: &crate::gpu_types::Splat| (s.ijk[2], s.ijk[1], s.ijk[0]);
        let (a, b) = (dense.splats(), bricked.splats());
        let (mut ia, mut ib, mut common, mut worst) = (0, 0, 0usize, 0f32);
        while ia < a.len() && ib < b.len() {
            match key(&a[ia]).cmp(&key(&b[ib])) {
                std::cmp::Ordering::Less => ia += 1,
                std::cmp::Ordering::Greater => ib += 1,
                std::cmp::Ordering::Equal => {
                    worst = (0..4).map(|c| (a[ia].color[c] - b[ib].color[c]).abs()).fold(worst, f32::max);
                    common += 1;
                    ia += 1;
                    ib += 1;
                }
            }
        }
        eprintln!(
            "{file}: {} dense splats, {} through the store, {common} common, max |colour diff| {worst:.2e}",
            a.len(),
            b.len()
        );
        assert!(common as f64 >= 0.999 * a.len().max(b.len()) as f64, "{file}: the same voxels are non-empty");
        assert!(worst <= 2e-3, "{file}: colours within the quantisation's reach ({worst})");
    }
}

/// An uncompressed NRRD streams into the same store as the volume loaded whole; a truncated one
/// and one past the streaming limit are typed errors before any large allocation.
#[test]
fn a_raw_nrrd_streams_into_the_same_store() {
    let dir = std::env::temp_dir().join(format!("voxsplat-bricks-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dims = [21u32, 18, 11];
    let n = (dims[0] * dims[1] * dims[2]) as usize;
    let mut rng = Rng(5);
    let data: Vec<u8> = (0..n).map(|v| if v % 3 == 0 { 7 } else { 7 + (rng.f32() * 200.0) as u8 }).collect();
    let write = |name: &str, sizes: &str, data: &[u8]| {
        let path = dir.join(name);
        let mut bytes =
            format!("NRRD0004\ntype: uint8\ndimension: 3\nsizes: {sizes}\nspacings: 1 0.5 2\nencoding: raw\n\n")
                .into_bytes();
        bytes.extend_from_slice(data);
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let path = write("small.nrrd", "21 18 11", &data);
    let whole = BrickStore::build(&crate::loaders::load_volume(&path, &Default::default()).unwrap()).unwrap();
    let streamed = BrickStore::load(&path, &Default::default()).unwrap();
    assert!(crate::loaders::SliceReader::nrrd(&path).unwrap().is_some());
    assert_eq!(streamed.range, whole.range);
    assert_eq!(streamed.spacing, [1.0, 0.5, 2.0]);
    assert_eq!(streamed.headers, whole.headers);
    assert_eq!(streamed.masks, whole.masks);
    assert_eq!(streamed.records, whole.records);
    let truncated = write("truncated.nrrd", "21 18 11", &data[..n - 1]);
    assert!(
        matches!(BrickStore::load(&truncated, &Default::default()), Err(crate::Error::InvalidArgument(m)) if m.contains("truncated"))
    );
    // 2^35 voxels: past what streaming takes, refused from the header alone.
    let huge = write("huge.nrrd", "32768 32768 32", &data);
    assert!(matches!(BrickStore::load(&huge, &Default::default()), Err(crate::Error::TooLarge(_))));
    std::fs::remove_dir_all(&dir).ok();
}

/// The streamed NRRD path under truncation and header corruption: typed errors or a store, never
/// a panic; every truncation of the data is an error.
#[test]
fn a_streamed_nrrd_survives_truncation_and_corruption() {
    let dir = std::env::temp_dir().join(format!("voxsplat-bricks-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = Rng(77);
    let data: Vec<u8> = (0..(9 * 10 * 11)).map(|_| (rng.f32() * 255.0) as u8).collect();
    let mut good = b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 9 10 11\nencoding: raw\n\n".to_vec();
    let header = good.len();
    good.extend_from_slice(&data);
    let path = dir.join("v.nrrd");
    let load = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        BrickStore::load(&path, &Default::default())
    };
    assert!(load(&good).is_ok());
    for _ in 0..300 {
        let cut = header + (rng.f32() * data.len() as f32) as usize;
        assert!(load(&good[..cut.min(good.len() - 1)]).is_err(), "a truncation at {cut} loads");
        let mut bad = good.clone();
        let at = (rng.f32() * header as f32) as usize;
        bad[at] = (rng.f32() * 256.0) as u8;
        let _ = load(&bad); // an error or a store: no panic
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// NIfTI (plain, and gzip inflated as it is read, a pass going back restarting the stream) and raw
/// files stream into the same store as the volume loaded whole; truncations are typed errors.
#[test]
fn nifti_and_raw_files_stream_into_the_same_store() {
    let dir = std::env::temp_dir().join(format!("voxsplat-bricks-nii-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let gz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bonsai/bonsai.nii.gz");
    let packed = std::fs::read(&gz).unwrap();
    let plain = crate::loaders::gunzip(&packed, 1 << 26, "bonsai").unwrap();
    let nii = dir.join("bonsai.nii");
    std::fs::write(&nii, &plain).unwrap();
    let whole = BrickStore::build(&crate::loaders::load_volume(&gz, &Default::default()).unwrap()).unwrap();
    assert!(whole.len() > 1_000_000, "{} stored voxels", whole.len());
    let same = |s: &BrickStore, what: &str| {
        assert_eq!((s.dims, s.spacing, s.range), (whole.dims, whole.spacing, whole.range), "{what}");
        assert!(s.headers == whole.headers && s.masks == whole.masks && s.records == whole.records, "{what}");
    };
    same(&BrickStore::load(&gz, &Default::default()).unwrap(), "nii.gz");
    same(&BrickStore::load(&nii, &Default::default()).unwrap(), "nii");
    // The same voxels as a raw file with its dims and type.
    let offset = plain.len() - whole.dims.iter().product::<u32>() as usize;
    let raw = dir.join("bonsai.raw");
    std::fs::write(&raw, &plain[offset..]).unwrap();
    let hints = crate::loaders::VolumeHints {
        dims: Some(whole.dims),
        dtype: Some(crate::loaders::DType::U8),
        spacing: Some(whole.spacing),
        ..Default::default()
    };
    same(&BrickStore::load(&raw, &hints).unwrap(), "raw");
    // Truncated: the plain file and the raw one before reading, the gzip stream while it inflates.
    let cut = |path: &std::path::Path, bytes: &[u8], at: usize, h: &crate::loaders::VolumeHints| {
        std::fs::write(path, &bytes[..at]).unwrap();
        BrickStore::load(path, h)
    };
    for frac in [0.1, 0.5, 0.999] {
        let at = |n: usize| (n as f64 * frac) as usize;
        let err = cut(&nii, &plain, at(plain.len()), &Default::default()).unwrap_err();
        assert!(
            matches!(err, crate::Error::InvalidArgument(ref m) if m.contains("truncated") || m.contains("NIfTI")),
            "{err}"
        );
        let err = cut(&dir.join("t.nii.gz"), &packed, at(packed.len()).max(400), &Default::default()).unwrap_err();
        assert!(matches!(err, crate::Error::InvalidArgument(_)), "{err}");
        assert!(cut(&raw, &plain[offset..], at(plain.len() - offset), &hints).is_err());
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A gzip-encoded NRRD (the stent) streams, inflated as it is read, into the store the whole
/// volume builds; cut anywhere in its data, it is a typed error.
#[test]
fn a_gzip_nrrd_streams_into_the_same_store() {
    let stent = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/stent/stent.nrrd");
    let whole = BrickStore::build(&crate::loaders::load_volume(&stent, &Default::default()).unwrap()).unwrap();
    assert!(crate::loaders::SliceReader::nrrd(&stent).unwrap().is_some(), "gzip data streams");
    let s = BrickStore::load(&stent, &Default::default()).unwrap();
    assert_eq!((s.dims, s.spacing, s.range), (whole.dims, whole.spacing, whole.range));
    assert!(s.headers == whole.headers && s.masks == whole.masks && s.records == whole.records);
    let bytes = std::fs::read(&stent).unwrap();
    let dir = std::env::temp_dir().join(format!("voxsplat-bricks-gz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cut = dir.join("cut.nrrd");
    for frac in [0.2, 0.6, 0.99] {
        std::fs::write(&cut, &bytes[..(bytes.len() as f64 * frac) as usize]).unwrap();
        let err = BrickStore::load(&cut, &Default::default()).unwrap_err();
        assert!(matches!(err, crate::Error::InvalidArgument(_)), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 44: a full brick whose voxels hold one value stores no records, only its header (a
/// constant 512³ volume took 4 bytes a voxel), and every value still comes back through it.
#[test]
fn uniform_bricks_store_no_records_and_every_value_comes_back() {
    let vol = common::flat_blocks([37, 29, 40]);
    let store = BrickStore::build(&vol).unwrap();
    let uniform: Vec<_> = store.headers.iter().filter(|h| h.is_uniform()).collect();
    assert!(uniform.len() >= 12, "{} uniform bricks", uniform.len());
    let dims = vol.dims;
    let mut stored = 0;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let v = vol.values[(i + dims[0] * (j + dims[1] * k)) as usize];
                let want = (v - store.range.0) / (store.range.1 - store.range.0);
                stored += usize::from(v > 0.0);
                let got = store.value_at(i as i64, j as i64, k as i64);
                assert!((got - want).abs() <= 0.5 / 65535.0 + 1e-7, "({i},{j},{k}): {got} for {want}");
            }
        }
    }
    assert_eq!(store.len(), stored);
    assert_eq!(store.records.len(), stored - uniform.len() * 512, "a uniform brick stores no record");
    // What the scene frames and draws, taken from uniform bricks' values, is what classifying
    // the store voxel by voxel gives.
    for tf in [common::blob_tf(), crate::classify::TransferFunction::preset("ramp").unwrap()] {
        let set = store.classify(&tf, None).unwrap();
        let scene = crate::bricks::BrickScene::new(store.clone(), tf, None).unwrap();
        assert_eq!(scene.visible_bounds(), set.bounds());
        assert_eq!(scene.drawn_counts().iter().sum::<u32>() as usize, set.len());
    }
    for h in &uniform {
        let records = store.brick_records(h);
        assert_eq!(records.len(), 512);
        let q = h.range & 0xFFFF;
        assert_eq!(h.range >> 16, q);
        assert!(records.iter().enumerate().all(|(l, &r)| r == l as u32 | q << 16));
    }
    // A constant volume: every brick uniform where it is full, records only in the partial ones.
    for (dims, records) in [([16, 24, 8], 0), ([17, 16, 8], 16 * 8)] {
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        let store = BrickStore::build(&ScalarVolume { dims, spacing: [1.0; 3], values: vec![3.0; n] }).unwrap();
        assert_eq!((store.len(), store.records.len()), (n, records), "{dims:?}");
        assert_eq!(store.value_at(5, 5, 5), 0.0);
        // Seen through a TF range that makes the value visible, every voxel is framed and drawn.
        let mut tf = crate::classify::TransferFunction::preset("ramp").unwrap();
        tf.range = Some((0.0, 6.0));
        let scene = crate::bricks::BrickScene::new(store, tf, None).unwrap();
        assert_eq!(scene.visible_bounds(), Some([[0; 3], dims.map(|d| d - 1)]), "{dims:?}");
        assert_eq!(scene.drawn_counts().iter().sum::<u32>() as usize, n, "{dims:?}");
    }
}

/// Each stored voxel's precomputed central differences (what a shaded frame's `brick_params`
/// reads in place of six neighbours) are exactly the store's own, voxel by voxel: across brick
/// faces, at the clamped grid edges, in partial and uniform bricks. The device finds a voxel's
/// two words as `brick_params` does: the header's first word plus the records before it.
#[test]
fn every_stored_voxel_keeps_the_stores_central_differences() {
    use crate::bricks::unpack_differences;
    let mut rng = Rng(41);
    let noisy = {
        let dims = [21, 17, 11];
        let n = (dims[0] * dims[1] * dims[2]) as usize;
        let values = (0..n).map(|v| if v % 5 == 0 { 0.0 } else { 1.0 + 300.0 * rng.f32() }).collect();
        ScalarVolume { dims, spacing: [1.0; 3], values }
    };
    for vol in [common::blob([37, 29, 23]), common::flat_blocks([37, 29, 40]), noisy] {
        let store = BrickStore::build(&vol).unwrap();
        let [words, hi] = store.gradient_words(|_| true);
        assert_eq!((words.len() as u64, hi.len()), (store.gradient_len(), words.len()));
        assert_eq!(words[..store.headers.len()], hi[..store.headers.len()]);
        let q = |i: i64, j: i64, k: i64| (store.value_at(i, j, k) * 65535.0).round() as i32;
        let (mut checked, mut across) = (0, 0);
        for (h, hd) in store.headers.iter().enumerate() {
            let records = store.brick_records(hd);
            let base = hd.coords().map(|c| (c * BRICK) as i64);
            for (rank, r) in records.iter().enumerate() {
                let l = r & 511;
                let local = [l % BRICK, l / BRICK % BRICK, l / (BRICK * BRICK)];
                let [i, j, k] = [0, 1, 2].map(|a| base[a] + local[a] as i64);
                let want =
                    [q(i + 1, j, k) - q(i - 1, j, k), q(i, j + 1, k) - q(i, j - 1, k), q(i, j, k + 1) - q(i, j, k - 1)];
                let at = (words[h] + rank as u32) as usize;
                let got = unpack_differences([words[at], hi[at]], 1.0);
                assert_eq!(got, want.map(|d| d as f32), "({i},{j},{k})");
                checked += 1;
                across += usize::from(local.iter().any(|&c| c == 0 || c == BRICK - 1) && want != [0; 3]);
            }
        }
        assert_eq!(checked, store.len());
        assert!(across > 0, "differences across brick faces are checked");
    }
    // A brick the predicate leaves out keeps zeros (the transfer function draws none of it).
    let store = BrickStore::build(&common::blob([37, 29, 23])).unwrap();
    let [words, hi] = store.gradient_words(|hd| hd.coords() != [1, 1, 1]);
    let h = store.headers.iter().position(|hd| hd.coords() == [1, 1, 1]).unwrap();
    let (at, n) = (words[h] as usize, store.headers[h].count as usize);
    assert!(n > 0 && words[at..at + n].iter().chain(&hi[at..at + n]).all(|&w| w == 0));
    assert_ne!(store.gradient_words(|_| true)[0][at..at + n], words[at..at + n]);
}

/// A stream that fits the slab cache is read once: the brick pass takes what the range pass kept
/// (a DICOM decoder or compressed chunks are the slow part of a load), and the store is the one
/// the volume in memory gives.
#[test]
fn a_stream_that_fits_is_read_once() {
    let vol = common::blob([37, 29, 23]);
    let plane = (vol.dims[0] * vol.dims[1]) as usize;
    let mut slices = 0;
    let streamed = BrickStore::from_slices(vol.dims, vol.spacing, |z0, count, out| {
        slices += count;
        out.clear();
        out.extend_from_slice(&vol.values[z0 as usize * plane..(z0 + count) as usize * plane]);
        Ok(())
    })
    .unwrap();
    assert_eq!(slices, vol.dims[2], "each slice read once");
    let whole = BrickStore::build(&vol).unwrap();
    assert_eq!((streamed.range, &streamed.headers, &streamed.records), (whole.range, &whole.headers, &whole.records));
    assert_eq!(streamed.masks, whole.masks);
}

/// The histogram a transfer-function editor draws over (issue 48 item 2): on the bonsai, a uint8
/// volume, each bin holds exactly the voxels whose file value lies in it, counted from the volume
/// itself; uniform bricks count every voxel; the empty voxels are counted apart; the log heights
/// run from 0 to 1; a bin count outside 1 to `MAX_BINS` is refused.
#[test]
fn the_histogram_counts_each_stored_voxel_in_the_bin_of_its_file_value() {
    let data = crate::loaders::data_dir();
    let vol = crate::loaders::load_volume(&data.join("bonsai/bonsai.nii.gz"), &Default::default()).unwrap();
    let store = BrickStore::build(&vol).unwrap();
    let (lo, hi) = store.range;
    assert!(vol.values.iter().all(|v| v.fract() == 0.0) && hi > lo, "integer samples");
    let span = (hi - lo) as u64;
    for bins in [1, 7, 16, 64, span as u32] {
        let h = store.histogram(bins).unwrap();
        let mut want = vec![0u64; bins as usize];
        let mut empty = 0;
        for &v in &vol.values {
            if v <= lo {
                empty += 1;
                continue;
            }
            // ⌊(v − lo) / (hi − lo) × bins⌋ in integers, the last bin closed.
            let at = (((v - lo) as u64 * bins as u64) / span).min(bins as u64 - 1);
            want[at as usize] += 1;
        }
        assert_eq!(h.counts, want, "{bins} bins");
        assert_eq!(h.empty, empty, "{bins} bins: the empty voxels");
        assert_eq!(h.counts.iter().sum::<u64>(), store.len() as u64);
        assert_eq!((h.edge(0), h.edge(bins as usize)), (lo, hi));
        let heights = h.log_heights();
        let top = h.counts.iter().position(|&c| c == *h.counts.iter().max().unwrap()).unwrap();
        assert_eq!(heights[top], 1.0);
        for (c, y) in h.counts.iter().zip(&heights) {
            assert!((*c == 0) == (*y == 0.0) && (0.0..=1.0).contains(y), "{bins} bins: {c} voxels drawn {y} high");
        }
    }

    // A span that does not divide the 65,535 quanta: 125 of 0..200 is stored just under its edge
    // (40,959 of 40,959.375), and still binned as its value.
    let values: Vec<f32> = (0..24 * 24 * 24).map(|i| (i % 201) as f32).collect();
    let vol = ScalarVolume { dims: [24, 24, 24], spacing: [1.0; 3], values };
    let h = BrickStore::build(&vol).unwrap().histogram(8).unwrap();
    let mut want = vec![0u64; 8];
    for &v in vol.values.iter().filter(|&&v| v > 0.0) {
        want[((v as usize * 8) / 200).min(7)] += 1;
    }
    assert_eq!(h.counts, want, "values 0 to 200 in 8 bins");

    let vol = common::flat_blocks([37, 29, 40]);
    let store = BrickStore::build(&vol).unwrap();
    assert!(store.headers.iter().any(|h| h.is_uniform()));
    let h = store.histogram(8).unwrap();
    // The flat block (50 of 0..~90) is the fullest bin, uniform bricks and all.
    let block = vol.values.iter().filter(|&&v| v == 50.0).count() as u64;
    let at = ((50.0 - store.range.0) / (store.range.1 - store.range.0) * 8.0) as usize;
    assert!(h.counts[at] >= block, "{} in the block's bin, {block} in the block", h.counts[at]);
    assert_eq!(h.counts.iter().sum::<u64>() + h.empty, vol.values.len() as u64);
    for bins in [0, crate::bricks::MAX_BINS + 1] {
        let e = store.histogram(bins).unwrap_err().to_string();
        assert!(e.contains("1 to 65536 bins"), "{e}");
    }
}

/// `VolumeHints::progress` follows a streamed load (issue 48 item 5's progress bar): after each
/// slab, the slices read of all it reads, rising to all of them, and the store is the one loaded
/// without it.
#[test]
fn a_streamed_load_tells_its_progress() {
    let path = crate::loaders::data_dir().join("bonsai/bonsai.nii.gz");
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let log = seen.clone();
    let progress = crate::loaders::Progress::new(move |read, of| log.lock().unwrap().push((read, of)));
    let hints = crate::loaders::VolumeHints { progress: Some(progress), ..Default::default() };
    let store = BrickStore::load(&path, &hints).unwrap();
    let seen = seen.lock().unwrap().clone();
    // The bonsai's 256 slices fit the kept samples: one pass over the file, 32 slabs.
    assert_eq!(seen.len(), 32, "{seen:?}");
    assert!(seen.windows(2).all(|w| w[0].0 < w[1].0 && w[0].1 == w[1].1), "{seen:?}");
    assert_eq!(seen.last(), Some(&(256, 256)));
    let plain = BrickStore::load(&path, &Default::default()).unwrap();
    assert_eq!((store.records, store.headers), (plain.records, plain.headers));
}

/// A plane through the store (issue 48 item 4's slice panes) reads the file's values back, to
/// half a quantum, along each axis; empty voxels read as the range's start, the value they had;
/// planes outside the grid are refused.
#[test]
fn a_plane_through_the_store_reads_the_files_values() {
    let path = crate::loaders::data_dir().join("stent/stent.nrrd");
    let vol = crate::loaders::load_volume(&path, &Default::default()).unwrap();
    let store = BrickStore::build(&vol).unwrap();
    let [nx, ny, nz] = vol.dims;
    let at = |i: u32, j: u32, k: u32| vol.values[(i + nx * (j + ny * k)) as usize];
    let tolerance = (store.range.1 - store.range.0) / 65535.0 * 0.5 + 1e-3;
    for (axis, index) in [(0, 40), (1, 77), (2, 130), (2, 0), (0, nx - 1)] {
        let p = store.plane(axis, index).unwrap();
        let (w, h) = [(ny, nz), (nx, nz), (nx, ny)][axis];
        assert_eq!((p.width, p.height, p.values.len()), (w, h, (w * h) as usize), "axis {axis}");
        for row in 0..h {
            for col in 0..w {
                let want = match axis {
                    0 => at(index, col, row),
                    1 => at(col, index, row),
                    _ => at(col, row, index),
                };
                let got = p.values[(row * w + col) as usize];
                assert!((got - want).abs() <= tolerance, "axis {axis} plane {index} ({col}, {row}): {got} for {want}");
            }
        }
    }
    for (axis, index) in [(0, nx), (2, nz), (3, 0)] {
        assert!(store.plane(axis, index).unwrap_err().to_string().contains("no plane"), "axis {axis}, {index}");
    }
}
