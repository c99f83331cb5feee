//! Chapter 3: Swan's anti-aliasing in the per-splat stage, and EWA beside it.
use super::common;
use crate::plan::Prepared;
use crate::truth::{supersampled, TruthOptions};
use crate::{scene, Antialias, Camera, Composite, Grid, Kernel, Projection, RenderOptions, SplatSet};
use glam::Vec3;

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
        window: None,
    }
}

#[test]
fn a_splat_beyond_k_keeps_its_footprint_energy() {
    let set = one_voxel(0.01);
    let tau = crate::cpu::splat_params::optical_depth(0.01) as f64;
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
    let none = crate::low_level::splat_params(&mut r, &cam, Kernel::Gaussian, Antialias::None).unwrap();
    let swan = crate::low_level::splat_params(&mut r, &cam, Kernel::Gaussian, Antialias::Swan).unwrap();
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
    let regions = crate::aa::k_regions(&set, &cam);
    assert!(regions.iter().filter(|&&x| x == 2).count() > 200);
    let mut r = common::gpu();
    r.set_scene(set).unwrap();
    let mut err = |aa| {
        let mut o = RenderOptions::default();
        o.antialias = aa;
        let img = r.render(&cam, &o).unwrap().image;
        crate::metrics::rmse_masked(&img, &truth, |i| regions[i] == 2).unwrap()
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
    let p = crate::low_level::splat_params(&mut r, &cam, Kernel::Gaussian, Antialias::Swan).unwrap();
    let want = 1.0 / (cam.pixels_per_unit());
    assert!(p.iter().all(|q| (q.screen[3] - want).abs() < 1e-4 * want));
}

/// A `w` x `h` image of luma `f(x, y)`, opaque.
fn luma_image(w: u32, h: u32, f: impl Fn(f32, f32) -> f32) -> crate::ImageF32 {
    let mut img = crate::ImageF32::new(w, h);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        let v = f((i % w as usize) as f32, (i / w as usize) as f32);
        *p = [v, v, v, 1.0];
    }
    img
}

#[test]
fn lanczos_keeps_what_the_pixels_can_hold_and_drops_what_they_cannot() {
    use crate::image::{downsample, Downsample};
    let f = 8usize;
    let sine = |period: f32| {
        luma_image(64 * f as u32, 8 * f as u32, move |x, _| 0.5 + 0.4 * (x * std::f32::consts::TAU / period).sin())
    };
    let amplitude = |img: &crate::ImageF32| {
        let row: Vec<f32> = (8..56).map(|x| img.pixels[4 * 64 + x][0]).collect();
        (row.iter().cloned().fold(0.0f32, f32::max) - row.iter().cloned().fold(1.0f32, f32::min)) / 2.0
    };
    // 8 output pixels a period (a quarter of Nyquist): both filters keep most of it.
    let slow = sine(8.0 * f as f32);
    assert!(amplitude(&downsample(&slow, f, Downsample::Lanczos3)) > 0.35);
    // 1.6 output pixels a period (above Nyquist): Lanczos leaves a trace, the box lets a lot through.
    let fast = sine(1.6 * f as f32);
    let (l, b) =
        (amplitude(&downsample(&fast, f, Downsample::Lanczos3)), amplitude(&downsample(&fast, f, Downsample::Box)));
    assert!(l < 0.05 && b > 2.0 * l, "above Nyquist: Lanczos {l}, box {b}");
    // A constant stays itself to the edges (the weights are normalised there).
    let flat = downsample(&luma_image(64, 64, |_, _| 0.7), 4, Downsample::Lanczos3);
    assert!(flat.pixels.iter().all(|p| (p[0] - 0.7).abs() < 1e-5 && (p[3] - 1.0).abs() < 1e-5));
}

#[test]
fn aliasing_energy_counts_added_patterns_not_blur() {
    use crate::metrics::aliasing_energy;
    let scene = |x: f32, y: f32| 0.5 + 0.3 * (x * 0.2).sin() * (y * 0.15).cos();
    let reference = luma_image(64, 48, scene);
    let all = |_: usize| true;
    assert_eq!(aliasing_energy(&reference, &reference, all), Some(0.0));
    // A blur takes power away: nothing in excess.
    let blurred = luma_image(64, 48, |x, y| 0.5 + 0.15 * (x * 0.2).sin() * (y * 0.15).cos());
    assert!(aliasing_energy(&blurred, &reference, all).unwrap() < 1e-9);
    // A moire-like pattern the reference lacks is counted.
    let moire = luma_image(64, 48, |x, y| scene(x, y) + 0.1 * (x * 2.1 + y * 0.7).sin());
    let e = aliasing_energy(&moire, &reference, all).unwrap();
    assert!(e > 0.05, "aliasing energy {e}");
    assert_eq!(aliasing_energy(&moire, &reference, |i| i < 2), None, "a box under 4 pixels");
}

#[test]
fn the_k_line_falls_across_the_terrain_fly_over() {
    // Fig. 3.7's view at its size: the near terrain (lower rows) before k, the far terrain beyond.
    let set = scene::build("rmnp").unwrap();
    let cam = Camera::flyover(set.grid(), 260, 179);
    let regions = crate::aa::k_regions(&set, &cam);
    let rows = |class: u8| {
        let ys: Vec<usize> = (0..regions.len()).filter(|&i| regions[i] == class).map(|i| i / 260).collect();
        (ys.len(), ys.iter().sum::<usize>() as f64 / ys.len().max(1) as f64)
    };
    let ((before, y_before), (beyond, y_beyond)) = (rows(1), rows(2));
    eprintln!("before k: {before} px (mean row {y_before:.1}); beyond: {beyond} px (mean row {y_beyond:.1})");
    assert!(before > 500 && beyond > 500, "the view spans k");
    // The image's first row is its top (Vulkan's y points down): the far terrain lies above.
    assert!(y_beyond < y_before);
    // A voxel raster the rays miss has no regions.
    let empty = crate::SplatSet::from_fn(*set.grid(), |_, _, _| None).unwrap();
    assert!(crate::aa::k_regions(&empty, &cam).iter().all(|&r| r == 0));
}

/// Issue 44: in a frame of a few pixels, or near the near plane, anti-aliasing's widening no longer
/// culls the splat it widens: the cull margin was CULL_RADII widened radii, and a radius widened to
/// a pixel grows with depth, so a small frame drew nothing at any distance (EWA at 8 x 8, 62°: a
/// voxel 4 units away, alpha 0). The widening now stops short of the planes; the energy holds.
#[test]
fn anti_aliasing_never_culls_the_splat_it_widens() {
    let set = one_voxel(0.3);
    let (mut c, mut g) = (common::cpu(), common::gpu());
    c.set_scene(set.clone()).unwrap();
    g.set_scene(set.clone()).unwrap();
    // Beyond the unwidened cull margin (3 units here), which still holds.
    let margin = Camera::cull_margin(set.grid().kernel_spacing());
    for (size, fov, beyond) in [(8, 62.0, 0.5), (4, 35.0, 0.6), (2, 30.0, 3.0), (16, 40.0, 0.2), (3, 20.0, 8.0)] {
        let mut cam = looking_at(set.grid().center(), margin + beyond, size);
        (cam.projection, cam.near) = (Projection::Perspective { fov_y_deg: fov }, 0.01);
        // The Gaussian, whose bounds these are. (Crawfis-Max, the default: EWA at 2 x 2 keeps 0.79
        // of --aa none's alpha, measured 2026-12-02; the widened footprint reaches past the frame.)
        let mut none_o = RenderOptions::default();
        none_o.kernel = Kernel::Gaussian;
        let none = c.render(&cam, &none_o).unwrap().image;
        let sum = |img: &crate::ImageF32| img.pixels.iter().map(|p| p[3]).sum::<f32>();
        assert!(sum(&none) > 0.05, "{size}: nothing drawn without anti-aliasing ({})", sum(&none));
        for aa in [Antialias::Swan, Antialias::Ewa] {
            let mut o = none_o.clone();
            o.antialias = aa;
            let img = c.render(&cam, &o).unwrap().image;
            let ratio = sum(&img) / sum(&none);
            assert!((0.8..1.25).contains(&ratio), "{aa:?} at {size}x{size}, {fov}°: coverage {ratio} of --aa none's");
            common::assert_mirrors(&g.render(&cam, &o).unwrap().image, &img, &format!("{aa:?} {size}"));
        }
    }
    common::assert_clean(&g);
}

/// Issue 44, found by the coverage property: in slab mode a splat's depth profile kept the radius
/// anti-aliasing widened on the screen, so beyond k most of its weight fell outside the slabs it
/// was binned into (the attenuated cube at 18 x 18 from 2,200 units: alpha 0). Its depth profile is
/// the kernel's own: slabs carry the energy splats and sheets carry.
#[test]
fn slab_mode_keeps_an_anti_aliased_splat_s_energy() {
    let set = one_voxel(0.3);
    let (mut c, mut g) = (common::cpu(), common::gpu());
    c.set_scene(set.clone()).unwrap();
    g.set_scene(set.clone()).unwrap();
    let probe = looking_at(set.grid().center(), 1.0, 64);
    let k = probe.k(1.0).unwrap();
    let sum = |img: &crate::ImageF32| img.pixels.iter().map(|p| p[3]).sum::<f32>();
    for (d_over_k, aa) in
        [(4.0f32, Antialias::Swan), (12.0, Antialias::Swan), (4.0, Antialias::Ewa), (12.0, Antialias::Ewa)]
    {
        let cam = looking_at(set.grid().center(), d_over_k * k, 64);
        let mut o = RenderOptions::default();
        o.antialias = aa;
        let splat = sum(&c.render(&cam, &o).unwrap().image);
        o.composite = Composite::Slab;
        let slab = c.render(&cam, &o).unwrap().image;
        let ratio = sum(&slab) / splat;
        assert!((0.9..1.1).contains(&ratio), "{aa:?} at d/k {d_over_k}: slabs carry {ratio} of the splat's alpha");
        common::assert_mirrors(&g.render(&cam, &o).unwrap().image, &slab, &format!("{aa:?} {d_over_k}"));
    }
    common::assert_clean(&g);
}
