//! The host's depth buffer (`RenderOptions::depth`): a plane of host geometry through a volume
//! hides exactly what lies behind it (the same frame as a clipping plane there), on the device and
//! the mirrors, in every raster; what it refuses.
mod common;
use common::{assert_clean, assert_mirrors, cpu, gpu};
use glam::{Mat4, Vec4};
use std::sync::Arc;
use voxsplat::classify::classify;
use voxsplat::{Camera, Clip, DepthBuffer, DepthFormat, Projection, Raster, RenderOptions, Renderer};

/// A host depth buffer of a plane facing the camera at eye depth `d`, drawn with the camera's
/// own projection.
fn plane_depth(cam: &Camera, d: f32, format: DepthFormat) -> DepthBuffer {
    let proj = cam.proj();
    let c = proj * Vec4::new(0.0, 0.0, -d, 1.0);
    let z = c.z / c.w;
    let texel = match format {
        DepthFormat::D32 => z.to_bits(),
        DepthFormat::D24S8 => ((z * 16777215.0).round() as u32) | (0x55 << 24),
    };
    DepthBuffer {
        width: cam.width,
        height: cam.height,
        format,
        texels: vec![texel; (cam.width * cam.height) as usize],
        projection: proj,
    }
}

/// The clipping plane that keeps what lies at eye depth at most `d`.
fn clip_at(cam: &Camera, d: f32) -> Clip {
    let f = cam.forward();
    Clip::new(&[(-f).extend(f.dot(cam.eye) + d)], None).unwrap()
}

fn cameras(set: &voxsplat::SplatSet) -> Vec<Camera> {
    let mut cam = Camera::framing(set.grid(), 72, 64);
    let mut ortho = cam;
    let r = set.grid().diagonal() * 0.5;
    ortho.projection = Projection::Orthographic { height: 2.2 * r };
    ortho.near = -2.0 * r;
    cam.projection = Projection::Perspective { fov_y_deg: 40.0 };
    vec![cam, ortho]
}

fn depth_of_centre(cam: &Camera, set: &voxsplat::SplatSet) -> f32 {
    (set.grid().center() - cam.eye).dot(cam.forward())
}

#[test]
fn a_plane_in_the_depth_buffer_hides_what_a_clipping_plane_there_cuts() {
    let set = classify(&common::blob([26, 22, 18]), &common::blob_tf(), None).unwrap();
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let mut c = cpu();
    c.set_scene(set.clone()).unwrap();
    for cam in cameras(&set) {
        // A little off the centre so that no splat sits on the plane.
        let d = depth_of_centre(&cam, &set) + 0.137;
        for raster in [Raster::Compute, Raster::Graphics, Raster::Points] {
            let mut o = RenderOptions::default();
            o.raster = raster;
            let whole = g.render(&cam, &o).unwrap().image;
            let mut clipped = o.clone();
            clipped.clip = clip_at(&cam, d);
            let want = g.render(&cam, &clipped).unwrap().image;
            o.depth = Some(Arc::new(plane_depth(&cam, d, DepthFormat::D32)));
            let got = g.render(&cam, &o).unwrap().image;
            let tag = format!("{raster} {:?}", cam.projection);
            let (worst, _) = common::diff(&got, &want);
            assert!(worst < 1e-6, "{tag}: the depth buffer's frame against the clipped one: {worst}");
            let (hidden, _) = common::diff(&got, &whole);
            assert!(hidden > 0.05, "{tag}: the plane hides part of the blob ({hidden})");
            assert_mirrors(&got, &c.render(&cam, &o).unwrap().image, &tag);
        }
    }
    assert_clean(&g);
}

#[test]
fn a_d24_depth_buffer_and_a_projection_mode_and_a_bricked_store_take_it_too() {
    let vol = common::blob([26, 22, 18]);
    let set = classify(&vol, &common::blob_tf(), None).unwrap();
    let cam = cameras(&set)[0];
    let d = depth_of_centre(&cam, &set) + 0.137;
    let depth = Some(Arc::new(plane_depth(&cam, d, DepthFormat::D24S8)));
    let store = voxsplat::bricks::BrickStore::build(&vol).unwrap();
    let scene = voxsplat::bricks::BrickScene::new(store, common::blob_tf(), None).unwrap();
    let mut g = gpu();
    let mut c = cpu();
    let mut o = RenderOptions::default();
    o.depth = depth;
    for (what, mode, bricked) in
        [("dense", voxsplat::Mode::Composite, false), ("mip", voxsplat::Mode::Mip, false), ("bricked", voxsplat::Mode::Composite, true)]
    {
        o.mode = mode;
        let set_up = |r: &mut Renderer| {
            if bricked {
                r.set_bricks(scene.clone()).unwrap()
            } else {
                r.set_scene(set.clone()).unwrap()
            }
        };
        set_up(&mut g);
        set_up(&mut c);
        let got = g.render(&cam, &o).unwrap().image;
        assert_mirrors(&got, &c.render(&cam, &o).unwrap().image, what);
        let mut open = o.clone();
        open.depth = None;
        let whole = g.render(&cam, &open).unwrap().image;
        let (hidden, _) = common::diff(&got, &whole);
        assert!(hidden > 0.05, "{what}: the plane hides part of the blob ({hidden})");
    }
    assert_clean(&g);
}

#[test]
fn a_depth_buffer_that_does_not_fit_is_refused() {
    let set = classify(&common::blob([12, 12, 12]), &common::blob_tf(), None).unwrap();
    let mut r = cpu();
    r.set_scene(set.clone()).unwrap();
    let cam = Camera::framing(set.grid(), 32, 32);
    let good = plane_depth(&cam, 10.0, DepthFormat::D32);
    let cases: Vec<(DepthBuffer, &str)> = vec![
        (DepthBuffer { width: 16, ..good.clone() }, "must match"),
        (DepthBuffer { texels: vec![0; 5], ..good.clone() }, "of 5 texels"),
        (DepthBuffer { projection: Mat4::ZERO, ..good.clone() }, "invertible"),
    ];
    for (d, says) in cases {
        let mut o = RenderOptions::default();
        o.depth = Some(Arc::new(d));
        let e = r.render(&cam, &o).unwrap_err().to_string();
        assert!(e.contains(says), "{e}");
    }
    let mut o = RenderOptions::default();
    o.depth = Some(Arc::new(good));
    o.composite = voxsplat::Composite::Sheet;
    assert!(r.render(&cam, &o).unwrap_err().to_string().contains("--composite splat"));
}
