//! Picking: the first hit on a ball of known centre and radius, the voxel of a MIP's maximum, and
//! what picking refuses.
use super::common;
use crate::classify::{classify, TransferFunction};
use crate::volume::ScalarVolume;
use crate::{Camera, Mode, Projection, RenderOptions};
use common::{cpu, Rng};
use glam::Vec3;

const N: u32 = 40;
const RADIUS: f32 = 12.0;

/// A solid ball of radius `RADIUS` voxels about the grid's centre (unit spacing), value 1 inside,
/// with one voxel of value 2 at `peak`.
fn ball(peak: [u32; 3]) -> ScalarVolume {
    let c = (N as f32 - 1.0) / 2.0;
    let mut values = Vec::new();
    for k in 0..N {
        for j in 0..N {
            for i in 0..N {
                let r = Vec3::new(i as f32 - c, j as f32 - c, k as f32 - c).length();
                values.push(if [i, j, k] == peak {
                    2.0
                } else if r < RADIUS {
                    1.0
                } else {
                    0.0
                });
            }
        }
    }
    ScalarVolume { dims: [N; 3], spacing: [1.0; 3], values }
}

/// Opaque from a quarter of the range up.
fn opaque() -> TransferFunction {
    TransferFunction::from_toml("points = [[0.2, [1, 1, 1, 0]], [0.25, [1, 1, 1, 0.95]]]").unwrap()
}

#[test]
fn a_picked_point_lies_within_a_voxel_of_the_analytic_first_hit() {
    let set = classify(&ball([20, 20, 20]), &opaque(), None).unwrap();
    let mut r = cpu();
    r.set_scene(set).unwrap();
    let mut rng = Rng(4600);
    let (mut tested, mut worst) = (0, 0.0f32);
    for view in 0..10 {
        let eye = rng.dir() * 60.0;
        let cam = Camera {
            eye,
            target: Vec3::ZERO,
            up: if eye.normalize().dot(Vec3::Y).abs() < 0.9 { Vec3::Y } else { Vec3::X },
            projection: if view % 2 == 0 {
                Projection::Perspective { fov_y_deg: 35.0 }
            } else {
                Projection::Orthographic { height: 34.0 }
            },
            near: 1.0,
            far: 200.0,
            width: 96,
            height: 96,
            window: None,
        };
        let o = RenderOptions::default();
        let mut here = 0;
        while here < 100 {
            let (x, y) = (rng.range(0.0, 96.0), rng.range(0.0, 96.0));
            // The analytic first hit of the pixel's ray on the sphere: rays that pass within 0.8
            // radii of the centre (a grazing ray's hit moves far along it for a small error across).
            let (a, dir) = ray(&cam, x, y);
            let b = a.dot(dir);
            let q = b * b - (a.length_squared() - RADIUS * RADIUS);
            let miss = (a - dir * b).length() > 0.8 * RADIUS;
            let p = r.pick(&cam, &o, x, y).unwrap();
            if q <= 0.0 || miss {
                if q <= -4.0 * RADIUS {
                    assert!(p.is_none(), "({x}, {y}) misses the ball by far, yet picked {p:?}");
                }
                continue;
            }
            let hit = a + dir * (-b - q.sqrt());
            let p = p.unwrap_or_else(|| panic!("({x}, {y}) hits the ball at {hit} but picked nothing"));
            let d = p.world.distance(hit);
            worst = worst.max(d);
            assert!(d < 1.0, "view {view} ({x}, {y}): picked {} against the hit {hit}: {d} voxels", p.world);
            assert!((p.value - 0.5).abs() < 1e-6, "the ball's value is half the range: {}", p.value);
            assert!((p.depth - (p.world - cam.eye).dot(cam.forward())).abs() < 1e-3);
            here += 1;
        }
        tested += here;
    }
    eprintln!("{tested} pixels picked, within {worst:.3} voxels of the analytic hit");
    assert_eq!(tested, 1000);
}

/// The pixel position's ray (origin on the near plane, unit direction), as the ray caster's.
fn ray(cam: &Camera, x: f32, y: f32) -> (Vec3, Vec3) {
    let inv = cam.view_proj().inverse();
    let ndc = glam::Vec2::new(x / cam.width as f32 * 2.0 - 1.0, y / cam.height as f32 * 2.0 - 1.0);
    let a = inv.project_point3(ndc.extend(0.0));
    let b = inv.project_point3(ndc.extend(1.0));
    (a, (b - a).normalize())
}

#[test]
fn a_mip_pick_returns_the_voxel_of_the_maximum() {
    let peak = [23, 17, 21];
    let set = classify(&ball(peak), &opaque(), None).unwrap();
    let mut r = cpu();
    r.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 128, 128);
    // The pixel the peak voxel projects to.
    let p = set.grid().position(peak);
    let ndc = cam.view_proj().project_point3(p);
    let (x, y) = ((ndc.x + 1.0) / 2.0 * 128.0, (ndc.y + 1.0) / 2.0 * 128.0);
    let mut o = RenderOptions::default();
    o.mode = Mode::Mip;
    let got = r.pick(&cam, &o, x, y).unwrap().expect("the peak's pixel shows the ball");
    assert_eq!(got.voxel, peak, "{got:?}");
    assert!((got.value - 1.0).abs() < 1e-6, "{got:?}");
    // Composited, the same pixel picks the ball's near surface, not the peak inside it.
    let front = r.pick(&cam, &RenderOptions::default(), x, y).unwrap().unwrap();
    assert!(front.depth < got.depth - 1.0, "{front:?} against {got:?}");
}

#[test]
fn picking_refuses_what_it_cannot_read() {
    let vol = ball([20, 20, 20]);
    let set = classify(&vol, &opaque(), None).unwrap();
    let mut r = cpu();
    let cam = Camera::framing(set.grid(), 32, 32);
    assert!(r.pick(&cam, &RenderOptions::default(), 4.0, 4.0).is_err(), "no scene");
    r.set_scene(set).unwrap();
    for (x, y) in [(-1.0, 3.0), (3.0, 33.0), (f32::NAN, 1.0)] {
        let e = r.pick(&cam, &RenderOptions::default(), x, y).unwrap_err().to_string();
        assert!(e.contains("outside the 32 x 32 image"), "{e}");
    }
}

#[test]
fn a_bricked_store_picks_what_its_dense_splats_pick() {
    let vol = ball([20, 20, 20]);
    let set = classify(&vol, &opaque(), None).unwrap();
    let mut dense = cpu();
    dense.set_scene(set.clone()).unwrap();
    let mut bricked = cpu();
    let store = crate::bricks::BrickStore::build(&vol).unwrap();
    bricked.set_bricks(crate::bricks::BrickScene::new(store, opaque(), None).unwrap()).unwrap();
    let cam = Camera::framing(set.grid(), 64, 64);
    let mut rng = Rng(4605);
    let mut hits = 0;
    for mode in [Mode::Composite, Mode::Mip] {
        let mut o = RenderOptions::default();
        o.mode = mode;
        for _ in 0..200 {
            // Around the centre, where the ball is (and some misses at its edge).
            let (x, y) = (rng.range(22.0, 42.0), rng.range(22.0, 42.0));
            let (a, b) = (dense.pick(&cam, &o, x, y).unwrap(), bricked.pick(&cam, &o, x, y).unwrap());
            assert_eq!(a.is_some(), b.is_some(), "{mode} ({x}, {y})");
            if let (Some(a), Some(b)) = (a, b) {
                // The store keeps values in 16 bits: the same voxel and point to within that.
                assert_eq!(a.voxel, b.voxel, "{mode} ({x}, {y})");
                assert!(a.world.distance(b.world) < 1e-2 && (a.value - b.value).abs() < 1e-4, "{a:?} {b:?}");
                hits += 1;
            }
        }
    }
    assert!(hits > 100, "{hits} pixels hit the ball");
}
