//! Clipping planes and the crop box (issue 27 item 2): every splat mode and the ray caster, dense
//! and bricked, GPU against the CPU mirrors; what they keep and drop; refused planes.
use super::common;
use crate::classify::classify;
use crate::RaycastOptions;
use crate::{scene, Camera, Clip, Composite, Raster, RenderOptions};
use common::{assert_clean, blob, blob_tf as tf, diff};
use glam::{Vec3, Vec4};

fn with(clip: Clip, composite: Composite, raster: Raster) -> RenderOptions {
    let mut o = RenderOptions::default();
    (o.clip, o.composite, o.raster) = (clip, composite, raster);
    o
}

fn covered(img: &crate::ImageF32) -> usize {
    common::covered(img)
}

#[test]
fn clipping_drops_what_lies_outside_in_every_mode_and_the_gpu_equals_its_mirror() {
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 96, 96);
    let half = Clip::new(&[Vec4::new(-1.0, 0.0, 0.0, 0.0)], None).unwrap();
    let cropped =
        Clip::new(&[Vec4::new(0.0, 1.0, 1.0, 5.0)], Some([Vec3::splat(-20.0), Vec3::new(25.0, 30.0, 30.0)])).unwrap();
    let everything = Clip::new(&[Vec4::new(0.0, 0.0, 1.0, 1000.0)], None).unwrap();
    let nothing = Clip::new(&[Vec4::new(0.0, 0.0, 1.0, -1000.0)], None).unwrap();
    let (mut g, mut c) = (common::gpu(), common::cpu());
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set).unwrap();
    for (composite, raster) in [
        (Composite::Splat, Raster::Compute),
        (Composite::Splat, Raster::Graphics),
        (Composite::Sheet, Raster::Graphics),
        (Composite::Slab, Raster::Compute),
    ] {
        let full = g.render(&cam, &with(Clip::default(), composite, raster)).unwrap().image;
        for (clip, what) in [(half, "half"), (cropped, "cropped")] {
            let a = g.render(&cam, &with(clip, composite, raster)).unwrap().image;
            let b = c.render(&cam, &with(clip, composite, raster)).unwrap().image;
            common::assert_mirrors(&a, &b, &format!("{composite:?} {raster} {what}"));
            assert!(covered(&a) > 500 && covered(&a) < covered(&full), "{composite:?} {raster} {what}: drops some");
        }
        let kept = g.render(&cam, &with(everything, composite, raster)).unwrap().image;
        assert_eq!(kept.pixels, full.pixels, "{composite:?} {raster}: a plane keeping all changes nothing");
        let gone = g.render(&cam, &with(nothing, composite, raster)).unwrap().image;
        assert_eq!(covered(&gone), 0, "{composite:?} {raster}: a plane keeping nothing draws nothing");
    }
    // The ray caster cuts its rays to the same half-space.
    for clip in [half, cropped] {
        let o = RaycastOptions { clip, ..Default::default() };
        let a = g.raycast(&cam, &o).unwrap().image;
        let b = c.raycast(&cam, &o).unwrap().image;
        let (most, mean) = diff(&a, &b);
        assert!(most <= 2e-3 && mean <= 1e-4, "ray caster: GPU vs mirror {most} / {mean}");
        let full = g.raycast(&cam, &RaycastOptions::default()).unwrap().image;
        assert!(covered(&a) > 500 && covered(&a) < covered(&full));
    }
    let o = RaycastOptions { clip: nothing, ..Default::default() };
    assert_eq!(covered(&g.raycast(&cam, &o).unwrap().image), 0);
    assert_clean(&g);
}

#[test]
fn a_clipped_bricked_volume_draws_the_clipped_dense_splats() {
    let vol = blob([37, 29, 23]);
    let grid = crate::Grid::centered(vol.dims, vol.spacing).unwrap();
    let cam = Camera::framing(&grid, 96, 80);
    // Through the middle, and a crop that leaves whole bricks out (the brick test culls them).
    let clip =
        Clip::new(&[Vec4::new(1.0, 0.5, 0.0, 2.0)], Some([Vec3::new(-30.0, -30.0, -4.0), Vec3::splat(30.0)])).unwrap();
    let (mut g, mut c, mut dense) = (common::gpu(), common::cpu(), common::gpu());
    g.set_volume(&vol, &tf(), None).unwrap();
    c.set_volume(&vol, &tf(), None).unwrap();
    dense.set_scene(classify(&vol, &tf(), None).unwrap()).unwrap();
    for raster in [Raster::Compute, Raster::Graphics] {
        let o = with(clip, Composite::Splat, raster);
        let a = g.render(&cam, &o).unwrap().image;
        let b = c.render(&cam, &o).unwrap().image;
        common::assert_mirrors(&a, &b, &format!("bricked {raster}"));
        let d = dense.render(&cam, &o).unwrap().image;
        let (most, mean) = diff(&a, &d);
        assert!(most <= 0.05 && mean <= 2e-3, "{raster}: bricked vs dense {most} / {mean}");
        let full = g.render(&cam, &with(Clip::default(), Composite::Splat, raster)).unwrap().image;
        assert!(covered(&a) > 200 && covered(&a) < covered(&full));
    }
    assert_clean(&g);
}

#[test]
fn degenerate_planes_and_boxes_are_refused() {
    let p = Vec4::new(1.0, 0.0, 0.0, 0.0);
    let e = |r: crate::Result<Clip>| r.unwrap_err().to_string();
    assert!(e(Clip::new(&[p; 7], None)).contains("at most 6"));
    assert!(e(Clip::new(&[Vec4::new(0.0, 0.0, 0.0, 1.0)], None)).contains("non-zero"));
    assert!(e(Clip::new(&[Vec4::new(f32::NAN, 1.0, 0.0, 1.0)], None)).contains("finite"));
    assert!(e(Clip::new(&[Vec4::new(1.0, 0.0, 0.0, f32::INFINITY)], None)).contains("finite"));
    assert!(e(Clip::new(&[], Some([Vec3::ONE, Vec3::new(2.0, 0.5, 2.0)]))).contains("below the second"));
    // Six planes and a box are taken; normals of any length are normalised.
    let c = Clip::new(&[Vec4::new(0.0, 2.0, 0.0, 4.0); 6], Some([Vec3::ZERO, Vec3::ONE])).unwrap();
    assert_eq!(c.planes().len(), 12);
    assert_eq!(c.planes()[0], Vec4::new(0.0, 1.0, 0.0, 2.0));
    assert!(c.keeps(Vec3::splat(0.5)) && !c.keeps(Vec3::new(0.5, 1.5, 0.5)));
}

/// A ray cut by a plane counts only what lies before it: the two halves of a volume, each cast
/// with its own plane and composited front over back, are the whole cast (how
/// `scripts/sparse-truth.py` casts a volume too large for one cast, tile by tile). Before the last
/// sample was cut to what is left of the ray, it counted up to a step past the plane twice (0.060
/// here; 0.0044 now, the two sample lattices' phases at the cube's edges).
#[test]
fn the_two_halves_of_a_clipped_ray_cast_composite_to_the_whole() {
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 96, 96);
    // The plane x = 0.3 (off the sample lattice), and its two sides.
    let keep = |s: f32| Clip::new(&[Vec4::new(s, 0.0, 0.0, -0.3 * s)], None).unwrap();
    let (mut g, mut c) = (common::gpu(), common::cpu());
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set).unwrap();
    // The eye's side of the plane is in front.
    let front = if cam.eye.x > 0.3 { 1.0 } else { -1.0 };
    for (engine, name) in [(&mut c, "cpu"), (&mut g, "gpu")] {
        let cast = |e: &mut crate::Renderer, clip| e.raycast(&cam, &RaycastOptions { clip, ..Default::default() });
        let whole = cast(engine, Clip::default()).unwrap().image;
        let near = cast(engine, keep(front)).unwrap().image;
        let far = cast(engine, keep(-front)).unwrap().image;
        let mut most = 0.0f32;
        for ((w, n), f) in whole.pixels.iter().zip(&near.pixels).zip(&far.pixels) {
            for k in 0..4 {
                most = most.max((n[k] + (1.0 - n[3]) * f[k] - w[k]).abs());
            }
        }
        assert!(covered(&near) > 500 && covered(&far) > 500, "{name}: both halves draw");
        assert!(most <= 1e-2, "{name}: the halves composited differ from the whole cast by {most}");
    }
    assert_clean(&g);
}
