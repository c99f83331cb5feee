//! Chapter 3: Swan's anti-aliasing in the per-splat stage, and EWA beside it.
mod common;
use glam::Vec3;
use voxsplat::plan::Prepared;
use voxsplat::truth::{supersampled, TruthOptions};
use voxsplat::{scene, Antialias, Camera, Composite, Grid, Kernel, Projection, RenderOptions, SplatSet};

fn one_voxel(opacity: f32) -> SplatSet {
    let grid = Grid::centered([1, 1, 1], [1.0; 3]).unwrap();
    SplatSet::from_fn(grid, |_, _, _| Some([1.0, 1.0, 1.0, opacity])).unwrap()
}

fn looking_at(p: Vec3, distance: f32, size: u32) -> Camera {
    Camera {
        eye: p + Vec3::new(0.31, 0.17, distance),
        target: p + Vec3::new(0.31, 0.17, 0.0),
        up: Vec3::Y,
        projection: Projection::Perspective { fov_y_deg: 40.0 },
        near: 0.5,
        far: 4.0 * distance,
        width: size,
        height: size,
    }
}

#[test]
fn a_splat_beyond_k_keeps_its_footprint_energy() {
    let set = one_voxel(0.01);
    let tau = voxsplat::cpu::splat_params::optical_depth(0.01) as f64;
    let mut r = common::cpu();
    r.set_scene(set.clone()).unwrap();
    let probe = looking_at(set.grid().center(), 1.0, 64);
    let k = probe.k(1.0).unwrap();
    for (d_over_k, aa) in
        [(4.0f32, Antialias::Swan), (6.0, Antialias::Swan), (4.0, Antialias::Ewa), (0.5, Antialias::Swan)]
    {
        let cam = looking_at(set.grid().center(), d_over_k * k, 64);
        let mut o = RenderOptions::default();
        o.composite = Composite::Sheet;
        o.antialias = aa;
        let img = r.render(&cam, &o).unwrap().image;
        // Sheet compositing of one splat: alpha = 1 - exp(-T), T = tau * energy * f.
        let total: f64 = img.pixels.iter().map(|p| -(1.0 - p[3] as f64).ln()).sum();
        // The unscaled footprint integrates to tau * (pixels per voxel)^2 pixels.
        let ppv = 1.0 / d_over_k as f64;
        let want = tau * ppv * ppv;
        let rel = (total - want).abs() / want;
        eprintln!("{aa:?} d/k {d_over_k}: energy {total:.6e} vs {want:.6e} ({:.3} %)", rel * 100.0);
        assert!(rel < 0.01, "{aa:?} at d/k = {d_over_k}: {total} vs {want}");
    }
}

#[test]
fn radius_scale_is_max_of_one_and_d_over_k_and_nothing_changes_before_k() {
    let set = scene::build("plane").unwrap();
    let cam = Camera::grazing(set.grid(), 128, 128);
    let k = cam.k(set.grid().kernel_spacing()).unwrap();
    let mut r = common::cpu();
    r.set_scene(set).unwrap();
    let none = r.splat_params(&cam, Kernel::Gaussian, Antialias::None).unwrap();
    let swan = r.splat_params(&cam, Kernel::Gaussian, Antialias::Swan).unwrap();
    let (mut before, mut beyond) = (0, 0);
    for (a, b) in none.iter().zip(&swan) {
        let d = b.screen[0];
        if d <= 0.0 {
            continue;
        }
        let want = (d / k).max(1.0);
        assert!((b.screen[3] - want).abs() <= 1e-4 * want, "scale {} want {want}", b.screen[3]);
        let len = |v: [f32; 4]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((len(b.axis_u) - want * len(a.axis_u)).abs() <= 1e-4 * len(b.axis_u));
        assert!((b.axis_u[3] - 1.0 / (want * want)).abs() <= 1e-5);
        if d <= k {
            assert_eq!(a, b, "no change before k");
            before += 1;
        } else {
            beyond += 1;
        }
    }
    assert!(before > 1000 && beyond > 1000, "the view spans k: {before} before, {beyond} beyond");
}

#[test]
fn swan_lowers_the_error_beyond_k_on_the_plane() {
    let set = scene::build("plane").unwrap();
    let cam = Camera::grazing(set.grid(), 96, 96);
    let truth = supersampled(&set, &cam, 8, &TruthOptions::default()).unwrap();
    let regions = voxsplat::aa::k_regions(&set, &cam);
    assert!(regions.iter().filter(|&&x| x == 2).count() > 200);
    let mut r = common::gpu();
    r.set_scene(set).unwrap();
    let mut err = |aa| {
        let mut o = RenderOptions::default();
        o.antialias = aa;
        let img = r.render(&cam, &o).unwrap().image;
        voxsplat::metrics::rmse_masked(&img, &truth, |i| regions[i] == 2).unwrap()
    };
    let (none, swan) = (err(Antialias::None), err(Antialias::Swan));
    eprintln!("beyond k: none {none:.4}, swan {swan:.4}");
    assert!(swan < none);
    common::assert_clean(&r);
}

#[test]
fn orthographic_dense_volume_lies_wholly_beyond_k() {
    // Fig. 3.8: voxels smaller than pixels in an orthographic view: every splat is scaled.
    let set = scene::build("stripes128").unwrap();
    let prep = Prepared::new(set.clone());
    assert_eq!(prep.set.grid().dims, [128, 128, 128]);
    let mut cam = Camera::framing(set.grid(), 64, 64);
    cam.projection = Projection::Orthographic { height: 180.0 };
    cam.near = -400.0;
    assert!(set.grid().kernel_spacing() * cam.pixels_per_unit() < 1.0);
    let mut r = common::cpu();
    r.set_scene(set).unwrap();
    let p = r.splat_params(&cam, Kernel::Gaussian, Antialias::Swan).unwrap();
    let want = 1.0 / (cam.pixels_per_unit());
    assert!(p.iter().all(|q| (q.screen[3] - want).abs() < 1e-4 * want));
}
