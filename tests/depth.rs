//! The host's depth buffer (`RenderOptions::depth`): a plane of host geometry through a volume
//! hides exactly what lies behind it (the same frame as a clipping plane there), on the device and
//! the mirrors, in every raster; what it refuses.
use super::common;
use crate::classify::classify;
use crate::{Camera, Clip, DepthBuffer, DepthFormat, Projection, Raster, RenderOptions, Renderer};
use common::{assert_clean, assert_mirrors, cpu, gpu};
use glam::{Mat4, Vec4};
use std::sync::Arc;

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

fn cameras(set: &crate::SplatSet) -> Vec<Camera> {
    let mut cam = Camera::framing(set.grid(), 72, 64);
    let mut ortho = cam;
    let r = set.grid().diagonal() * 0.5;
    ortho.projection = Projection::Orthographic { height: 2.2 * r };
    ortho.near = -2.0 * r;
    cam.projection = Projection::Perspective { fov_y_deg: 40.0 };
    vec![cam, ortho]
}

/// A half-float target reading a depth image of `format` cleared to the plane at eye depth `d`
/// (the target image and the depth image live as long as the returned values).
fn target_with_depth(
    g: &Renderer,
    cam: &Camera,
    d: f32,
    format: DepthFormat,
) -> (crate::vk::TargetImage, crate::vk::DepthImage, crate::vk::HostTarget) {
    use crate::vk::ImageLayout as IL;
    let proj = cam.proj();
    let c = proj * Vec4::new(0.0, 0.0, -d, 1.0);
    let depth = g.depth_image(format, cam.width, cam.height, c.z / c.w).unwrap();
    let image = g.target_image(crate::TargetFormat::Rgba16Float, cam.width, cam.height).unwrap();
    let target = depth.attach(image.target(IL::UNDEFINED, IL::TRANSFER_SRC_OPTIMAL).unwrap(), proj).unwrap();
    (image, depth, target)
}

/// The largest difference of a half-float target's texels from `frame` presented as the blit
/// delivers it (linear values, no background).
fn target_against(g: &Renderer, target: &crate::vk::HostTarget, frame: &crate::ImageF32) -> f32 {
    use crate::cpu::present::{decode, present_pixel};
    let got = decode(crate::TargetFormat::Rgba16Float, &g.read_target(target).unwrap()).unwrap();
    let push = crate::plan::present_push(None, 1, true, frame.width, frame.height);
    got.iter()
        .zip(&frame.pixels)
        .map(|(a, &b)| {
            let w = present_pixel(&push, b, [0.0; 4], [0.0; 4]);
            (0..4).map(|k| (a[k] - w[k]).abs()).fold(0.0f32, f32::max)
        })
        .fold(0.0f32, f32::max)
}

fn depth_of_centre(cam: &Camera, set: &crate::SplatSet) -> f32 {
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
    let store = crate::bricks::BrickStore::build(&vol).unwrap();
    let scene = crate::bricks::BrickScene::new(store, common::blob_tf(), None).unwrap();
    let mut g = gpu();
    let mut c = cpu();
    let mut o = RenderOptions::default();
    o.depth = depth;
    for (what, mode, bricked) in [
        ("dense", crate::Mode::Composite, false),
        ("mip", crate::Mode::Mip, false),
        ("bricked", crate::Mode::Composite, true),
    ] {
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
    o.composite = crate::Composite::Sheet;
    assert!(r.render(&cam, &o).unwrap_err().to_string().contains("--accumulate splat"));
}

#[test]
fn render_to_reads_the_hosts_depth_image_on_the_device() {
    let set = classify(&common::blob([26, 22, 18]), &common::blob_tf(), None).unwrap();
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    for cam in cameras(&set) {
        let d = depth_of_centre(&cam, &set) + 0.137;
        // The plane's depth as the host's depth image holds it (D32), against the clipped frame.
        let (_image, _depth, target) = target_with_depth(&g, &cam, d, DepthFormat::D32);
        for raster in [Raster::Compute, Raster::Graphics] {
            let mut o = RenderOptions::default();
            o.raster = raster;
            g.render_to(&cam, &o, &target).unwrap();
            let mut clipped = o.clone();
            clipped.clip = clip_at(&cam, d);
            let want = g.render(&cam, &clipped).unwrap().image;
            let worst = target_against(&g, &target, &want);
            // Half floats: 2e-3 as tests/present.rs allows.
            assert!(
                worst <= 2e-3,
                "{raster} {:?}: render_to with the depth image against the clipped frame: {worst}",
                cam.projection
            );
            // Both a depth image and a depth buffer: refused.
            let mut both = o.clone();
            both.depth = Some(Arc::new(plane_depth(&cam, d, DepthFormat::D32)));
            assert!(g.render_to(&cam, &both, &target).unwrap_err().to_string().contains("give one"));
        }
        let mut scaled = RenderOptions::default();
        scaled.render_scale = 0.5;
        assert!(g.render_to(&cam, &scaled, &target).unwrap_err().to_string().contains("render scale 1"));
    }
    assert_clean(&g);
}

#[test]
fn a_d24s8_depth_image_is_read_on_the_device_as_the_mirror_reads_its_texels() {
    let set = classify(&common::blob([26, 22, 18]), &common::blob_tf(), None).unwrap();
    let mut g = gpu();
    g.set_scene(set.clone()).unwrap();
    let cam = cameras(&set)[0];
    let d = depth_of_centre(&cam, &set) + 0.137;
    let (_image, _depth, target) = target_with_depth(&g, &cam, d, DepthFormat::D24S8);
    let o = RenderOptions::default();
    g.render_to(&cam, &o, &target).unwrap();
    // The same depth as texels: the plane's depth rounded to 24 bits, as the device stores it.
    let mut with = o.clone();
    with.depth = Some(Arc::new(plane_depth(&cam, d, DepthFormat::D24S8)));
    let want = g.render(&cam, &with).unwrap().image;
    let worst = target_against(&g, &target, &want);
    assert!(worst <= 2e-3, "the D24S8 image against its texels: {worst}");
    assert_clean(&g);
}
