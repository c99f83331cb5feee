//! Isosurface splats (`--mode iso`): against the ray caster's first crossing (depth and
//! coverage), the GPU against the CPU mirrors, a new value per frame, and what they refuse.
mod common;
use common::{assert_clean, assert_mirrors, cpu, gpu};
use glam::Vec3;
use voxsplat::{Camera, Grid, Mode, RaycastOptions, RenderOptions, SplatSet};

/// A ball whose value falls linearly from 1 at its centre to 0 at `radius` (every voxel with a
/// value is a splat, so the set holds the whole field): its isosurface at v is the sphere of
/// radius (1 - v) radius.
fn ball(n: u32, radius: f32) -> SplatSet {
    let grid = Grid::centered([n; 3], [1.0; 3]).unwrap();
    let c = (n as f32 - 1.0) / 2.0;
    SplatSet::from_fn_valued(grid, |i, j, k| {
        let r = Vec3::new(i as f32 - c, j as f32 - c, k as f32 - c).length();
        let v = 1.0 - r / radius;
        (v > 0.0).then_some(([0.5, 0.5, 0.5, 0.1], v))
    })
    .unwrap()
}

fn iso(v: f32) -> RenderOptions {
    let mut o = RenderOptions::default();
    o.mode = Mode::Iso;
    o.iso = Some(v);
    o
}

fn cast(v: f32) -> RaycastOptions {
    let mut o = RaycastOptions::default();
    o.mode = Mode::Iso;
    o.iso = Some(v);
    o.step = 0.25;
    o
}

#[test]
fn smoke() {
    let set = ball(32, 14.0);
    let cam = Camera::framing(set.grid(), 96, 96);
    let mut g = gpu();
    let mut c = cpu();
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set).unwrap();
    let a = g.render(&cam, &iso(0.5)).unwrap();
    let b = c.render(&cam, &iso(0.5)).unwrap();
    println!("splats {} {}", a.stats.splats, b.stats.splats);
    voxsplat::output::write_image(&a.image, std::path::Path::new("/tmp/iso_gpu.png")).unwrap();
    let r = c.raycast(&cam, &cast(0.5)).unwrap();
    let rg = g.raycast(&cam, &cast(0.5)).unwrap();
    voxsplat::output::write_image(&r.image, std::path::Path::new("/tmp/iso_rc.png")).unwrap();
    let cov = |img: &voxsplat::ImageF32| img.pixels.iter().filter(|p| p[3] >= 0.5).count();
    println!("coverage splats {} rc {} rcg {}", cov(&a.image), cov(&r.image), cov(&rg.image));
    assert_mirrors(&a.image, &b.image, "iso");
    assert_mirrors(&rg.image, &r.image, "iso rc");
    assert_clean(&g);
}

#[test]
fn radius_study() {
    let set = ball(48, 40.0);
    let mut c = cpu();
    c.set_scene(set.clone()).unwrap();
    for (name, cam) in [("framing", Camera::framing(set.grid(), 128, 128)), ("close", voxsplat::scene::close_view(set.grid(), 128))] {
        for v in [0.3f32, 0.5, 0.7] {
            let a = c.render(&cam, &iso(v)).unwrap();
            let r = c.raycast(&cam, &cast(v)).unwrap();
            let (mut both, mut holes, mut extra) = (0, 0, 0);
            for (p, q) in a.image.pixels.iter().zip(&r.image.pixels) {
                match (p[3] >= 0.5, q[3] >= 0.5) {
                    (true, true) => both += 1,
                    (false, true) => holes += 1,
                    (true, false) => extra += 1,
                    _ => {}
                }
            }
            if v == 0.3 {
                let mut d = a.image.clone();
                for (p, q) in d.pixels.iter_mut().zip(&r.image.pixels) {
                    *p = match (p[3] >= 0.5, q[3] >= 0.5) { (false, true) => [1.0, 0.0, 0.0, 1.0], (true, false) => [0.0, 1.0, 0.0, 1.0], _ => *p };
                }
                voxsplat::output::write_image(&d, std::path::Path::new(&format!("/tmp/iso_{name}.png"))).unwrap();
            }
            println!("{name} iso {v}: rc {} splats {} holes {holes} extra {extra}", both + holes, both + extra);
        }
    }
}
