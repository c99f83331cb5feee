//! Reduced-resolution rendering (`RenderOptions::render_scale`, src/resample.rs): the coarse frame
//! is the backend's own frame of `scaled_camera`, resampled; close to the full-size frame where
//! voxels cover several pixels; bad scales are typed errors.
use super::common;
use crate::resample::{scaled_camera, upsample};
use crate::scene::peer;
use crate::ImageF32;
use crate::RaycastOptions;
use crate::{classify, scene, Camera, Error, Kernel, Raster, RenderOptions, Renderer};

fn opts(raster: Raster, kernel: Kernel, scale: f32) -> RenderOptions {
    let mut o = RenderOptions::default();
    o.raster = raster;
    o.kernel = kernel;
    o.render_scale = scale;
    o
}

fn peer64(r: &mut Renderer) -> Camera {
    r.set_scene(classify::classify(&peer::volume(64).unwrap(), &peer::transfer_function(), None).unwrap()).unwrap();
    // ~3.5 px per voxel, as the peers' 128³ scene at 512².
    peer::camera(64, 256)
}

/// PSNR of 8-bit RGB over black, over pixels where either image has coverage.
fn psnr(a: &ImageF32, b: &ImageF32) -> f64 {
    let (mut se, mut n) = (0.0f64, 0usize);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        if p[3] <= 1.0 / 255.0 && q[3] <= 1.0 / 255.0 {
            continue;
        }
        for c in 0..3 {
            let (x, y) = ((p[c].clamp(0.0, 1.0) * 255.0).round() as f64, (q[c].clamp(0.0, 1.0) * 255.0).round() as f64);
            se += (x - y).powi(2);
        }
        n += 3;
    }
    assert!(n > 3000, "the object covers the frame");
    10.0 * (255.0f64.powi(2) / (se / n as f64).max(1e-12)).log10()
}

#[test]
fn a_scaled_frame_is_the_coarse_frame_resampled() {
    let mut r = common::gpu();
    let cam = peer64(&mut r);
    for raster in [Raster::Compute, Raster::Points, Raster::Graphics] {
        let o = opts(raster, Kernel::Narrow, 0.5);
        let scaled = r.render(&cam, &o).unwrap();
        assert!(scaled.timings.iter().any(|t| t.stage == "upsample"), "{raster}: the resampling is timed");
        assert_eq!((scaled.image.width, scaled.image.height), (cam.width, cam.height));
        let low = scaled_camera(&cam, 0.5).unwrap();
        assert_eq!((low.width, low.height), (128, 128));
        let coarse = r.render(&low, &opts(raster, Kernel::Narrow, 1.0)).unwrap().image;
        let expect = upsample(&coarse, cam.width, cam.height).unwrap();
        assert!(expect.pixels.iter().any(|p| p[3] > 0.0));
        assert_eq!(scaled.image, expect, "{raster}");
    }
    // The ray caster takes the same knob.
    let rc = |scale| RaycastOptions { step: 1.0, render_scale: scale, ..Default::default() };
    let scaled = r.raycast(&cam, &rc(0.5)).unwrap();
    assert!(scaled.timings.iter().any(|t| t.stage == "upsample"));
    let coarse = r.raycast(&scaled_camera(&cam, 0.5).unwrap(), &rc(1.0)).unwrap().image;
    assert_eq!(scaled.image, upsample(&coarse, cam.width, cam.height).unwrap(), "ray caster");
    assert!(matches!(r.raycast(&cam, &rc(0.0)), Err(Error::InvalidArgument(_))));
    common::assert_clean(&r);
    // The CPU mirrors take the same path.
    let mut c = common::cpu();
    c.set_scene(scene::build("cube40").unwrap()).unwrap();
    let cam = Camera::framing(c.scene().unwrap().grid(), 96, 72);
    let o = opts(Raster::Graphics, Kernel::Gaussian, 0.5);
    let low = scaled_camera(&cam, 0.5).unwrap();
    let coarse = c.render(&low, &opts(Raster::Graphics, Kernel::Gaussian, 1.0)).unwrap().image;
    assert_eq!(c.render(&cam, &o).unwrap().image, upsample(&coarse, 96, 72).unwrap());
    // Analytically: a linear ramp survives the resampling. A full-size pixel centre X lies at
    // 0.5 X - 0.25 on the half-size grid (clamped at its edges), where the ramp is linear.
    let ramp = |x: f64, y: f64| 0.01 * x + 0.02 * y;
    let coarse = crate::ImageF32 {
        width: 8,
        height: 6,
        pixels: (0..48).map(|i| [ramp((i % 8) as f64, (i / 8) as f64) as f32, 0.0, 0.0, 1.0]).collect(),
    };
    let fine = upsample(&coarse, 16, 12).unwrap();
    for (i, p) in fine.pixels.iter().enumerate() {
        let at = |x: usize, n: f64| (0.5 * x as f64 - 0.25).clamp(0.0, n - 1.0);
        let want = ramp(at(i % 16, 8.0), at(i / 16, 6.0));
        assert!((p[0] as f64 - want).abs() < 1e-6 && p[3] == 1.0, "pixel {i}: {} against {want}", p[0]);
    }
}

/// Where a voxel covers ~3.5 px (the peers' scene), half the grid changes little: the scaled frame
/// stays within a few 8-bit steps of the full one, far closer than the full frame shifted by one
/// pixel (what a misregistered resampling would give).
#[test]
fn half_the_grid_stays_close_to_the_full_frame_where_voxels_are_magnified() {
    let mut r = common::gpu();
    let cam = peer64(&mut r);
    for kernel in [Kernel::Gaussian, Kernel::Narrow] {
        let full = r.render(&cam, &opts(Raster::Compute, kernel, 1.0)).unwrap().image;
        let half = r.render(&cam, &opts(Raster::Compute, kernel, 0.5)).unwrap().image;
        let mut shifted = full.clone();
        let w = full.width as usize;
        for (i, p) in shifted.pixels.iter_mut().enumerate() {
            if i % w + 1 < w {
                *p = full.pixels[i + 1];
            }
        }
        let (scaled_db, shift_db) = (psnr(&half, &full), psnr(&shifted, &full));
        eprintln!("{kernel:?}: half grid {scaled_db:.1} dB, one-pixel shift {shift_db:.1} dB");
        assert!(scaled_db >= 45.0, "{kernel:?}: {scaled_db:.1} dB");
        assert!(scaled_db >= shift_db + 6.0, "{kernel:?}: {scaled_db:.1} vs shifted {shift_db:.1} dB");
    }
    common::assert_clean(&r);
}

#[test]
fn bad_render_scales_are_typed_errors() {
    let mut c = common::cpu();
    c.set_scene(scene::build("cube40").unwrap()).unwrap();
    let cam = Camera::framing(c.scene().unwrap().grid(), 32, 32);
    for bad in [0.0, -1.0, 1.01, f32::NAN, f32::INFINITY, 0.01] {
        match c.render(&cam, &opts(Raster::Graphics, Kernel::Gaussian, bad)) {
            Err(Error::InvalidArgument(m)) => assert!(m.contains("render scale"), "{bad}: {m}"),
            other => panic!("{bad}: {other:?}"),
        }
    }
    // The smallest scale still draws at least one row and column.
    let tiny = Camera { width: 3, height: 2, ..cam };
    let img = c.render(&tiny, &opts(Raster::Graphics, Kernel::Gaussian, crate::resample::MIN_RENDER_SCALE)).unwrap();
    assert_eq!((img.image.width, img.image.height), (3, 2));
}
