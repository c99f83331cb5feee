//! Levels of detail over bricked volumes (issues 23-24): the pyramid stage and the coarse paths
//! of the brick stages against their CPU mirrors, the mixed-level sequence against the cell
//! validator over a random view battery, and the pyramid rebuilt when the classification
//! changes. Validation on: any message fails.
use super::common;
use super::probes::splat_stage;
use crate::classify::{Shading, TransferFunction};
use crate::plan::{pyramid_bytes, PYRAMID_BYTES, SLOTTED_LOD_BUFFERS, STREAMED_LOD_BUFFERS};
use crate::stages::{Res, StageId};
use crate::volume::ScalarVolume;
use crate::{Camera, Direction, Lod, Raster, RenderOptions, Renderer};
use common::{assert_clean, blob, blob_tf as tf, diff, random_camera, Rng, ViewKind};

fn lod(raster: Raster, direction: Direction, pixels: f32) -> RenderOptions {
    let mut o = RenderOptions::default();
    (o.raster, o.direction, o.lod, o.lod_pixels, o.lod_error) =
        (raster, Some(direction), Lod::Auto, pixels, crate::options::MAX_LOD_ERROR);
    o
}

/// The frame's cells in draw order, (i, j, k, side), read back once the splats are made.
fn drawn_cells(r: &mut Renderer, cam: &Camera, o: &RenderOptions) -> Vec<[u32; 4]> {
    let got = r.probe(cam, o, splat_stage(o), &[Res::BrickSlots, Res::BrickVoxels]).unwrap();
    let total: u32 = got[0].iter().filter(|&&w| w != 0).map(|&w| crate::bricks::slot_entry(w).2).sum();
    got[1]
        .chunks_exact(2)
        .take(total as usize)
        .map(|v| {
            let [i, j, k] = crate::cpu::brick::voxel_ijk([v[0], v[1]]);
            [i, j, k, 1 << crate::cpu::brick::voxel_level([v[0], v[1]])]
        })
        .collect()
}

#[test]
fn coarse_levels_match_the_cpu_mirrors_on_every_raster() {
    let vol = blob([45, 37, 29]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 80);
    let shading = Some(Shading::headlight(cam.forward()));
    let mut weighted = tf();
    weighted.gradient_weight = 0.5;
    for (tf, shading, what) in [(tf(), None, "plain"), (tf(), shading, "shaded"), (weighted, shading, "weighted")] {
        let (mut g, mut c) = (common::gpu(), common::cpu());
        g.set_volume(&vol, &tf, shading).unwrap();
        c.set_volume(&vol, &tf, shading).unwrap();
        // Two coarse levels in one frame: the pixel bound between the near and far bricks'.
        let mut mixed = None;
        for pixels in [2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0] {
            let o = lod(Raster::Graphics, Direction::BackToFront, pixels);
            let cells = drawn_cells(&mut g, &cam, &o);
            let sides: std::collections::BTreeSet<u32> = cells.iter().map(|c| c[3]).collect();
            assert_eq!(cells, drawn_cells(&mut c, &cam, &o), "{what}: GPU vs mirror cells");
            if sides.len() >= 2 && !sides.contains(&1) {
                mixed = Some(pixels);
                break;
            }
        }
        let pixels = mixed.unwrap_or_else(|| panic!("{what}: no bound mixes two coarse levels"));
        let o = lod(Raster::Graphics, Direction::BackToFront, pixels);
        let mut full = o.clone();
        full.lod = Lod::Off;
        let all = g.render(&cam, &full).unwrap().image;
        // Where nothing coarsens or morphs, levels of detail change no pixel.
        let mut fine = o.clone();
        fine.lod_pixels = 0.01;
        assert!(drawn_cells(&mut g, &cam, &fine).iter().all(|c| c[3] == 1), "{what}: all at full detail");
        assert_eq!(diff(&g.render(&cam, &fine).unwrap().image, &all).0, 0.0, "{what}: levels of detail, none coarse");
        for (raster, direction) in [
            (Raster::Compute, Direction::FrontToBack),
            (Raster::Compute, Direction::BackToFront),
            (Raster::Graphics, Direction::BackToFront),
            (Raster::Points, Direction::FrontToBack),
        ] {
            let o = lod(raster, direction, pixels);
            let a = g.render(&cam, &o).unwrap().image;
            let b = c.render(&cam, &o).unwrap().image;
            assert!(a.pixels.iter().any(|p| p[3] > 0.1), "{what} {raster:?}: something drawn");
            let (most, mean) = diff(&a, &b);
            assert!(most <= 2e-3 && mean <= 1e-5, "{what} {raster:?} {direction:?}: GPU vs mirror {most} / {mean}");
            if raster == Raster::Graphics {
                // The prefiltered levels stand for the voxels: close to full detail, not equal
                // (without morphing: each brick exactly at its level).
                let mut abrupt = o.clone();
                abrupt.lod_band = 0.0;
                let (most, mean) = diff(&g.render(&cam, &abrupt).unwrap().image, &all);
                assert!(mean > 1e-5 && mean <= 0.02, "{what}: coarse against full detail {most} / {mean}");
                let (most, mean) =
                    diff(&c.render(&cam, &abrupt).unwrap().image, &g.render(&cam, &abrupt).unwrap().image);
                assert!(most <= 2e-3 && mean <= 1e-5, "{what}: unmorphed GPU vs mirror {most} / {mean}");
            }
        }
        assert_clean(&g);
    }
}

#[test]
fn mixed_level_sequences_pass_the_cell_validator_on_both_engines() {
    let vol = blob([45, 37, 29]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let (mut g, mut c) = (common::gpu(), common::cpu());
    g.set_volume(&vol, &tf(), None).unwrap();
    c.set_volume(&vol, &tf(), None).unwrap();
    let mut rng = Rng(2424);
    let (mut views, mut mixed) = (0, 0);
    for kind in [ViewKind::Outside, ViewKind::Inside, ViewKind::OnGridPlane, ViewKind::Orthographic] {
        for v in 0..10 {
            let mut cam = random_camera(&mut rng, &grid, kind);
            if v % 3 == 0 {
                // The eye on a brick plane, or on a cell plane inside a brick.
                let a = v as usize % 3;
                cam.eye[a] = grid.origin[a] + (8.0 * (1 + v % 2) as f32 - 2.5 * (v % 2) as f32 - 0.5) * grid.spacing[a];
            }
            if cam.validate().is_err() {
                continue;
            }
            // Mix the levels: the pixel bound sits between the nearest and farthest bricks'.
            let pixels = [2.0, 4.0, 8.0, 30.0][v as usize % 4];
            for direction in [Direction::FrontToBack, Direction::BackToFront] {
                let o = lod(Raster::Graphics, direction, pixels);
                let cells = drawn_cells(&mut g, &cam, &o);
                assert_eq!(cells, drawn_cells(&mut c, &cam, &o), "{kind:?} {v}: GPU vs mirror sequence");
                let bad = crate::order::count_cell_violations(&grid, &cam, &cells, direction).unwrap();
                assert_eq!(bad, 0, "{kind:?} {v} {direction:?}: validator violations");
                let sides: std::collections::BTreeSet<u32> = cells.iter().map(|c| c[3]).collect();
                mixed += usize::from(sides.len() >= 2);
                views += 1;
            }
        }
    }
    assert!(views >= 60 && mixed >= 20, "{views} views, {mixed} with mixed levels");
    // The validator sees a wrong order: two cells that share a face, swapped.
    let cam = Camera::framing(&grid, 64, 64);
    let o = lod(Raster::Graphics, Direction::FrontToBack, 4.0);
    let mut cells = drawn_cells(&mut g, &cam, &o);
    let n = cells.len();
    cells.swap(0, n - 1);
    assert!(crate::order::count_cell_violations(&grid, &cam, &cells, Direction::FrontToBack).unwrap() > 0);
    assert_clean(&g);
}

#[test]
fn the_pyramid_follows_the_classification() {
    let vol = blob([45, 37, 29]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), 80, 64);
    let o = lod(Raster::Compute, Direction::FrontToBack, 6.0);
    let mut other = tf();
    other.points[1].1 = [0.2, 0.8, 0.3, 0.6];
    let shading = Some(Shading::headlight(cam.forward()));
    let mut g = common::gpu();
    g.set_volume(&vol, &tf(), None).unwrap();
    let first = g.render(&cam, &o).unwrap().image;
    for (tf, shading) in [(other.clone(), None), (other, shading), (tf(), None)] {
        g.set_transfer_function(&tf, shading).unwrap();
        let kept = g.render(&cam, &o).unwrap().image;
        let mut fresh = common::gpu();
        fresh.set_volume(&vol, &tf, shading).unwrap();
        let want = fresh.render(&cam, &o).unwrap().image;
        assert_eq!(diff(&kept, &want).0, 0.0, "the pyramid is rebuilt for the new classification");
        assert_clean(&fresh);
    }
    // Back to the first classification: the first frame again.
    assert_eq!(diff(&g.render(&cam, &o).unwrap().image, &first).0, 0.0);
    // A pyramid build is timed once per classification, not per frame.
    let stages = |r: &crate::Rendered| r.timings.iter().filter(|t| t.stage == "lod").count();
    assert_eq!(stages(&g.render(&cam, &o).unwrap()), 0);
    assert_clean(&g);
}

/// A constant-density cube (one empty corner voxel: the store keeps values above the minimum).
fn constant_cube(n: u32) -> (ScalarVolume, TransferFunction) {
    let mut values = vec![1.0; (n * n * n) as usize];
    values[0] = 0.0;
    let tf = TransferFunction {
        points: vec![(0.0, [0.8, 0.6, 0.4, 0.0]), (0.4, [0.8, 0.6, 0.4, 0.05]), (1.0, [0.8, 0.6, 0.4, 0.05])],
        gradient_weight: 0.0,
        range: Some((0.0, 2.0)),
        threshold: 0.0,
    };
    (ScalarVolume { dims: [n; 3], spacing: [1.0; 3], values }, tf)
}

/// Popping along a steady dolly, locally: the largest ratio between a frame-to-frame change and
/// the mean of its two neighbours (either way). A level switching abruptly makes one change jump
/// or dip against the changes around it; the dolly alone changes them smoothly. (The global score,
/// the largest change over the median, also follows the image's blur as levels coarsen.)
fn local_popping(frames: &[crate::ImageF32]) -> f64 {
    let c = crate::metrics::frame_changes(frames).unwrap();
    c.windows(3)
        .map(|w| {
            let around = 0.5 * (w[0] + w[2]);
            (w[1] / around).max(around / w[1])
        })
        .fold(1.0, f64::max)
}

#[test]
fn a_dolly_across_level_boundaries_changes_smoothly_with_morphing() {
    let vol = blob([40, 40, 40]);
    let mut g = common::gpu();
    g.set_volume(&vol, &tf(), None).unwrap();
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let mut dolly = |band: f32, lod: Lod| -> f64 {
        let mut frames = Vec::new();
        let mut o = RenderOptions::default();
        (o.raster, o.lod, o.lod_pixels, o.lod_error, o.lod_band) =
            (Raster::Compute, lod, 4.0, crate::options::MAX_LOD_ERROR, band);
        for f in 0..24 {
            let mut cam = Camera::framing(&grid, 96, 96);
            cam.target = glam::Vec3::ZERO;
            // A steady dolly: the projected size shrinks by the same ratio every frame.
            cam.eye = glam::Vec3::new(0.0, 0.0, 90.0 * 1.03f32.powi(f));
            cam.far = cam.eye.z + 60.0;
            frames.push(g.render(&cam, &o).unwrap().image);
        }
        local_popping(&frames)
    };
    let off = dolly(0.0, Lod::Off);
    let abrupt = dolly(0.0, Lod::Auto);
    let morphed = dolly(RenderOptions::default().lod_band, Lod::Auto);
    assert!(abrupt > 1.3 * off, "abrupt level changes pop: {abrupt} against full detail's {off}");
    assert!(morphed < abrupt && morphed <= 1.25 * off, "morphing: {morphed}, abrupt {abrupt}, full detail {off}");
    assert_clean(&g);
}

#[test]
fn level_boundaries_keep_the_brightness_of_a_constant_slab_and_cube() {
    // The slab seen obliquely (its depth varies across the face: level boundaries cross it), the
    // cube face on (front bricks finer than back ones: rays cross level boundaries).
    let views = [
        ("slab", [64u32, 64, 6], glam::Vec3::new(0.0, -45.0, 55.0)),
        ("cube", [48, 48, 48], glam::Vec3::new(0.0, 0.0, 70.0)),
    ];
    for (name, dims, eye) in views {
        let (mut vol, tf) = constant_cube(1);
        vol.dims = dims;
        vol.values = vec![1.0; (dims[0] * dims[1] * dims[2]) as usize];
        vol.values[0] = 0.0;
        let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
        let mut cam = Camera::framing(&grid, 128, 128);
        (cam.eye, cam.target, cam.near, cam.far) = (eye, glam::Vec3::ZERO, 1.0, 200.0);
        let mut g = common::gpu();
        g.set_volume(&vol, &tf, None).unwrap();
        let mut full = RenderOptions::default();
        full.raster = Raster::Compute;
        let a = g.render(&cam, &full).unwrap().image;
        // Away from the silhouette, where a coarse footprint is wider: in the middle half, pixels
        // whose neighbours 8 pixels away are all covered.
        let opaque = a.pixels.iter().map(|p| p[3]).fold(0.0f32, f32::max);
        let covered = |x: usize, y: usize| a.pixels[y * 128 + x][3] >= 0.5 * opaque;
        let inside = |i: usize| {
            let (x, y) = (i % 128, i / 128);
            (32..96).contains(&x)
                && (32..96).contains(&y)
                && [(x - 8, y), (x + 8, y), (x, y - 8), (x, y + 8)].iter().all(|&(x, y)| covered(x, y))
        };
        assert!((0..a.pixels.len()).filter(|&i| inside(i)).count() > 1000, "{name}: pixels compared");
        let (mut boundaries, mut abrupt_step) = (0, 0.0f32);
        for step in 0..10 {
            let pixels = 1.5 * 1.15f32.powi(step);
            for band in [0.0, RenderOptions::default().lod_band] {
                let mut o = full.clone();
                (o.lod, o.lod_pixels, o.lod_error, o.lod_band) =
                    (Lod::Auto, pixels, crate::options::MAX_LOD_ERROR, band);
                let cells = drawn_cells(&mut g, &cam, &o);
                let sides: std::collections::BTreeSet<u32> = cells.iter().map(|c| c[3]).collect();
                boundaries += usize::from(sides.len() >= 2);
                let b = g.render(&cam, &o).unwrap().image;
                // Against full detail, over 4x4-pixel tiles (full detail's own lattice ripple, a
                // period under 2 pixels, averages out): a seam or a crack at a level boundary is a
                // step in the ratio; a level's uniform bias is not.
                let mut ratios = Vec::new();
                for ty in (32..96).step_by(4) {
                    for tx in (32..96).step_by(4) {
                        let tile: Vec<usize> =
                            (0..16).map(|k| (ty + k / 4) * 128 + tx + k % 4).filter(|&i| inside(i)).collect();
                        if tile.len() == 16 {
                            let sum = |img: &crate::ImageF32| tile.iter().map(|&i| img.pixels[i][3]).sum::<f32>();
                            ratios.push(sum(&b) / sum(&a));
                        }
                    }
                }
                let (lo, hi) = ratios.iter().fold((f32::MAX, 0.0f32), |(lo, hi), &r| (lo.min(r), hi.max(r)));
                let mean = ratios.iter().sum::<f32>() / ratios.len() as f32;
                let what = format!("{name} {pixels} px band {band} levels {sides:?}");
                assert!((mean - 1.0).abs() <= 0.02, "{what}: brightness against full detail {mean}");
                if band > 0.0 {
                    assert!(hi - lo <= 0.01, "{what}: brightness against full detail spreads over {lo}..{hi}");
                } else if sides.len() >= 2 {
                    abrupt_step = abrupt_step.max(hi - lo);
                }
            }
        }
        assert!(boundaries >= 2, "{name}: views with a level boundary {boundaries}");
        if name == "slab" {
            // The check sees seams: abrupt level changes step by more than the bound.
            assert!(abrupt_step > 0.01, "slab: largest step at an abrupt level boundary {abrupt_step}");
        }
        assert_clean(&g);
    }
}

/// The alpha-weighted mean row of an image.
fn mean_row(img: &crate::ImageF32) -> f64 {
    let w = img.width as usize;
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (i, p) in img.pixels.iter().enumerate() {
        sum += (i / w) as f64 * p[3] as f64;
        weight += p[3] as f64;
    }
    sum / weight
}

/// A one-voxel 64 x 64 plate of constant colour and opacity, its transfer function and grid (a
/// store keeps the voxels above its minimum: one corner voxel is the empty value).
fn plate() -> (ScalarVolume, TransferFunction, crate::Grid) {
    let mut values = vec![1.0; 64 * 64];
    values[0] = 0.0;
    let vol = ScalarVolume { dims: [64, 64, 1], spacing: [1.0; 3], values };
    let mut plate = tf();
    plate.points = vec![(0.0, [0.9, 0.8, 0.7, 0.6]), (1.0, [0.9, 0.8, 0.7, 0.6])];
    plate.threshold = 0.0;
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    (vol, plate, grid)
}

#[test]
fn a_coarse_cell_the_grid_end_cuts_sits_on_the_voxels_it_holds() {
    // A one-voxel plate seen from 17 degrees above, orthographic (a wider footprint grows the
    // plate's image alike at both ends): its coarse cells span one voxel of their 2-8 in z, and a
    // centre at the cell's middle would lift the plate by up to 3.5 voxels.
    let (vol, plate, grid) = plate();
    let mut cam = Camera::framing(&grid, 96, 96);
    cam.eye = grid.center() + glam::Vec3::new(0.0, -110.0, 34.0);
    cam.projection = crate::camera::Projection::Orthographic { height: 80.0 };
    // Planes well clear of the plate: splats within 1.5 radii of one are dropped.
    (cam.near, cam.far) = (1.0, 1000.0);
    for mut r in [common::gpu(), common::cpu()] {
        r.set_volume(&vol, &plate, None).unwrap();
        let fine = lod(Raster::Compute, Direction::BackToFront, crate::options::MAX_LOD_PIXELS);
        let mut full = fine.clone();
        full.lod = Lod::Off;
        let cells = drawn_cells(&mut r, &cam, &fine);
        // Level 3, or a node above the brick (cells of 16-64 voxels; also one voxel thick).
        assert!(!cells.is_empty() && cells.iter().all(|c| c[3] >= 8), "every cell at level 3 or above");
        let (a, b) = (r.render(&cam, &full).unwrap().image, r.render(&cam, &fine).unwrap().image);
        let shift = mean_row(&b) - mean_row(&a);
        assert!(shift.abs() < 0.5, "the coarse plate moved {shift:.2} rows");
        assert_clean(&r);
    }
}

#[test]
fn a_streamed_store_draws_the_levels_a_resident_one_draws() {
    // A small image: its frame buffers leave the pyramid room under a budget the store streams in.
    const SIDE: u32 = 32;
    let vol = blob([80, 72, 64]);
    let cam = Camera::framing(&crate::Grid::centered(vol.dims, vol.spacing).unwrap(), SIDE, SIDE);
    let mut other = tf();
    other.points[1].1[3] *= 0.5;
    let mut frames = Vec::new();
    for gpu in [true, false] {
        let mut resident = if gpu { common::gpu() } else { common::cpu() };
        resident.set_volume(&vol, &tf(), None).unwrap();
        let records = resident.volume().unwrap().store.records.len() as u64 * 4;
        // Under twice the records the store streams, in several batches: its pyramid resident,
        // and under a budget where the pyramid would take more than half the room, only the
        // summaries, each batch building its coarse bricks' pyramids.
        let scene = resident.volume().unwrap();
        let headers = scene.store.headers.len();
        let per_batch = crate::plan::bricked_min_budget(scene, records, SIDE, SIDE)
            + pyramid_bytes(STREAMED_LOD_BUFFERS, headers)
            + 64 * PYRAMID_BYTES;
        // The resident pyramid built in one batch, and in several (room for it and under all
        // the records).
        let slotted = pyramid_bytes(SLOTTED_LOD_BUFFERS, headers);
        let several = crate::plan::bricked_resident_bytes(scene, 2 * records - 1, SIDE, SIDE) + 2 * slotted;
        assert!(slotted < records, "the pyramid and a batch leave less room than the records take");
        let budgets = [2 * records - 1, several, per_batch];
        for (k, &budget) in budgets.iter().enumerate() {
            let room = budget - crate::plan::bricked_resident_bytes(scene, budget, SIDE, SIDE);
            assert!(scene.streams(budget));
            assert_eq!(slotted <= room / 2, k < 2, "{budget}");
        }
        let mut streamed: Vec<Renderer> = budgets
            .iter()
            .map(|&budget| {
                let mut r = if gpu { common::gpu() } else { common::cpu() };
                r.set_gpu_budget(budget).unwrap();
                r.set_volume(&vol, &tf(), None).unwrap();
                r
            })
            .collect();
        let mut levels = std::collections::BTreeSet::new();
        for pixels in [0.5, 1.0, 2.0] {
            levels.extend(
                drawn_cells(&mut resident, &cam, &lod(Raster::Compute, Direction::BackToFront, pixels))
                    .iter()
                    .map(|c| c[3]),
            );
            for (raster, direction) in [
                (Raster::Compute, Direction::FrontToBack),
                (Raster::Compute, Direction::BackToFront),
                (Raster::Graphics, Direction::BackToFront),
            ] {
                let o = lod(raster, direction, pixels);
                let a = resident.render(&cam, &o).unwrap().image;
                assert!(a.pixels.iter().any(|p| p[3] > 0.1));
                for (k, s) in streamed.iter_mut().enumerate() {
                    let b = s.render(&cam, &o).unwrap().image;
                    assert!(a.pixels == b.pixels, "gpu {gpu} {pixels} px {raster:?} {direction:?} budget {k}: differs");
                    frames.push(b);
                }
            }
        }
        assert!(levels.len() >= 3, "gpu {gpu}: levels drawn {levels:?}");
        // A new classification: the streamed summaries are rebuilt.
        resident.set_transfer_function(&other, None).unwrap();
        let o = lod(Raster::Compute, Direction::BackToFront, 1.0);
        let a = resident.render(&cam, &o).unwrap().image;
        for s in &mut streamed {
            s.set_transfer_function(&other, None).unwrap();
            assert!(a.pixels == s.render(&cam, &o).unwrap().image.pixels, "gpu {gpu}: after a TF change");
            if gpu {
                assert_clean(s);
            }
        }
        if gpu {
            assert_clean(&resident);
        }
    }
    // The GPU's streamed frames are the mirror's.
    let n = frames.len() / 2;
    for (g, c) in frames[..n].iter().zip(&frames[n..]) {
        let (most, _) = diff(g, c);
        assert!(most <= 2e-3, "GPU vs mirror, streamed: {most}");
    }
}

#[test]
fn no_level_is_taken_whose_splats_the_near_plane_would_drop() {
    // A plate 20 units in front of the eye, the near plane at 1: level-3 splats (eight voxels
    // wide) reach past the near plane and would all be dropped; the cut keeps finer levels there.
    let (vol, plate, grid) = plate();
    let mut cam = Camera::framing(&grid, 64, 64);
    cam.eye = grid.center() + glam::Vec3::new(0.0, 0.0, 20.0);
    (cam.near, cam.far) = (1.0, 1000.0);
    let coverage = |img: &crate::ImageF32| img.pixels.iter().map(|p| p[3] as f64).sum::<f64>();
    for mut r in [common::gpu(), common::cpu()] {
        r.set_volume(&vol, &plate, None).unwrap();
        let coarse = lod(Raster::Compute, Direction::BackToFront, crate::options::MAX_LOD_PIXELS);
        let mut full = coarse.clone();
        full.lod = Lod::Off;
        let (a, b) = (r.render(&cam, &full).unwrap().image, r.render(&cam, &coarse).unwrap().image);
        assert!(coverage(&a) > 1000.0);
        let ratio = coverage(&b) / coverage(&a);
        assert!((ratio - 1.0).abs() < 0.05, "coverage with levels of detail over full detail: {ratio}");
        // Far from the planes the same cut takes the coarsest level.
        cam.eye = grid.center() + glam::Vec3::new(0.0, 0.0, 200.0);
        let far = drawn_cells(&mut r, &cam, &coarse);
        assert!(!far.is_empty() && far.iter().all(|c| c[3] >= 8), "level 3 or a node away from the planes");
        cam.eye = grid.center() + glam::Vec3::new(0.0, 0.0, 20.0);
        assert_clean(&r);
    }
}

/// Opaque one-voxel rods along z on a 4-voxel lattice in x and y (every 16th column), 32³.
fn rods() -> (ScalarVolume, TransferFunction, crate::Grid) {
    let n = 32u32;
    let mut values = Vec::new();
    for _k in 0..n {
        for j in 0..n {
            for i in 0..n {
                values.push(if i % 4 == 1 && j % 4 == 1 { 1.0 } else { 0.0 });
            }
        }
    }
    let vol = ScalarVolume { dims: [n; 3], spacing: [1.0; 3], values };
    let mut rod = tf();
    rod.points = vec![(0.0, [0.0; 4]), (0.5, [0.0; 4]), (0.6, [0.8, 0.7, 0.6, 0.999]), (1.0, [0.8, 0.7, 0.6, 0.999])];
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    (vol, rod, grid)
}

#[test]
fn coarse_cells_cover_what_their_voxels_cover_along_each_axis() {
    // Seen along a rod, a level-1 cell holding one (a 2x2 column of voxels, one of them filled)
    // covers a quarter of its footprint; seen across, half. Averaging optical depth over the cell
    // instead would make it near-opaque both ways (1 - e^(-tau/2) = 0.97 for these rods). (Levels
    // 2 and 3 compose their children as if independent: a rod running through two children
    // covers more than its share there.)
    let (vol, rod, grid) = rods();
    let cam = Camera::framing(&grid, 64, 64);
    let o = lod(Raster::Compute, Direction::FrontToBack, crate::options::MAX_LOD_PIXELS);
    let (mut g, mut c) = (common::gpu(), common::cpu());
    let mut cells = Vec::new();
    for r in [&mut g, &mut c] {
        r.set_volume(&vol, &rod, None).unwrap();
        cells.push(r.probe(&cam, &o, StageId::BrickPyramid, &[Res::Pyramid]).unwrap().remove(0));
    }
    // 64 bricks, all holding rods.
    let words = 64 * crate::plan::SLOT_CELLS * crate::plan::CELL_WORDS;
    assert!(cells[0][..words] == cells[1][..words], "GPU vs mirror pyramid");
    let alpha = |code: u32| 1.0 - (-crate::cpu::lod::tau_decode(code)).exp();
    let pyramid = &cells[0];
    let a0 = 1.0 - (1.0f32 - 0.999).powi(2);
    // Level 1 of brick 0: cell (0, 0, z) holds voxel column (1, 1) of its 2x2 (i, j).
    for (cell, along_z, across) in [(0u32, a0 / 4.0, 0.999 / 2.0), (1, 0.0, 0.0)] {
        let w = &pyramid[cell as usize * 3..cell as usize * 3 + 3];
        let (x, y, z) = (alpha(w[0] & 0xffff), alpha(w[0] >> 16), alpha(w[1] & 0xffff));
        for (got, want, axis) in [(x, across, "x"), (y, across, "y"), (z, along_z, "z")] {
            assert!((got - want).abs() < 2e-3, "cell {cell} along {axis}: opacity {got}, want {want}");
        }
    }
    assert_clean(&g);
}

/// Dropping hidden bricks between waves over mixed levels, the eye outside and inside the volume:
/// the frame is the one drawn without dropping any, bit for bit, and some views drop bricks. (The
/// culled sequence is the full one less whole bricks, so the cell validator's verdict on the full
/// sequence, `mixed_level_sequences_pass_the_cell_validator_on_both_engines`, holds for it.)
#[test]
fn hidden_bricks_dropped_over_mixed_levels_change_no_pixel_eye_inside_too() {
    let vol = blob([96, 80, 72]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let opaque = TransferFunction { points: vec![(0.05, [0.0; 4]), (0.1, [0.8, 0.5, 0.3, 0.95])], ..tf() };
    let mut rng = Rng(4343);
    for gpu in [true, false] {
        let mut r = if gpu { common::gpu() } else { common::cpu() };
        r.set_volume(&vol, &opaque, None).unwrap();
        let (mut views, mut dropping, mut mixed) = (0, 0, 0);
        for kind in [ViewKind::Outside, ViewKind::Inside] {
            for v in 0..4 {
                let mut cam = random_camera(&mut rng, &grid, kind);
                (cam.width, cam.height) = (160, 160);
                if cam.validate().is_err() {
                    continue;
                }
                let mut o = lod(Raster::Compute, Direction::FrontToBack, [1.5, 3.0][v % 2]);
                (o.early_termination, o.lod_error) = (1.0 / 1024.0, 0.1);
                let culled = r.render(&cam, &o).unwrap();
                o.cull_hidden_bricks = false;
                let kept = r.render(&cam, &o).unwrap();
                assert!(
                    culled.image.pixels == kept.image.pixels,
                    "gpu {gpu} {kind:?} {v}: dropping hidden bricks changed the frame ({:?})",
                    culled.stats
                );
                let st = culled.stats;
                views += 1;
                dropping += usize::from(st.bricks_hidden > 0);
                mixed += usize::from(st.bricks_coarse > 0 && st.bricks_coarse < st.bricks_visible);
            }
        }
        assert!(
            views >= 6 && dropping >= 2 && mixed >= 2,
            "gpu {gpu}: {views} views, {dropping} dropped bricks, {mixed} mixed"
        );
        if gpu {
            assert_clean(&r);
        }
    }
}

/// Levels above the brick: a volume seen small draws each node of 2^k bricks a side whose one
/// cell passes the cut as one splat, listed by the first of its bricks that draws. A uniform cube
/// (nothing to lose by coarsening it) seen at thumbnail sizes: the GPU's nodes are the mirror's bit
/// for bit and its frames and statistics the mirror's; nodes are drawn, and far fewer splats than
/// bricks.
#[test]
fn nodes_above_the_brick_draw_a_volume_seen_small() {
    let mut values = vec![1.0; 64 * 64 * 64];
    values[0] = 0.0;
    let vol = ScalarVolume { dims: [64, 64, 64], spacing: [1.0; 3], values };
    let mut cube = tf();
    cube.points = vec![(0.0, [0.9, 0.6, 0.3, 0.05]), (1.0, [0.9, 0.6, 0.3, 0.05])];
    cube.threshold = 0.0;
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let (mut g, mut c) = (common::gpu(), common::cpu());
    for r in [&mut g, &mut c] {
        r.set_volume(&vol, &cube, None).unwrap();
    }
    let mut o = RenderOptions::default();
    // Sizes alone choose: this tests the nodes' machinery (mirror, statistics, order). With the
    // error test on, the cube's faces (a full cell beside the empty outside) keep every node from
    // standing in for it at these sizes: its one footprint would blur the cube's silhouette.
    (o.lod, o.lod_nodes, o.lod_error) = (Lod::Auto, true, crate::options::MAX_LOD_ERROR);
    let mut full = o.clone();
    (full.lod, full.lod_nodes) = (Lod::Off, false);
    let mut drawn = 0;
    for size in [3u32, 4, 6, 8] {
        let mut cam = Camera::framing(&grid, size, size);
        // The planes well clear of the cube: a node's splats (anti-aliased: a pixel wide, a good
        // part of the cube here) must keep clear of both.
        (cam.near, cam.far) = (1.0, cam.far * 4.0);
        let nodes: Vec<Vec<u32>> = [&mut g, &mut c]
            .map(|r| r.probe(&cam, &o, StageId::BrickNodes, &[Res::LodSummary]).unwrap().remove(0))
            .into();
        // The nodes, after the bricks' summaries (whose float sums differ from the mirror's in the
        // last bits: exp and log): packed fields within a step, sums within 1e-4, the brick exact.
        let at = 512 * crate::plan::SUMMARY_WORDS;
        let words = crate::plan::NODE_WORDS;
        let fields = |w: u32, i: usize| match i {
            0 | 1 => vec![w & 0xffff, w >> 16],
            2 => vec![w & 1023, w >> 10 & 1023, w >> 20 & 1023],
            _ => vec![w],
        };
        let near = |a: u32, b: u32, i: usize| match i {
            3 | 4 => (f32::from_bits(a) - f32::from_bits(b)).abs() <= 1e-4 * f32::from_bits(a).abs().max(1e-2),
            5 | 6 => a == b,
            _ => fields(a, i).iter().zip(fields(b, i)).all(|(x, y)| x.abs_diff(y) <= 1),
        };
        // 4³ + 2³ + 1 nodes over the 8³ bricks.
        let n = crate::plan::node_words([8; 3], 3) as usize;
        assert_eq!(n, 73 * words);
        for (i, (x, y)) in nodes[0][at..at + n].iter().zip(&nodes[1][at..at + n]).enumerate() {
            assert!(
                near(*x, *y, i % words),
                "{size}: node {} word {}: GPU {x:#x}, mirror {y:#x}",
                i / words,
                i % words
            );
        }
        let (a, b) = (g.render(&cam, &o).unwrap(), c.render(&cam, &o).unwrap());
        let (most, _) = diff(&a.image, &b.image);
        assert!(most <= 2e-3, "{size}: GPU vs mirror frame {most}");
        let st = a.stats;
        assert_eq!(st, b.stats, "{size}: GPU vs mirror statistics");
        // What the nodes cover against full detail is measured, not bounded, here: at 3-8 pixels
        // the footprints' anti-aliasing dominates (docs/log/2026-11-28-thumbnails-and-nodes.md).
        let f = g.render(&cam, &full).unwrap().image;
        let coverage = |i: &crate::ImageF32| i.pixels.iter().map(|p| p[3] as f64).sum::<f64>();
        eprintln!("{size}: coverage {:.3} of full detail's ({st:?})", coverage(&a.image) / coverage(&f));
        // Each node draws at its first drawing brick's place in the brick order: the cell
        // validator checks that order against every face two drawn cells share.
        for direction in [Direction::FrontToBack, Direction::BackToFront] {
            let mut o = o.clone();
            o.direction = Some(direction);
            let cells = drawn_cells(&mut g, &cam, &o);
            let bad = crate::order::count_cell_violations(&grid, &cam, &cells, direction).unwrap();
            assert_eq!(bad, 0, "{size} {direction:?}: validator violations over nodes");
        }
        drawn += usize::from(st.nodes > 0 && st.splats < st.bricks as u64 / 4);
    }
    assert!(drawn >= 2, "nodes drawn at {drawn} of 4 sizes");
    assert_clean(&g);
}

/// Nodes above the brick keep the order a visibility order: a node draws at one of its bricks'
/// places, which is right only where its bricks are consecutive in the brick order (a k-d box, or
/// an aligned block inside a leaf, whose bricks follow an octree). Random views of a blob at
/// thumbnail sizes with the error bound lifted, so nodes of several levels mix with bricks: the
/// cell validator finds no violation on either engine, and GPU and mirror draw the same sequence.
#[test]
fn nodes_above_the_brick_keep_a_visibility_order() {
    let vol = blob([128, 112, 96]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let (mut g, mut c) = (common::gpu(), common::cpu());
    g.set_volume(&vol, &tf(), None).unwrap();
    c.set_volume(&vol, &tf(), None).unwrap();
    let mut rng = Rng(5151);
    let (mut views, mut with_nodes) = (0, 0);
    for kind in [ViewKind::Outside, ViewKind::Orthographic] {
        for v in 0..6 {
            let mut cam = random_camera(&mut rng, &grid, kind);
            let size = [4u32, 6, 8, 12, 16, 24][v];
            (cam.width, cam.height) = (size, size);
            (cam.near, cam.far) = (cam.near.min(1.0), cam.far * 4.0);
            if cam.validate().is_err() {
                continue;
            }
            for direction in [Direction::FrontToBack, Direction::BackToFront] {
                let mut o = lod(Raster::Compute, direction, 1.5);
                o.lod_nodes = true;
                let cells = drawn_cells(&mut g, &cam, &o);
                assert_eq!(cells, drawn_cells(&mut c, &cam, &o), "{kind:?} {v}: GPU vs mirror sequence");
                let bad = crate::order::count_cell_violations(&grid, &cam, &cells, direction).unwrap();
                assert_eq!(bad, 0, "{kind:?} {v} {direction:?}: validator violations");
                with_nodes += usize::from(cells.iter().any(|c| c[3] > 8));
                views += 1;
            }
        }
    }
    assert!(views >= 16 && with_nodes >= 6, "{views} views, {with_nodes} with nodes");
    assert_clean(&g);
}

/// A resident pyramid builds in parts, each its own dispatch: `render_to_with_progress` hears of
/// each once it has run, rising to every brick; a frame with the pyramid built hears nothing; an
/// error from the hook stops the frame (the next builds it all); the frame is `render_to`'s.
#[test]
fn the_pyramid_builds_in_parts_and_says_how_far_it_has_got() {
    use crate::vk::ImageLayout as IL;
    let gz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/bonsai/bonsai.nii.gz");
    let store = crate::bricks::BrickStore::load(&gz, &Default::default()).unwrap();
    let tf = TransferFunction::preset("bonsai").unwrap();
    let (mut a, mut b) = (common::gpu(), common::gpu());
    a.set_bricks(crate::bricks::BrickScene::new(store.clone(), tf.clone(), None).unwrap()).unwrap();
    b.set_bricks(crate::bricks::BrickScene::new(store, tf, None).unwrap()).unwrap();
    let bricks = a.volume().unwrap().store.headers.len() as u64;
    assert!(bricks > 2 * 4096, "several parts: {bricks} bricks");
    let cam = Camera::framing(&a.volume().unwrap().store.grid().unwrap(), 40, 40);
    let o = RenderOptions::default();
    assert_eq!(o.lod, Lod::Auto);
    let format = crate::TargetFormat::Rgba16Float;
    let (ia, ib) = (a.target_image(format, 40, 40).unwrap(), b.target_image(format, 40, 40).unwrap());
    let (ta, tb) = (
        ia.target(IL::UNDEFINED, IL::TRANSFER_SRC_OPTIMAL).unwrap(),
        ib.target(IL::UNDEFINED, IL::TRANSFER_SRC_OPTIMAL).unwrap(),
    );
    let mut heard = Vec::new();
    for _ in 0..2 {
        a.render_to_with_progress(&cam, &o, &ta, &mut |done, of| {
            heard.push((done, of));
            Ok(())
        })
        .unwrap();
    }
    // All from the first frame: the second found the pyramid built.
    assert!(heard.len() >= 3, "{heard:?}");
    assert!(heard.windows(2).all(|w| w[0].0 < w[1].0) && heard.iter().all(|h| h.1 == bricks), "{heard:?}");
    assert_eq!(heard.last(), Some(&(bricks, bricks)));
    let mut parts = 0;
    let stop = b.render_to_with_progress(&cam, &o, &tb, &mut |_, _| {
        parts += 1;
        Err(crate::Error::InvalidArgument("stop".into()))
    });
    assert!(parts == 1 && stop.is_err_and(|e| e.to_string().contains("stop")));
    b.render_to(&cam, &o, &tb).unwrap();
    assert!(a.read_target(&ta).unwrap() == b.read_target(&tb).unwrap(), "the same frame");
    // Every part built its own bricks: the summaries are the CPU mirror's, brick for brick
    // (one word each of what levels it draws, then its levels' errors).
    let mut c = common::cpu();
    c.set_bricks(
        crate::bricks::BrickScene::new(
            b.volume().unwrap().store.clone(),
            TransferFunction::preset("bonsai").unwrap(),
            None,
        )
        .unwrap(),
    )
    .unwrap();
    let what = [Res::LodSummary];
    let (gpu, cpu) = (
        b.probe(&cam, &o, StageId::BrickPyramid, &what).unwrap(),
        c.probe(&cam, &o, StageId::BrickPyramid, &what).unwrap(),
    );
    let words = crate::plan::SUMMARY_WORDS;
    let differ = (0..bricks as usize).filter(|&h| gpu[0][h * words] != cpu[0][h * words]).count();
    let built = (0..bricks as usize).filter(|&h| cpu[0][h * words] != 0).count();
    let later = (2 * 4096..bricks as usize).filter(|&h| cpu[0][h * words] != 0).count();
    assert!(later > 500, "the third part builds {later} bricks that draw");
    assert!(differ * 1000 <= built, "{differ} of {built} bricks' levels differ");
    assert_clean(&a);
    assert_clean(&b);
}

/// Each stored brick's summary (drawn cells, then levels 1-3's errors) from the mirror, after
/// checking the device's against it: the drawn cells exactly, the errors to 1e-4.
fn summaries_match_the_mirror(g: &mut Renderer, c: &mut Renderer, cam: &Camera, o: &RenderOptions) -> Vec<[u32; 4]> {
    let summaries: Vec<Vec<u32>> =
        [g, c].map(|r| r.probe(cam, o, StageId::BrickPyramid, &[Res::LodSummary]).unwrap().remove(0)).into();
    let words = crate::plan::SUMMARY_WORDS;
    // One summary per stored brick (the empty ones have no header).
    (0..summaries[1].len() / words)
        .map(|h| {
            let [gs, cs] = [&summaries[0], &summaries[1]].map(|s| &s[h * words..h * words + 4]);
            assert_eq!(gs[0], cs[0], "brick {h}: drawn cells");
            for l in 1..4 {
                let (a, b) = (f32::from_bits(gs[l]), f32::from_bits(cs[l]));
                assert!(
                    (a - b).abs() <= 1e-4 * b.abs().max(1e-2),
                    "brick {h} level {l}: error {a} on the device, {b} mirror"
                );
            }
            [cs[0], cs[1], cs[2], cs[3]]
        })
        .collect()
}

/// A ball of 20 voxels' radius on a 24³ grid, each voxel repeated 2x2x2 (48³): every aligned
/// level-1 cell is constant, so only its neighbours tell a silhouette from the inside.
fn blocky_ball() -> ScalarVolume {
    let mut values = vec![0.0; 48 * 48 * 48];
    for (i, v) in values.iter_mut().enumerate() {
        let c = [i % 48, i / 48 % 48, i / 2304].map(|x| (x / 2) as f32 - 11.5);
        if c.iter().map(|x| x * x).sum::<f32>() < 10.0 * 10.0 {
            *v = 1.0;
        }
    }
    ScalarVolume { dims: [48; 3], spacing: [1.0; 3], values }
}

#[test]
fn the_cut_sees_a_blocky_silhouette_and_its_errors_are_the_mirror_s() {
    let vol = blocky_ball();
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let cam = Camera::framing(&grid, 40, 40);
    let (mut g, mut c) = (common::gpu(), common::cpu());
    for r in [&mut g, &mut c] {
        r.set_volume(&vol, &tf(), None).unwrap();
    }
    let o = RenderOptions::default();
    let (mut edges, mut inside) = (0, 0);
    for cs in summaries_match_the_mirror(&mut g, &mut c, &cam, &o) {
        let level1 = f32::from_bits(cs[1]);
        if cs[0] & 0xff == 64 {
            // Every level-1 cell drawn: the brick lies inside the ball (the children agree).
            inside += usize::from(level1 < 1e-6);
        } else if cs[0] & 0xff > 0 {
            // A brick the silhouette crosses: an opaque cell beside an empty one.
            edges += usize::from(level1 > 0.5);
        }
    }
    assert!(inside > 0 && edges > 20, "bricks inside with no error {inside}, on the silhouette with one {edges}");
    // The frames the default cut draws are the mirror's.
    assert_eq!(drawn_cells(&mut g, &cam, &o), drawn_cells(&mut c, &cam, &o));
    let (a, b) = (g.render(&cam, &o).unwrap().image, c.render(&cam, &o).unwrap().image);
    assert!(diff(&a, &b).0 <= 2e-3, "device against mirror {}", diff(&a, &b).0);
    assert_clean(&g);
}

/// 48³ along x: a ramp in value (the TF faint, so optical depth rises nearly linearly) or a step
/// at x = 20 (inside a brick, on a level-1 and a level-2 cell face); one corner voxel at the
/// minimum, so the store keeps every other voxel.
fn along_x(step: bool) -> (ScalarVolume, TransferFunction) {
    let n = 48;
    let mut values: Vec<f32> = (0..n * n * n)
        .map(|i| {
            let x = (i % n) as f32;
            if step {
                if x < 20.0 {
                    0.2
                } else {
                    1.0
                }
            } else {
                0.2 + 0.8 * x / (n - 1) as f32
            }
        })
        .collect();
    values[0] = 0.0;
    let tf = TransferFunction {
        points: vec![(0.0, [0.8, 0.8, 0.8, 0.0]), (1.0, [0.8, 0.8, 0.8, 0.04])],
        gradient_weight: 0.0,
        range: Some((0.0, 1.0)),
        threshold: 0.0,
    };
    (ScalarVolume { dims: [n as u32; 3], spacing: [1.0; 3], values }, tf)
}

#[test]
fn a_ramp_is_not_an_edge_and_a_step_is() {
    // Opacity over a brick's side (8 voxels) of optical depth tau per voxel: the error's measure.
    let seen = |value: f32| 1.0 - (-8.0 * -(1.0 - 0.04 * value).ln()).exp();
    let mut most = [0.0f32; 2];
    let mut least = [f32::MAX; 2];
    for (k, step) in [false, true].into_iter().enumerate() {
        let (vol, tf) = along_x(step);
        let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
        let cam = Camera::framing(&grid, 40, 40);
        let (mut g, mut c) = (common::gpu(), common::cpu());
        for r in [&mut g, &mut c] {
            r.set_volume(&vol, &tf, None).unwrap();
        }
        for cs in summaries_match_the_mirror(&mut g, &mut c, &cam, &RenderOptions::default()) {
            let level1 = f32::from_bits(cs[1]);
            (most[k], least[k]) = (most[k].max(level1), least[k].min(level1));
        }
        assert_clean(&g);
    }
    // Two voxels apart along the ramp (a level-1 cell's neighbour), mid-volume.
    let neighbour = seen(0.2 + 0.8 * 25.0 / 47.0) - seen(0.2 + 0.8 * 23.0 / 47.0);
    // Inside the volume a ramp brick's level 1 departs only inside its cells (half a voxel's
    // rise, over a brick's side); compared with the cell itself, each neighbour departed by two.
    assert!(
        least[0] > 0.0 && least[0] < 0.5 * neighbour,
        "ramp: level-1 error {} against a neighbour's {neighbour}",
        least[0]
    );
    // The step's bricks: its whole rise.
    let rise = seen(1.0) - seen(0.2);
    eprintln!("level-1 errors: ramp {} (a neighbour {neighbour}), step {} (its rise {rise})", least[0], most[1]);
    assert!(most[1] >= 0.9 * rise, "step: level-1 error {} against its rise {rise}", most[1]);
}

/// A ball of two materials (a ramp's 0.5 and 1.0) meeting at the plane x = `plane`, on a 128³ grid.
fn two_materials(plane: usize) -> ScalarVolume {
    let n = 128;
    let values = (0..n * n * n)
        .map(|i| {
            let p = [i % n, i / n % n, i / (n * n)].map(|x| x as f32 + 0.5 - 64.0);
            if p.iter().map(|x| x * x).sum::<f32>() >= 50.0 * 50.0 {
                0.0
            } else if i % n < plane {
                0.5
            } else {
                1.0
            }
        })
        .collect();
    ScalarVolume { dims: [n as u32; 3], spacing: [1.0; 3], values }
}

/// Where two materials meet at a brick face, the voxels past it are not resident in a streamed
/// store, and the pyramid took them to be the cell's own: every brick on either side coarsened and
/// blurred the edge (at 128² of the same ball at 256³, 26.7 dB from full detail against 39.0 with
/// the plane two voxels inside a brick). The brick past the face has its value range resident, and
/// a cell whose value lies outside it sees the step. Seen edge-on, the plane at a face (x = 64)
/// must draw as close to full detail as the plane inside a brick (x = 66), on both engines.
#[test]
fn an_edge_between_materials_at_a_brick_face_is_seen() {
    let tf = TransferFunction::preset("ramp").unwrap();
    let mut psnr = Vec::new();
    for plane in [64, 66] {
        let vol = two_materials(plane);
        let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
        let [lo, hi] = grid.world_box(glam::Vec3::ZERO, glam::Vec3::splat(127.0));
        let cam = Camera::framing_box(lo, hi, 1.0, glam::Vec3::Y, glam::Vec3::Z, 64, 64);
        let (mut g, mut c) = (common::gpu(), common::cpu());
        for r in [&mut g, &mut c] {
            r.set_volume(&vol, &tf, None).unwrap();
        }
        let o = RenderOptions::default();
        let mut full = RenderOptions::default();
        full.lod = Lod::Off;
        let (a, b) = (g.render(&cam, &o).unwrap().image, g.render(&cam, &full).unwrap().image);
        let m = crate::metrics::compare(&a, &b).unwrap();
        let mirror = c.render(&cam, &o).unwrap().image;
        assert!(diff(&a, &mirror).0 <= 2e-3, "plane {plane}: device against mirror {}", diff(&a, &mirror).0);
        assert!(drawn_cells(&mut g, &cam, &o).iter().any(|s| s[3] > 1), "plane {plane}: levels engage");
        assert_clean(&g);
        psnr.push(m.covered_psnr);
    }
    eprintln!("the plane at a brick face {:.2} dB from full detail, inside a brick {:.2} dB", psnr[0], psnr[1]);
    assert!(psnr[0] >= psnr[1] - 1.0, "at a brick face {} dB, inside a brick {} dB", psnr[0], psnr[1]);
}

#[test]
fn a_view_along_a_grid_axis_counts_a_row_of_departures() {
    use crate::cpu::lod::{view_coherence, MAX_COHERENCE};
    // Along an axis a ray stays in one column of children through every cell: the most. Half a
    // cell's drift per cell (tan 0.5) or more: once. Between, the cells a ray stays in a column.
    assert_eq!(view_coherence(glam::Vec3::new(0.0, 0.0, -3.0)), MAX_COHERENCE);
    assert_eq!(view_coherence(glam::Vec3::new(1.0, 1.0, 0.2)), 1.0);
    assert_eq!(view_coherence(glam::Vec3::new(0.5, -0.1, 1.0)), 1.0);
    assert!((view_coherence(glam::Vec3::new(0.15, 0.2, -1.0)) - 2.0).abs() < 1e-5);
    assert_eq!(view_coherence(glam::Vec3::ZERO), 1.0);

    // Orthographic, a voxel over a pixel (no share of a pixel discounts an error) and no pixel
    // bound: a brick takes level 1 exactly where its level-1 error, times the view's coherence,
    // passes the bound. Half the bricks with an error pass it seen obliquely, fewer along z.
    let vol = blob([48, 48, 48]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let (mut g, mut c) = (common::gpu(), common::cpu());
    for r in [&mut g, &mut c] {
        r.set_volume(&vol, &tf(), None).unwrap();
    }
    let view = |dir: glam::Vec3| {
        let mut cam = Camera::framing(&grid, 96, 96);
        cam.target = grid.center();
        cam.eye = grid.center() + 150.0 * dir.normalize();
        cam.projection = crate::camera::Projection::Orthographic { height: 80.0 };
        (cam.near, cam.far) = (1.0, 1000.0);
        cam
    };
    let (along, oblique) = (view(glam::Vec3::Z), view(glam::Vec3::new(1.0, 0.0, 1.0)));
    let mut o = lod(Raster::Compute, Direction::BackToFront, crate::options::MAX_LOD_PIXELS);
    let errors: Vec<f32> = summaries_match_the_mirror(&mut g, &mut c, &along, &o)
        .iter()
        .filter(|s| s[0] & 0xff > 0)
        .map(|s| f32::from_bits(s[1]))
        .collect();
    let mut nonzero: Vec<f32> = errors.iter().copied().filter(|&e| e > 0.0).collect();
    nonzero.sort_by(f32::total_cmp);
    assert!(nonzero.len() > 20, "bricks with a level-1 error: {}", nonzero.len());
    o.lod_error = nonzero[nonzero.len() / 2];
    let coarse_bricks = |r: &mut Renderer, cam: &Camera| {
        let cells = drawn_cells(r, cam, &o);
        let bricks: std::collections::BTreeSet<[u32; 3]> =
            cells.iter().filter(|c| c[3] > 1).map(|c| [c[0] / 8, c[1] / 8, c[2] / 8]).collect();
        bricks.len()
    };
    for (cam, coherence, what) in [(&oblique, 1.0, "oblique"), (&along, MAX_COHERENCE, "along z")] {
        let expected = errors.iter().filter(|&&e| e * coherence <= o.lod_error).count();
        assert_eq!(coarse_bricks(&mut g, cam), expected, "{what}: bricks at level 1 or coarser");
        assert_eq!(drawn_cells(&mut g, cam, &o), drawn_cells(&mut c, cam, &o), "{what}: GPU vs mirror cells");
    }
    assert_clean(&g);
}
