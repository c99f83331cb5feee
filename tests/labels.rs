//! Label volumes and channels: labels never interpolated into one another, hidden labels draw
//! nothing, missing labels are counted; channels combined per voxel; and what each refuses.
use super::common;
use crate::classify::{classify_channels, TransferFunction};
use crate::labels::{classify_labels, LabelTable};
use crate::volume::ScalarVolume;
use crate::{Camera, Grid, Raster, RenderOptions};
use common::{assert_clean, assert_mirrors, cpu, gpu};

const DIMS: [u32; 3] = [24, 20, 16];

/// Slabs of labels 1 and 3 side by side along x (no voxel of label 2 between them), a block of
/// label 7 (not in the table) and background 0 around.
fn segmentation() -> ScalarVolume {
    let mut values = Vec::new();
    for k in 0..DIMS[2] {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                let inside = (3..DIMS[1] - 3).contains(&j) && (2..DIMS[2] - 2).contains(&k);
                values.push(match i {
                    _ if !inside => 0.0,
                    3..=10 => 1.0,
                    11..=18 => 3.0,
                    19..=21 if j < 8 => 7.0,
                    _ => 0.0,
                });
            }
        }
    }
    ScalarVolume { dims: DIMS, spacing: [1.0; 3], values }
}

fn table(show_3: bool) -> LabelTable {
    let mut t = LabelTable::from_toml(
        r#"
        [[label]]
        value = 1
        color = [1.0, 0.0, 0.0]
        opacity = 0.6
        [[label]]
        value = 2
        color = [0.0, 1.0, 0.0]
        opacity = 0.9
        [[label]]
        value = 3
        color = [0.0, 0.0, 1.0]
        opacity = 0.6
        "#,
    )
    .unwrap();
    t.set_visible(3, show_3).unwrap();
    t
}

fn cameras(grid: &Grid) -> Vec<Camera> {
    let mut rng = common::Rng(4603);
    let mut cams = vec![Camera::framing(grid, 64, 64)];
    cams.extend((0..3).map(|_| common::random_camera(&mut rng, grid, common::ViewKind::Outside)));
    cams
}

#[test]
fn labels_are_never_interpolated_into_one_another_and_hidden_labels_draw_nothing() {
    let seg = segmentation();
    let grid = Grid::centered(DIMS, [1.0; 3]).unwrap();
    let shown = classify_labels(grid, &seg, &table(true), None).unwrap();
    let hidden = classify_labels(grid, &seg, &table(false), None).unwrap();
    let sevens = seg.values.iter().filter(|&&v| v == 7.0).count() as u64;
    assert_eq!(shown.unlabelled, sevens, "label 7 is missing from the table");
    assert_eq!(shown.missing, vec![7]);
    let mut g = gpu();
    let mut c = cpu();
    for raster in [Raster::Compute, Raster::Graphics] {
        let mut o = RenderOptions::default();
        o.raster = raster;
        for cam in cameras(&grid) {
            g.set_scene(shown.set.clone()).unwrap();
            let f = g.render(&cam, &o).unwrap();
            assert_eq!(f.stats.unlabelled, sevens, "the frame reports the missing label's voxels");
            // Labels 1 (red) and 3 (blue) touch; an interpolated label would pass through 2 (green).
            let green = f.image.pixels.iter().map(|p| p[1]).fold(0.0f32, f32::max);
            assert!(green == 0.0, "{raster}: a pixel took label 2's green ({green}), which no voxel has");
            assert!(f.image.pixels.iter().any(|p| p[0] > 0.2) && f.image.pixels.iter().any(|p| p[2] > 0.2));
            c.set_scene(shown.set.clone()).unwrap();
            assert_mirrors(&f.image, &c.render(&cam, &o).unwrap().image, &format!("labels {raster}"));
            // Hidden, label 3 adds nothing: no blue, and the frame is the one without its voxels.
            g.set_scene(hidden.set.clone()).unwrap();
            let h = g.render(&cam, &o).unwrap().image;
            assert!(h.pixels.iter().all(|p| p[2] == 0.0), "{raster}: the hidden label drew");
            let mut without = seg.clone();
            without.values.iter_mut().filter(|v| **v == 3.0).for_each(|v| *v = 0.0);
            let alone = classify_labels(grid, &without, &table(true), None).unwrap();
            g.set_scene(alone.set).unwrap();
            let a = g.render(&cam, &o).unwrap().image;
            assert!(h.pixels == a.pixels, "{raster}: hiding a label differs from removing its voxels");
        }
    }
    assert_clean(&g);
}

#[test]
fn a_label_volume_over_a_scalar_volume_adds_their_emission_and_extinction() {
    let seg = segmentation();
    let grid = Grid::centered(DIMS, [1.0; 3]).unwrap();
    let scalar = common::blob(DIMS);
    let tf = common::blob_tf();
    let both = classify_labels(grid, &seg, &table(true), Some((&scalar, &tf, None))).unwrap().set;
    let alone = crate::classify::classify_on(grid, &scalar, &tf, None).unwrap();
    let tau = |a: f32| -(1.0 - a).ln();
    let mut checked = 0;
    for sp in both.splats() {
        let [i, j, k, _] = sp.ijk;
        let label = seg.values[(i + DIMS[0] * (j + DIMS[1] * k)) as usize];
        let under = alone.find(i, j, k).map(|s| alone.splats()[s].color);
        match (label, under) {
            (1.0, Some(s)) => {
                // Red label (opacity 0.6) over the scalar's voxel: optical depths add, colours weigh.
                let (ts, tl) = (tau(s[3]), tau(0.6));
                let want_a = 1.0 - (-(ts + tl)).exp();
                assert!((sp.color[3] - want_a).abs() < 1e-5, "{sp:?}");
                let want_r = (s[0] * ts + tl) / (ts + tl);
                assert!((sp.color[0] - want_r).abs() < 1e-5, "{sp:?} against {s:?}");
                assert_eq!(
                    f32::from_bits(sp.ijk[3]),
                    f32::from_bits(alone.splats()[alone.find(i, j, k).unwrap()].ijk[3])
                );
                checked += 1;
            }
            (0.0, Some(s)) => assert!(sp.color.iter().zip(s).all(|(a, b)| (a - b).abs() < 1e-6)),
            _ => {}
        }
    }
    assert!(checked > 50, "{checked} voxels of label 1 inside the blob");
}

#[test]
fn channels_combine_per_voxel_and_must_share_a_grid() {
    let grid = Grid::centered(DIMS, [1.0; 3]).unwrap();
    let a = common::blob(DIMS);
    let mut b = common::blob(DIMS);
    // The second channel lies only in the upper half.
    for k in 0..DIMS[2] / 2 {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                b.values[(i + DIMS[0] * (j + DIMS[1] * k)) as usize] = 0.0;
            }
        }
    }
    let red = TransferFunction::from_toml("points = [[0.1, [1, 0, 0, 0]], [1.0, [1, 0, 0, 0.5]]]").unwrap();
    let green = TransferFunction::from_toml("points = [[0.1, [0, 1, 0, 0]], [1.0, [0, 1, 0, 0.5]]]").unwrap();
    let set = classify_channels(grid, &[(&a, &red), (&b, &green)], None).unwrap();
    let only_a = crate::classify::classify_on(grid, &a, &red, None).unwrap();
    let (mut mixed, mut alone) = (0, 0);
    for sp in set.splats() {
        let [i, j, k, _] = sp.ijk;
        let ra = only_a.splats()[only_a.find(i, j, k).unwrap()].color;
        if k < DIMS[2] / 2 {
            assert_eq!(sp.color[..3], [1.0, 0.0, 0.0], "only the red channel below the middle");
            assert!((sp.color[3] - ra[3]).abs() < 1e-6);
            alone += 1;
        } else if sp.color[1] > 0.0 {
            // Both channels: opacity above either's, red and green in proportion to their depths.
            assert!(sp.color[3] > ra[3] && (sp.color[0] + sp.color[1] - 1.0).abs() < 1e-5, "{sp:?}");
            mixed += 1;
        }
    }
    assert!(mixed > 100 && alone > 100, "{mixed} mixed, {alone} red only");
    // Drawn, the GPU mirrors the CPU.
    let cam = Camera::framing(&grid, 64, 64);
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let mut c = cpu();
    c.set_scene(set).unwrap();
    let o = RenderOptions::default();
    assert_mirrors(&g.render(&cam, &o).unwrap().image, &c.render(&cam, &o).unwrap().image, "channels");
    assert_clean(&g);
    // Refused: channels on other grids, none, too many.
    let small = common::blob([8, 8, 8]);
    let e = classify_channels(grid, &[(&a, &red), (&small, &green)], None).unwrap_err().to_string();
    assert!(e.contains("channel 2") && e.contains("share one grid"), "{e}");
    assert!(classify_channels(grid, &[], None).is_err());
    let five: Vec<_> = (0..5).map(|_| (&a, &red)).collect();
    assert!(classify_channels(grid, &five, None).unwrap_err().to_string().contains("1 to 4"));
}

#[test]
fn label_tables_and_volumes_refuse_what_they_cannot_mean() {
    let grid = Grid::centered(DIMS, [1.0; 3]).unwrap();
    for (toml, says) in [
        ("[[label]]\nvalue = 1\ncolor = [1, 0, 0]\nopacity = 0.5\n[[label]]\nvalue = 1\ncolor = [0, 1, 0]\nopacity = 0.5", "listed twice"),
        ("[[label]]\nvalue = 1\ncolor = [2, 0, 0]\nopacity = 0.5", "[0, 1]"),
        ("[[label]]\nvalue = 1\ncolor = [1, 0]\nopacity = 0.5", "label table"),
        ("", "1 to"),
        ("[[label]]\nvalue = 99999999\ncolor = [1, 0, 0]\nopacity = 0.5", "past"),
    ] {
        let e = LabelTable::from_toml(toml).unwrap_err().to_string();
        assert!(e.contains(says), "{toml}: {e}");
    }
    let mut seg = segmentation();
    seg.values[5] = 1.5;
    let e = classify_labels(grid, &seg, &table(true), None).unwrap_err().to_string();
    assert!(e.contains("sample 5 is 1.5"), "{e}");
    let seg = segmentation();
    let other = Grid::centered([8, 8, 8], [1.0; 3]).unwrap();
    assert!(classify_labels(other, &seg, &table(true), None).is_err());
    let mut t = table(true);
    assert!(t.set_visible(9, false).is_err());
}

/// A NIfTI-1 file of `channels` u8 channels of `dims`, stored one after another: 4-D, or 5-D
/// with one frame.
fn nifti_channels(dims: [u32; 3], data: &[u8], channels: u16, five: bool) -> Vec<u8> {
    let mut f = common::nifti(dims, data, None, None);
    let rank: i16 = if five { 5 } else { 4 };
    f[40..42].copy_from_slice(&rank.to_le_bytes());
    let at = if five { 50 } else { 48 };
    f[at..at + 2].copy_from_slice(&(channels as i16).to_le_bytes());
    f
}

#[test]
fn a_four_d_nifti_reads_as_its_channels() {
    let dir = std::env::temp_dir().join(format!("voxsplat-channels-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dims = [6u32, 5, 4];
    let n = 120usize;
    let data: Vec<u8> = (0..3 * n).map(|i| (i % 251) as u8).collect();
    for (five, name) in [(false, "c.nii"), (true, "c5.nii")] {
        let path = dir.join(name);
        std::fs::write(&path, nifti_channels(dims, &data, 3, five)).unwrap();
        let vols = crate::loaders::load_channels(&path, &Default::default()).unwrap();
        assert_eq!(vols.len(), 3, "{name}");
        for (k, v) in vols.iter().enumerate() {
            assert_eq!(v.dims, dims);
            let want: Vec<f32> = data[k * n..(k + 1) * n].iter().map(|&b| b as f32).collect();
            assert_eq!(v.values, want, "{name}: channel {k}");
        }
        let e = crate::loaders::load_volume(&path, &Default::default()).unwrap_err().to_string();
        assert!(e.contains("holds 3 channels"), "{e}");
    }
    // Too many channels (a 5-D file's vector axis), and a file too short for its channels. A 4-D
    // file of 7 is a series of 7 time points (the standard's fourth axis is time;
    // tests/series.rs reads them).
    let many = dir.join("many.nii");
    std::fs::write(&many, nifti_channels(dims, &vec![0; 7 * n], 7, true)).unwrap();
    let e = crate::loaders::load_channels(&many, &Default::default()).unwrap_err().to_string();
    assert!(e.contains("2 to 4 channels"), "{e}");
    std::fs::write(&many, nifti_channels(dims, &vec![0; 7 * n], 7, false)).unwrap();
    let e = crate::loaders::load_channels(&many, &Default::default()).unwrap_err().to_string();
    assert!(e.contains("holds 7 time points"), "{e}");
    let short = dir.join("short.nii");
    std::fs::write(&short, nifti_channels(dims, &data[..2 * n], 3, false)).unwrap();
    let e = crate::loaders::load_channels(&short, &Default::default()).unwrap_err().to_string();
    assert!(e.contains("truncated"), "{e}");
    // A 3-D file is one channel.
    let one = dir.join("one.nii");
    std::fs::write(&one, common::nifti(dims, &data[..n], None, None)).unwrap();
    assert_eq!(crate::loaders::load_channels(&one, &Default::default()).unwrap().len(), 1);
    std::fs::remove_dir_all(&dir).ok();
}

/// A 4-D NRRD of u8 samples with `sizes` and extra header lines, raw data attached.
fn nrrd4(sizes: [usize; 4], extra: &str, data: &[u8]) -> Vec<u8> {
    let s = sizes.map(|d| d.to_string()).join(" ");
    let mut f = format!("NRRD0004\ntype: uint8\ndimension: 4\nsizes: {s}\n{extra}encoding: raw\n\n").into_bytes();
    f.extend_from_slice(data);
    f
}

#[test]
fn a_four_d_nrrd_reads_as_its_channels() {
    let dir = std::env::temp_dir().join(format!("voxsplat-nrrd-channels-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (dims, n) = ([6usize, 5, 4], 120usize);
    // Channel k of voxel v holds (v + 40 k) % 251.
    let value = |v: usize, k: usize| ((v + 40 * k) % 251) as u8;
    let interleaved: Vec<u8> = (0..n).flat_map(|v| (0..3).map(move |k| value(v, k))).collect();
    let planar: Vec<u8> = (0..3).flat_map(|k| (0..n).map(move |v| value(v, k))).collect();
    let cases = [
        ("first.nrrd", nrrd4([3, 6, 5, 4], "kinds: vector domain domain domain\nspacings: nan 1 2 3\n", &interleaved)),
        ("first-unmarked.nrrd", nrrd4([3, 6, 5, 4], "", &interleaved)),
        ("last.nrrd", nrrd4([6, 5, 4, 3], "kinds: domain domain domain list\n", &planar)),
    ];
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let vols = crate::loaders::load_channels(&path, &Default::default()).unwrap();
        assert_eq!(vols.len(), 3, "{name}");
        for (k, v) in vols.iter().enumerate() {
            assert_eq!(v.dims, dims.map(|d| d as u32), "{name}");
            let want: Vec<f32> = (0..n).map(|i| value(i, k) as f32).collect();
            assert_eq!(v.values, want, "{name}: channel {k}");
        }
        if name == "first.nrrd" {
            assert_eq!(vols[0].spacing, [1.0, 2.0, 3.0], "the channel axis's spacing is dropped");
        }
        let e = crate::loaders::load_volume(&path, &Default::default()).unwrap_err().to_string();
        assert!(e.contains("holds 3 channels"), "{name}: {e}");
    }
    // Five channels; a channel axis in the middle; four spatial-looking axes of which none is marked.
    for (name, bytes, says) in [
        ("five.nrrd", nrrd4([5, 6, 5, 4], "kinds: vector domain domain domain\n", &[0; 600]), "5 channels"),
        ("middle.nrrd", nrrd4([6, 3, 5, 4], "kinds: domain vector domain domain\n", &[0; 360]), "first or last"),
        ("unmarked.nrrd", nrrd4([6, 5, 7, 8], "", &[0; 1680]), "not marked"),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = crate::loaders::load_channels(&path, &Default::default()).unwrap_err().to_string();
        assert!(e.contains(says), "{name}: {e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
