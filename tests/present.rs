//! Frames into a host's image (issue 27 item 1): `render_to` writes, on the device, the bytes the
//! mirror of `present.comp` and of the blit says, in every swapchain format, over a background or
//! transparent, in the modes whose final images differ (accumulation, raster target, two slots);
//! semaphores order frames; bad targets are refused.
use super::common;
use crate::cpu::present::{decode, encode, host_texel, present_pixel};
use crate::plan::{over_bits, present_push};
use crate::vk::ImageLayout as IL;
use crate::{scene, Camera, Composite, Motion, Raster, RenderOptions, TargetFormat};
use common::assert_clean;

fn options(composite: Composite, raster: Raster, background: Option<[f32; 4]>) -> RenderOptions {
    let mut o = RenderOptions::default();
    (o.composite, o.raster, o.background) = (composite, raster, background);
    o
}

/// Largest difference between two images' texels, as values (8-bit steps are 1/255).
fn most(format: TargetFormat, a: &[u8], b: &[u8]) -> f32 {
    assert_eq!(a.len(), b.len());
    let (a, b) = (decode(format, a).unwrap(), decode(format, b).unwrap());
    // Compare in the stored encoding: an sRGB byte step is not a fixed linear step.
    let stored = |p: [f32; 4]| {
        if matches!(format, TargetFormat::Bgra8Srgb | TargetFormat::Rgba8Srgb) {
            [0, 1, 2].map(|c| crate::cpu::present::to_srgb(p[c])).into_iter().chain([p[3]]).collect::<Vec<_>>()
        } else {
            p.to_vec()
        }
    };
    a.iter()
        .zip(&b)
        .flat_map(|(x, y)| stored(*x).into_iter().zip(stored(*y)).map(|(u, v)| (u - v).abs()))
        .fold(0.0, f32::max)
}

#[test]
fn render_to_writes_what_the_mirror_says_in_every_format_and_mode() {
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 80, 64);
    let mut g = common::gpu();
    g.set_scene(set).unwrap();
    let slotted = {
        let mut o = options(Composite::Splat, Raster::Graphics, Some([0.1, 0.2, 0.3, 1.0]));
        let mut m = Motion::straight(glam::Mat4::from_translation(glam::Vec3::new(6.0, 0.0, 0.0)), 0.5);
        m.profile = crate::BlurProfile::Slotted;
        o.motion = Some(m);
        o
    };
    let cases = [
        ("tile compositor, opaque background", options(Composite::Splat, Raster::Compute, Some([0.1, 0.2, 0.3, 1.0]))),
        ("quads, transparent", options(Composite::Splat, Raster::Graphics, None)),
        (
            "sheets, half-transparent background",
            options(Composite::Sheet, Raster::Graphics, Some([1.0, 0.5, 0.0, 0.5])),
        ),
        ("slotted blur", slotted),
    ];
    for format in TargetFormat::ALL {
        let image = g.target_image(format, cam.width, cam.height).unwrap();
        for (i, (what, o)) in cases.iter().enumerate() {
            let first = if i == 0 { IL::UNDEFINED } else { IL::SHADER_READ_ONLY_OPTIMAL };
            let target = image.target(first, IL::SHADER_READ_ONLY_OPTIMAL).unwrap();
            g.render_to(&cam, o, &target).unwrap();
            let got = g.read_target(&target).unwrap();
            // The mirror: the frame as render() reads it back without a background, presented on the
            // host as present.comp does for this format, encoded as the blit does.
            let mut plain = o.clone();
            plain.background = None;
            let frame = g.render(&cam, &plain).unwrap().image;
            let push = present_push(o.background, 1, format.linear(), cam.width, cam.height);
            let presented: Vec<[f32; 4]> =
                frame.pixels.iter().map(|&p| present_pixel(&push, p, [0.0; 4], [0.0; 4])).collect();
            let want = encode(format, &presented);
            let step = if format == TargetFormat::Rgba16Float { 2e-3 } else { 1.0 / 255.0 + 1e-6 };
            let d = most(format, &got, &want);
            assert!(d <= step, "{format:?}, {what}: {d} from the mirror");
            let lit = presented.iter().filter(|p| p[0] + p[1] + p[2] > 0.05).count();
            assert!(lit > 1000, "{format:?}, {what}: only {lit} pixels lit");
        }
    }
    assert_clean(&g);
}

#[test]
fn a_background_goes_through_present_on_both_engines_and_keeps_the_png_bytes() {
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 72, 72);
    let (mut g, mut c) = (common::gpu(), common::cpu());
    g.set_scene(set.clone()).unwrap();
    c.set_scene(set).unwrap();
    for (composite, raster) in [(Composite::Splat, Raster::Compute), (Composite::Splat, Raster::Graphics)] {
        let o = options(composite, raster, Some([0.2, 0.4, 0.6, 1.0]));
        let a = g.render(&cam, &o).unwrap().image;
        let b = c.render(&cam, &o).unwrap().image;
        common::assert_mirrors(&a, &b, &format!("{raster} over a background"));
        assert!(a.pixels.iter().all(|p| (p[3] - 1.0).abs() < 1e-6), "an opaque background leaves alpha 1");
        // An empty pixel is the background itself.
        assert!(a.pixels[0].iter().zip([0.2, 0.4, 0.6, 1.0]).all(|(x, y)| (x - y).abs() < 1e-6), "{:?}", a.pixels[0]);
    }
    // The sRGB target gets the PNG's bytes back: render_to into B8G8R8A8_SRGB, decoded by hand.
    let o = options(Composite::Splat, Raster::Graphics, Some([0.0, 0.0, 0.0, 1.0]));
    let png = crate::output::to_rgba8(&g.render(&cam, &o).unwrap().image);
    let image = g.target_image(TargetFormat::Bgra8Srgb, cam.width, cam.height).unwrap();
    let target = image.target(IL::UNDEFINED, IL::TRANSFER_SRC_OPTIMAL).unwrap();
    g.render_to(&cam, &o, &target).unwrap();
    let bgra = g.read_target(&target).unwrap();
    let worst = png
        .chunks_exact(4)
        .zip(bgra.chunks_exact(4))
        .map(|(p, t)| [p[0].abs_diff(t[2]), p[1].abs_diff(t[1]), p[2].abs_diff(t[0]), p[3].abs_diff(t[3])])
        .flat_map(|d| d.into_iter())
        .max()
        .unwrap();
    assert!(worst <= 1, "the sRGB target differs from the PNG by {worst} steps");
    assert_clean(&g);
}

#[test]
fn render_to_over_the_hosts_image_composites_the_frame_over_what_it_held() {
    // The host's drawing: a frame of the cube over an opaque background; then a frame from
    // another eye, transparent where it misses the cube, drawn over it.
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 80, 64);
    let moved = Camera { eye: cam.eye + glam::Vec3::new(25.0, 10.0, 0.0), ..cam };
    let mut g = common::gpu();
    g.set_scene(set).unwrap();
    let host = options(Composite::Splat, Raster::Compute, Some([0.1, 0.3, 0.8, 1.0]));
    let over = options(Composite::Splat, Raster::Compute, None);
    let frame = g.render(&moved, &over).unwrap().image;
    let layout = IL::TRANSFER_SRC_OPTIMAL;
    for format in TargetFormat::ALL {
        let image = g.target_image(format, cam.width, cam.height).unwrap();
        g.render_to(&cam, &host, &image.target(IL::UNDEFINED, layout).unwrap()).unwrap();
        let held = g.read_target(&image.target(layout, layout).unwrap()).unwrap();
        // SAFETY: voxsplat's image, made with TRANSFER_SRC usage, holds the frame just drawn.
        let target = unsafe { image.target(layout, layout).unwrap().over() }.unwrap();
        g.render_to(&moved, &over, &target).unwrap();
        let got = g.read_target(&target).unwrap();
        // The same drawing written by the host (`TargetImage::over`) gets the same frame.
        let written = g.target_image(format, cam.width, cam.height).unwrap();
        g.render_to(&moved, &over, &written.over(&held, layout).unwrap()).unwrap();
        assert!(g.read_target(&written.target(layout, layout).unwrap()).unwrap() == got, "{format:?}: written");
        // The mirror: the frame presented for this format over the held texels, as stored.
        let mut push = present_push(None, 1, format.linear(), cam.width, cam.height);
        push.sources |= over_bits(format);
        let words: Vec<u32> = held.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let presented: Vec<[f32; 4]> = (0..frame.pixels.len())
            .map(|i| present_pixel(&push, frame.pixels[i], [0.0; 4], host_texel(&push, &words, i)))
            .collect();
        let step = if format == TargetFormat::Rgba16Float { 2e-3 } else { 1.0 / 255.0 + 1e-6 };
        let d = most(format, &got, &encode(format, &presented));
        assert!(d <= step, "{format:?}: {d} from the mirror");
        // Over a host image of one colour the frame is the frame over that background.
        let flat = g.target_image(format, cam.width, cam.height).unwrap();
        let bg = options(Composite::Splat, Raster::Compute, Some([0.1, 0.3, 0.8, 1.0]));
        let empty_cam = Camera { eye: cam.eye * 40.0, target: cam.eye * 41.0, ..cam };
        g.render_to(&empty_cam, &bg, &flat.target(IL::UNDEFINED, layout).unwrap()).unwrap();
        // SAFETY: as above.
        g.render_to(&moved, &over, &unsafe { flat.target(layout, layout).unwrap().over() }.unwrap()).unwrap();
        let on_flat = g.read_target(&flat.target(layout, layout).unwrap()).unwrap();
        let alone = g.target_image(format, cam.width, cam.height).unwrap();
        g.render_to(&moved, &bg, &alone.target(IL::UNDEFINED, layout).unwrap()).unwrap();
        let want = g.read_target(&alone.target(layout, layout).unwrap()).unwrap();
        let d = most(format, &on_flat, &want);
        assert!(d <= step, "{format:?}: over one colour differs from that background by {d}");
        // Both show: the host's drawing where the frame is empty, the frame where it is opaque,
        // and neither alone in between.
        // (8-bit texels pass through exactly; halves through display values and back.)
        let (got_v, held_v) = (decode(format, &got).unwrap(), decode(format, &held).unwrap());
        let apart = |i: usize| (0..4).map(|c| (got_v[i][c] - held_v[i][c]).abs()).fold(0.0, f32::max);
        let kept = if format == TargetFormat::Rgba16Float { 2e-3 } else { 0.0 };
        let empty = (0..frame.pixels.len()).filter(|&i| frame.pixels[i][3] == 0.0).collect::<Vec<_>>();
        assert!(empty.len() > 500 && empty.iter().all(|&i| apart(i) <= kept), "{format:?}: host kept");
        let changed = (0..frame.pixels.len()).filter(|&i| apart(i) > 0.02).count();
        assert!(changed > 1000, "{format:?}: the frame drew over {changed} pixels only");
    }
    // Refused: a background (the host's image is the frame's), a target with nothing to draw over,
    // a render scale (the host's image is read pixel for pixel).
    let image = g.target_image(TargetFormat::Rgba8Unorm, cam.width, cam.height).unwrap();
    g.render_to(&cam, &host, &image.target(IL::UNDEFINED, layout).unwrap()).unwrap();
    // SAFETY: as above.
    let target = unsafe { image.target(layout, layout).unwrap().over() }.unwrap();
    let e = g.render_to(&cam, &host, &target).unwrap_err();
    assert!(e.to_string().contains("no background"), "{e}");
    let mut scaled = over.clone();
    scaled.render_scale = 0.5;
    let e = g.render_to(&cam, &scaled, &target).unwrap_err();
    assert!(e.to_string().contains("render scale 1"), "{e}");
    // SAFETY: as above.
    let e = unsafe { image.target(IL::UNDEFINED, layout).unwrap().over() }.unwrap_err();
    assert!(e.to_string().contains("nothing to draw over"), "{e}");
    let e = image.over(&[0; 12], layout).unwrap_err();
    assert!(e.to_string().contains("12 bytes of drawing for a 80 x 64 image"), "{e}");
    assert_clean(&g);
}

/// A 64 x 64 RGBA8 target of voxsplat's `image`, with raw semaphores, as a host would pass them.
fn rgba8_target(
    image: &crate::vk::TargetImage,
    layouts: (IL, IL),
    wait: &[crate::vk::ash::vk::Semaphore],
    signal: &[crate::vk::ash::vk::Semaphore],
) -> crate::vk::HostTarget {
    let format = crate::vk::vk_format(TargetFormat::Rgba8Unorm);
    // SAFETY: the image and semaphores are voxsplat's and outlive every frame that uses them; each
    // wait semaphore was signalled by the frame before.
    unsafe { crate::vk::HostTarget::new(image.raw(), format, (64, 64), layouts, wait, signal) }.unwrap()
}

#[test]
fn semaphores_order_frames_into_one_image() {
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 64, 64);
    let mut g = common::gpu();
    g.set_scene(set).unwrap();
    let ctx = g.context().unwrap().clone();
    let (a, b) = (crate::vk::Semaphore::new(&ctx).unwrap(), crate::vk::Semaphore::new(&ctx).unwrap());
    let image = g.target_image(TargetFormat::Rgba8Unorm, 64, 64).unwrap();
    let o = options(Composite::Splat, Raster::Graphics, Some([0.0, 0.0, 0.0, 1.0]));
    let mut last = Vec::new();
    // Each frame signals the semaphore the next one waits on, as a swapchain loop does.
    for f in 0..4 {
        let (wait, signal) = if f % 2 == 0 { (&b, &a) } else { (&a, &b) };
        let waits: Vec<_> = if f == 0 { vec![] } else { vec![wait.raw()] };
        let old = if f == 0 { IL::UNDEFINED } else { IL::GENERAL };
        let target = rgba8_target(&image, (old, IL::GENERAL), &waits, &[signal.raw()]);
        g.render_to(&Camera { eye: cam.eye + glam::Vec3::new(f as f32, 0.0, 0.0), ..cam }, &o, &target).unwrap();
        last = g.read_target(&target).unwrap();
    }
    // The fourth frame signalled `b` with nobody waiting; a last frame waits on it so nothing dangles.
    let target = rgba8_target(&image, (IL::GENERAL, IL::GENERAL), &[b.raw()], &[]);
    let moved = Camera { eye: cam.eye + glam::Vec3::new(3.0, 0.0, 0.0), ..cam };
    g.render_to(&moved, &o, &target).unwrap();
    assert_eq!(g.read_target(&target).unwrap(), last, "the same camera gives the same bytes");
    assert_clean(&g);
}

#[test]
fn bad_targets_are_refused_with_typed_errors() {
    let set = scene::build("cube60").unwrap();
    let cam = Camera::framing(set.grid(), 64, 48);
    let mut g = common::gpu();
    g.set_scene(set.clone()).unwrap();
    let image = g.target_image(TargetFormat::Rgba8Unorm, 32, 32).unwrap();
    let target = image.target(IL::UNDEFINED, IL::GENERAL).unwrap();
    let e = g.render_to(&cam, &RenderOptions::default(), &target).unwrap_err();
    assert!(e.to_string().contains("does not fit"), "{e}");
    let wrong = crate::vk::target_format(crate::vk::Format::R8_UNORM).unwrap_err();
    assert!(wrong.to_string().contains("R16G16B16A16_SFLOAT"), "{wrong}");
    assert!(image.target(IL::UNDEFINED, IL::UNDEFINED).is_err(), "a target left undefined");
    let image = g.target_image(TargetFormat::Rgba8Unorm, 64, 48).unwrap();
    let target = image.target(IL::UNDEFINED, IL::GENERAL).unwrap();
    let mut scaled = RenderOptions::default();
    scaled.render_scale = 0.01;
    assert!(g.render_to(&cam, &scaled, &target).is_err(), "a render scale below the least");
    let mut bad = RenderOptions::default();
    bad.background = Some([2.0, 0.0, 0.0, 1.0]);
    assert!(g.render(&cam, &bad).unwrap_err().to_string().contains("background"));
    let mut c = common::cpu();
    c.set_scene(set).unwrap();
    assert!(c.target_image(TargetFormat::Rgba8Unorm, 8, 8).is_err(), "no device, no target");
    assert_clean(&g);
}

#[test]
fn a_render_scale_is_stretched_by_the_blit_as_render_resamples_it() {
    let set = scene::build("cube60").unwrap();
    let mut g = common::gpu();
    g.set_scene(set.clone()).unwrap();
    // 128 x 96 at 0.5: a 64 x 48 grid that covers the view exactly; 100 x 70 at 0.5: 35 rows and
    // 50 columns (the blit's whole-pixel region is exact there too); 90 x 70: 45.0 -> 45 columns.
    for (w, h) in [(128u32, 96u32), (100, 70), (90, 70)] {
        let cam = Camera::framing(set.grid(), w, h);
        let mut o = options(Composite::Splat, Raster::Compute, Some([0.0, 0.0, 0.0, 1.0]));
        o.render_scale = 0.5;
        let image = g.target_image(TargetFormat::Rgba8Unorm, w, h).unwrap();
        let target = image.target(IL::UNDEFINED, IL::GENERAL).unwrap();
        let d = g.render_to(&cam, &o, &target).unwrap();
        assert_eq!(d.raster.raster, Raster::Compute);
        let got = decode(TargetFormat::Rgba8Unorm, &g.read_target(&target).unwrap()).unwrap();
        let want = g.render(&cam, &o).unwrap().image;
        let errs: Vec<f32> =
            got.iter().zip(&want.pixels).flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs())).collect();
        let worst = errs.iter().copied().fold(0.0, f32::max);
        let mean = errs.iter().sum::<f32>() / errs.len() as f32;
        // The blit's linear filter is the host's bilinear resampling: one 8-bit rounding apart.
        assert!(worst <= 1.0 / 255.0 + 1e-6 && mean <= 0.5 / 255.0, "{w}x{h}: worst {worst}, mean {mean}");
        let lit = got.iter().filter(|p| p[0] + p[1] + p[2] > 0.05).count();
        assert!(lit > (w * h / 8) as usize, "{w}x{h}: {lit} lit");
    }
    assert_clean(&g);
}
