//! Isosurface splats (`--mode iso`): against the ray caster's first crossing (depth and
//! coverage), the GPU against the CPU mirrors, a bricked volume against its dense set, a new value
//! per frame without a new upload, and what they refuse.
use super::common;
use crate::stages::{Res, StageId};
use crate::volume::ScalarVolume;
use crate::{Camera, Error, Grid, ImageF32, Kernel, Mode, Raster, RaycastOptions, RenderOptions, Renderer, SplatSet};
use common::{assert_clean, assert_mirrors, cpu, gpu};
use glam::Vec3;

/// A ball's values: 1 at its centre falling linearly to 0 at `radius` voxels, on an n³ grid:
/// its isosurface at v is the sphere of radius (1 - v) radius.
fn ball_value(n: u32, radius: f32, i: u32, j: u32, k: u32) -> f32 {
    let c = (n as f32 - 1.0) / 2.0;
    let r = Vec3::new(i as f32 - c, j as f32 - c, k as f32 - c).length();
    (1.0 - r / radius).max(0.0)
}

/// The ball as a splat set holding every valued voxel (so the set holds the whole field).
fn ball(n: u32, radius: f32) -> SplatSet {
    let grid = Grid::centered([n; 3], [1.0; 3]).unwrap();
    SplatSet::from_fn_valued(grid, |i, j, k| {
        let v = ball_value(n, radius, i, j, k);
        (v > 0.0).then_some(([0.5, 0.5, 0.5, 0.1], v))
    })
    .unwrap()
}

fn iso(v: f32) -> RenderOptions {
    let mut o = RenderOptions::default();
    // The discs' size (ISO_DISC_VOXELS) was set for the Gaussian's profile. With Crawfis-Max, the
    // default, two pixels stay open at the crease of the ortho view at iso 0.3 (measured 2026-12-02).
    o.kernel = Kernel::Gaussian;
    o.mode = Mode::Iso;
    o.iso = Some(v);
    o
}

fn cast(v: f32) -> RaycastOptions {
    RaycastOptions { mode: Mode::Iso, iso: Some(v), step: 0.25, ..Default::default() }
}

fn opaque(img: &ImageF32) -> Vec<bool> {
    img.pixels.iter().map(|p| p[3] >= 0.5).collect()
}

/// The views the comparisons take: the framing perspective, a close perspective, two oblique
/// orthographic ones from opposite octants.
fn views(grid: &Grid, size: u32) -> Vec<(&'static str, Camera)> {
    let framing = Camera::framing(grid, size, size);
    let close = crate::scene::close_view(grid, size);
    let mut ortho = Camera::framing(grid, size, size);
    ortho.eye = Vec3::new(70.0, 45.0, 90.0);
    ortho.projection = crate::Projection::Orthographic { height: grid.dims[1] as f32 * 1.3 };
    // From the opposite octant: the grid's low faces.
    let mut back = ortho;
    back.eye = Vec3::new(-80.0, -40.0, -70.0);
    vec![("framing", framing), ("close", close), ("ortho", ortho), ("back", back)]
}

#[test]
fn gpu_matches_its_mirrors_and_the_ray_casters() {
    let set = ball(32, 14.0);
    let (mut g, mut c) = (gpu(), cpu());
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set.clone()).unwrap();
    for (name, cam) in views(set.grid(), 80) {
        for v in [0.3f32, 0.6] {
            let a = g.render(&cam, &iso(v)).unwrap();
            let b = c.render(&cam, &iso(v)).unwrap();
            assert_eq!(a.stats.splats, b.stats.splats, "{name} {v}: surface splats");
            assert!(a.stats.splats > 100, "{name} {v}: {} splats", a.stats.splats);
            assert_mirrors(&a.image, &b.image, &format!("iso {v}, {name}"));
            let ra = g.raycast(&cam, &cast(v)).unwrap();
            let rb = c.raycast(&cam, &cast(v)).unwrap();
            assert_mirrors(&ra.image, &rb.image, &format!("ray-cast iso {v}, {name}"));
        }
    }
    assert_clean(&g);
}

/// Pixels the rays hit (and their eight neighbours too) that the splats leave open.
fn holes(splats: &[bool], rays: &[bool], w: usize, h: usize) -> usize {
    let interior = |i: usize| {
        let (x, y) = (i % w, i / w);
        x > 0 && y > 0 && x + 1 < w && y + 1 < h && (0..9).all(|d| rays[(y + d / 3 - 1) * w + x + d % 3 - 1])
    };
    (0..w * h).filter(|&i| interior(i) && !splats[i]).count()
}

#[test]
fn surface_lies_on_the_ray_casters_first_crossing_without_holes() {
    // A ball of radius 40 voxels: at iso 0.5 the sphere of radius 20; at iso 0.3 the sphere of
    // radius 28 cut by the grid's faces (creases where they meet, each cell of the cut a crossing
    // with the 0 outside the grid). The discs reach past a silhouette by about r² / 2R (r: their
    // radius, 1.25 voxels), so the coverage grows by about r² / R²: 0.4 % at R = 20 (0.7 % at
    // R = 15, measured); the creases add a little.
    let set = ball(48, 40.0);
    let mut r = cpu();
    r.set_scene(set.clone()).unwrap();
    for (v, most) in [(0.5f32, 0.005), (0.3, 0.01)] {
        for (name, cam) in views(set.grid(), 256) {
            let o = iso(v);
            let splats = r.render(&cam, &o).unwrap();
            let rays = r.raycast(&cam, &cast(v)).unwrap();
            let (s, t) = (opaque(&splats.image), opaque(&rays.image));
            let (w, h) = (cam.width as usize, cam.height as usize);
            let (covered, truth) = (s.iter().filter(|&&b| b).count(), t.iter().filter(|&&b| b).count());
            let open = holes(&s, &t, w, h);
            let excess = (covered as f64 - truth as f64).abs() / truth as f64;
            println!(
                "iso {v}, {name}: splats cover {covered} px, rays {truth}, holes {open}, |difference| {excess:.4}"
            );
            assert!(truth > 1000, "{name}: the ball covers {truth} px");
            assert!(excess <= most, "iso {v}, {name}: coverage {covered} against the ray caster's {truth}");
            assert_eq!(open, 0, "iso {v}, {name}: pixels inside the rays' picture that the splats leave open");
            // Depth: each pixel's visible depth (the compositor's fourth channel) against the
            // first crossing along its ray, over every pixel both cover.
            let acc = r.probe(&cam, &o, StageId::TileComposite, &[Res::Accum]).unwrap().remove(0);
            let mut off: Vec<f32> = (0..w * h)
                .filter(|&i| s[i] && t[i])
                // (A ray that grazes a corner may cross between two of the ray caster's samples
                // and none of picking's, or the other way round.)
                .filter_map(|i| {
                    let hit = r.pick(&cam, &o, (i % w) as f32 + 0.5, (i / w) as f32 + 0.5).unwrap()?;
                    Some((f32::from_bits(acc[4 * i + 3]) - hit.depth).abs())
                })
                .collect();
            off.sort_by(f32::total_cmp);
            let (n, worst, p99) = (off.len(), off[off.len() - 1], off[off.len() * 99 / 100]);
            println!(
                "iso {v}, {name}: depth within {worst:.3} voxel of the first crossing over {n} px (99 %: {p99:.3})"
            );
            // Along a crease a disc's plane parts from the surface it meets (up to 2.57 voxels
            // measured, on a few pixels: the depth band is 2); elsewhere within a voxel.
            let most = if v == 0.5 { 1.0 } else { 3.0 };
            assert!(
                n > 1000 && worst <= most && p99 <= 1.0,
                "iso {v}, {name}: depth off by {worst} voxels (99 %: {p99})"
            );
        }
    }
}

#[test]
fn the_hosts_depth_hides_the_surface_behind_it() {
    let set = ball(32, 28.0);
    let (mut g, mut c) = (gpu(), cpu());
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 64, 64);
    let plain = c.render(&cam, &iso(0.5)).unwrap();
    let z = c.probe(&cam, &iso(0.5), StageId::TileComposite, &[Res::Accum]).unwrap().remove(0);
    // A plane facing the camera through the front of the sphere (radius 14), 11 voxels before its
    // centre: it hides the rim and leaves the middle.
    let d = (crate::glam::Vec3::ZERO - cam.eye).dot(cam.forward()) - 11.0;
    let proj = cam.proj();
    let clip = proj * crate::glam::Vec4::new(0.0, 0.0, -d, 1.0);
    let depth = crate::DepthBuffer {
        width: cam.width,
        height: cam.height,
        format: crate::DepthFormat::D32,
        texels: vec![(clip.z / clip.w).to_bits(); (cam.width * cam.height) as usize],
        projection: proj,
    };
    let mut o = iso(0.5);
    o.depth = Some(std::sync::Arc::new(depth));
    let (a, b) = (g.render(&cam, &o).unwrap(), c.render(&cam, &o).unwrap());
    assert_mirrors(&a.image, &b.image, "iso over the host's depth");
    let (mut kept, mut hidden) = (0, 0);
    for (i, (p, q)) in b.image.pixels.iter().zip(&plain.image.pixels).enumerate() {
        let surface = f32::from_bits(z[4 * i + 3]);
        if q[3] < 0.5 {
            continue;
        }
        // The discs reach about their radius (1.25 voxels) either side of their centres' depth.
        if surface < d - 2.0 {
            assert!((0..4).all(|k| (p[k] - q[k]).abs() < 1e-4), "pixel {i}: in front of the host's plane, {p:?} {q:?}");
            kept += 1;
        } else if surface > d + 2.0 {
            assert_eq!(p[3], 0.0, "pixel {i}: behind the host's plane");
            hidden += 1;
        }
    }
    assert!(kept > 100 && hidden > 100, "kept {kept}, hidden {hidden}");
    assert_clean(&g);
}

#[test]
fn a_new_iso_value_needs_no_new_upload() {
    let set = ball(32, 14.0);
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 64, 64);
    let uploads = |r: &crate::Rendered| r.timings.iter().filter(|t| t.stage == "iso_field").count();
    let first = g.render(&cam, &iso(0.4)).unwrap();
    let second = g.render(&cam, &iso(0.6)).unwrap();
    assert_eq!((uploads(&first), uploads(&second)), (1, 0), "the field goes up once per scene");
    // Radii 8.4 and 5.6 voxels: the surface's splats and its picture shrink with it.
    assert!(second.stats.splats < first.stats.splats * 3 / 4, "{} {}", first.stats.splats, second.stats.splats);
    let area = |img: &ImageF32| opaque(img).iter().filter(|&&b| b).count() as f32;
    let ratio = area(&second.image) / area(&first.image);
    assert!((ratio - (5.6f32 / 8.4).powi(2)).abs() < 0.08, "area ratio {ratio}");
    // A new scene's field goes up again.
    g.set_scene(ball(24, 10.0)).unwrap();
    let third = g.render(&cam, &iso(0.5)).unwrap();
    assert_eq!(uploads(&third), 1);
    assert_clean(&g);
}

#[test]
fn a_bricked_volume_draws_the_surface_of_its_dense_set() {
    let n = 32;
    let values: Vec<f32> = (0..n * n * n).map(|v| ball_value(n, 14.0, v % n, v / n % n, v / (n * n))).collect();
    let max = values.iter().copied().fold(0.0, f32::max);
    let volume = ScalarVolume { dims: [n; 3], spacing: [1.0; 3], values };
    let tf = common::blob_tf();
    let (mut bricked, mut dense) = (gpu(), gpu());
    bricked.set_volume(&volume, &tf, None).unwrap();
    dense.set_scene(ball(n, 14.0)).unwrap();
    let cam = Camera::framing(dense.scene().unwrap().grid(), 72, 72);
    // The store normalises by the volume's largest value.
    let a = bricked.render(&cam, &iso(0.5 / max)).unwrap();
    let b = dense.render(&cam, &iso(0.5)).unwrap();
    assert_eq!(a.stats.splats, b.stats.splats);
    let (worst, mean) = common::diff(&a.image, &b.image);
    assert!(worst < 0.02 && mean < 1e-3, "bricked against dense: {worst} {mean}");
    // The ray caster reads a bricked volume's isosurface too, from the same values.
    let ra = bricked.raycast(&cam, &cast(0.5 / max)).unwrap();
    let rb = dense.raycast(&cam, &cast(0.5)).unwrap();
    let (worst, mean) = common::diff(&ra.image, &rb.image);
    assert!(worst < 0.02 && mean < 1e-3, "ray-cast bricked against dense: {worst} {mean}");
    // Picking meets the same surface.
    let (pa, pb) =
        (bricked.pick(&cam, &iso(0.5 / max), 36.0, 36.0).unwrap(), dense.pick(&cam, &iso(0.5), 36.0, 36.0).unwrap());
    let (pa, pb) = (pa.expect("bricked pick"), pb.expect("dense pick"));
    assert!((pa.depth - pb.depth).abs() < 1e-2, "{} {}", pa.depth, pb.depth);
    assert_clean(&bricked);
}

#[test]
fn a_value_the_volume_never_crosses_draws_nothing() {
    let set = ball(24, 10.0);
    let cam = Camera::framing(set.grid(), 48, 48);
    for mut r in [gpu(), cpu()] {
        r.set_scene(set.clone()).unwrap();
        // Above the largest value (about 0.93), at or below the outside's 0, beyond [0, 1].
        for v in [0.99f32, 0.0, -0.5, 1.5] {
            let f = r.render(&cam, &iso(v)).unwrap();
            assert_eq!(f.stats.splats, 0, "iso {v}");
            assert!(f.image.pixels.iter().all(|p| p[3] == 0.0), "iso {v}: something drawn");
            let rays = r.raycast(&cam, &cast(v)).unwrap();
            assert!(rays.image.pixels.iter().all(|p| p[3] == 0.0), "iso {v}: the ray caster drew something");
            assert!(r.pick(&cam, &iso(v), 24.0, 24.0).unwrap().is_none(), "iso {v}: a pick");
        }
        assert_clean(&r);
    }
}

#[test]
fn refusals() {
    let set = ball(16, 7.0);
    let cam = Camera::framing(set.grid(), 32, 32);
    let mut r: Renderer = cpu();
    r.set_scene(set).unwrap();
    let refused = |r: &mut Renderer, o: &RenderOptions, words: &str| {
        let e = r.render(&cam, o).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument(_)) && e.to_string().contains(words), "{e}");
    };
    let mut o = iso(0.5);
    o.iso = None;
    refused(&mut r, &o, "needs an iso value");
    let mut o = RenderOptions::default();
    o.mode = Mode::Mip;
    o.iso = Some(0.5);
    refused(&mut r, &o, "--mode iso only");
    let mut o = iso(f32::NAN);
    refused(&mut r, &o, "not a finite number");
    o = iso(0.5);
    o.raster = Raster::Graphics;
    refused(&mut r, &o, "compute tile compositor");
    o = iso(0.5);
    o.composite = crate::Composite::Sheet;
    refused(&mut r, &o, "sheets and slabs");
    let mut c = cast(0.5);
    c.iso = None;
    assert!(r.raycast(&cam, &c).is_err());
}
