//! Levels of detail over bricked volumes (issues 23-24): the pyramid stage and the coarse paths
//! of the brick stages against their CPU mirrors, the mixed-level sequence against the cell
//! validator over a random view battery, and the pyramid rebuilt when the classification
//! changes. Validation on: any message fails.
mod common;
use common::{assert_clean, random_camera, Rng, ViewKind};
use voxsplat::classify::{Shading, TransferFunction};
use voxsplat::stages::{Res, StageId};
use voxsplat::volume::ScalarVolume;
use voxsplat::{Camera, Direction, Lod, Raster, RenderOptions, Renderer};

/// A lumpy blob with empty space around it, on a grid whose sides are not multiples of 8.
fn blob(dims: [u32; 3]) -> ScalarVolume {
    let c = dims.map(|d| d as f32 / 2.0);
    let mut values = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = [i, j, k].map(|v| v as f32);
                let r = ((0..3).map(|a| ((p[a] - c[a]) / c[a]).powi(2)).sum::<f32>()).sqrt();
                let wobble = 0.15 * ((p[0] * 0.7).sin() * (p[1] * 0.5).cos() + (p[2] * 0.9).sin());
                values.push(if r < 0.9 { (1.0 - r + wobble).max(0.0) * 100.0 } else { 0.0 });
            }
        }
    }
    ScalarVolume { dims, spacing: [1.0, 1.2, 0.9], values }
}

fn tf() -> TransferFunction {
    TransferFunction {
        points: vec![(0.1, [0.0, 0.0, 0.0, 0.0]), (0.3, [0.9, 0.4, 0.2, 0.3]), (1.0, [0.9, 0.9, 1.0, 0.8])],
        gradient_weight: 0.0,
        range: None,
        threshold: 0.0,
    }
}

fn lod(raster: Raster, direction: Direction, pixels: f32) -> RenderOptions {
    let mut o = RenderOptions::default();
    (o.raster, o.direction, o.lod, o.lod_pixels, o.lod_error) = (raster, Some(direction), Lod::Auto, pixels, 100.0);
    o
}

/// Largest and mean absolute channel difference.
fn diff(a: &voxsplat::ImageF32, b: &voxsplat::ImageF32) -> (f32, f32) {
    let d: Vec<f32> =
        a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..4).map(move |c| (p[c] - q[c]).abs())).collect();
    (d.iter().copied().fold(0.0, f32::max), d.iter().sum::<f32>() / d.len() as f32)
}

/// The frame's cells in draw order, (i, j, k, side), read back after `brick_params`.
fn drawn_cells(r: &mut Renderer, cam: &Camera, o: &RenderOptions) -> Vec<[u32; 4]> {
    let got = r.probe(cam, o, StageId::BrickParams, &[Res::BrickSlots, Res::BrickVoxels]).unwrap();
    let total: u32 = got[0].iter().filter(|&&w| w != 0).map(|&w| voxsplat::bricks::slot_entry(w).2).sum();
    got[1]
        .chunks_exact(2)
        .take(total as usize)
        .map(|v| [v[0] & 0xffff, v[0] >> 16, v[1] & 0x1fff, 1 << (v[1] >> 13 & 3)])
        .collect()
}

#[test]
fn coarse_levels_match_the_cpu_mirrors_on_every_raster() {
    let vol = blob([45, 37, 29]);
    let cam = Camera::framing(&voxsplat::Grid::centered(vol.dims, vol.spacing).unwrap(), 96, 80);
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
                // The prefiltered levels stand for the voxels: close to full detail, not equal.
                let (most, mean) = diff(&a, &all);
                assert!(mean > 1e-5 && mean <= 0.02, "{what}: coarse against full detail {most} / {mean}");
            }
        }
        assert_clean(&g);
    }
}

#[test]
fn mixed_level_sequences_pass_the_cell_validator_on_both_engines() {
    let vol = blob([45, 37, 29]);
    let grid = voxsplat::Grid::centered(vol.dims, vol.spacing).unwrap();
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
                let bad = voxsplat::order::count_cell_violations(&grid, &cam, &cells, direction).unwrap();
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
    assert!(voxsplat::order::count_cell_violations(&grid, &cam, &cells, Direction::FrontToBack).unwrap() > 0);
    assert_clean(&g);
}

#[test]
fn the_pyramid_follows_the_classification() {
    let vol = blob([45, 37, 29]);
    let cam = Camera::framing(&voxsplat::Grid::centered(vol.dims, vol.spacing).unwrap(), 80, 64);
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
    let stages = |r: &voxsplat::Rendered| r.timings.iter().filter(|t| t.stage == "lod").count();
    assert_eq!(stages(&g.render(&cam, &o).unwrap()), 0);
    assert_clean(&g);
}
