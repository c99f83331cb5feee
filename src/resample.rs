//! Reduced-resolution rendering (`RenderOptions::render_scale`): the frame is drawn on a coarser
//! pixel grid over the same view and resampled to the camera's size on the host.
//!
//! Why: where voxels project to several pixels (the peers' scene: ~3.5 px per voxel, 10–14-px
//! footprints), the image carries no detail finer than the reconstruction kernel, yet every stage
//! after `splat_params` pays per pixel: the footprints' fill, the tile lists, the sheets. A grid
//! matched to the kernel's width costs a fraction of that; the error it adds is measured against
//! the full-size truth (docs/RESULTS.md, peers section), not assumed. It is the splatting analogue
//! of a ray caster's image sample distance (its inverse).
use crate::camera::Camera;
use crate::error::{Error, Result};
use crate::image::ImageF32;
use crate::options::{Rendered, StageTime};
use rayon::prelude::*;

pub use crate::options::{check_scale, MIN_RENDER_SCALE};

/// The camera that draws `camera`'s view at `scale`: `round(height * scale)` rows and enough
/// columns to cover the full width. Pixels stay square and the view's vertical extent is kept, so
/// both grids share their centre and one pixel of the coarse grid is exactly `height / rows`
/// pixels of the full one on both axes (`upsample` relies on that).
pub fn scaled_camera(camera: &Camera, scale: f32) -> Result<Camera> {
    check_scale(scale)?;
    if scale != 1.0 && camera.window.is_some() {
        return Err(Error::Unsupported(
            "a render scale below 1 draws the whole frame: a window of it (a camera's `window`) cannot be drawn coarser"
                .into(),
        ));
    }
    let rows = ((camera.height as f64 * scale as f64).round() as u32).max(1);
    let cols = ((camera.width as f64 * rows as f64 / camera.height as f64).ceil() as u32).max(1);
    Ok(Camera { width: cols, height: rows, ..*camera })
}

/// `draw` at `scale`: on `scaled_camera`'s grid, then resampled to `camera`'s size (timed on the
/// host as stage `upsample`). Scale 1 draws `camera` itself.
pub fn render_scaled(camera: &Camera, scale: f32, draw: impl FnOnce(&Camera) -> Result<Rendered>) -> Result<Rendered> {
    // `scaled_camera` checks the scale.
    if scale == 1.0 {
        return draw(camera);
    }
    let mut out = draw(&scaled_camera(camera, scale)?)?;
    let t = std::time::Instant::now();
    out.image = upsample(&out.image, camera.width, camera.height)?;
    out.timings.push(StageTime { stage: "upsample", ms: t.elapsed().as_secs_f64() * 1e3 });
    Ok(out)
}

/// Bilinear resampling of `low` (drawn by `scaled_camera`) to `width` x `height`: each full-size
/// pixel centre is mapped about the shared image centre by `low.height / height` and the four
/// nearest coarse pixels are interpolated (clamped at the border). Premultiplied colour, so alpha
/// and colour interpolate alike.
pub fn upsample(low: &ImageF32, width: u32, height: u32) -> Result<ImageF32> {
    upsample_rows(low, width, height, 0, height)
}

/// Rows `first .. first + rows` of `upsample(low, width, height)`, alone: a frame resampled band
/// by band (`Renderer::render_bands` under a render scale) never holds the whole of it.
pub fn upsample_rows(low: &ImageF32, width: u32, height: u32, first: u32, rows: u32) -> Result<ImageF32> {
    if low.width == 0 || low.height == 0 || width == 0 || height == 0 || rows == 0 {
        return Err(Error::InvalidArgument("cannot resample an empty image".into()));
    }
    if first.checked_add(rows).is_none_or(|end| end > height) {
        return Err(Error::InvalidArgument(format!(
            "rows {first}..{} lie outside a frame of {height} rows",
            first as u64 + rows as u64
        )));
    }
    if low.pixels.len() != low.width as usize * low.height as usize {
        return Err(Error::InvalidArgument("image size does not match its pixels".into()));
    }
    let r = low.height as f64 / height as f64;
    let (cx, cy) = (width as f64 * 0.5, height as f64 * 0.5);
    let (lx, ly) = (low.width as f64 * 0.5, low.height as f64 * 0.5);
    // Coarse coordinate of a full-size pixel centre: its lower neighbour and the weight of the upper.
    let axis = |i: u32, c: f64, l: f64, n: u32| -> (usize, usize, f32) {
        let t = ((i as f64 + 0.5 - c) * r + l - 0.5).clamp(0.0, (n - 1) as f64);
        let i0 = t.floor() as u32;
        (i0 as usize, (i0 + 1).min(n - 1) as usize, (t - i0 as f64) as f32)
    };
    let xs: Vec<_> = (0..width).map(|x| axis(x, cx, lx, low.width)).collect();
    let w = low.width as usize;
    let mut out = ImageF32::new(width, rows);
    out.pixels.par_chunks_mut(width as usize).enumerate().for_each(|(y, row)| {
        let (y0, y1, fy) = axis(first + y as u32, cy, ly, low.height);
        let (top, bottom) = (&low.pixels[y0 * w..][..w], &low.pixels[y1 * w..][..w]);
        for (p, &(x0, x1, fx)) in row.iter_mut().zip(&xs) {
            for c in 0..4 {
                let t = top[x0][c] + (top[x1][c] - top[x0][c]) * fx;
                let b = bottom[x0][c] + (bottom[x1][c] - bottom[x0][c]) * fx;
                p[c] = t + (b - t) * fy;
            }
        }
    });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Projection;
    use glam::Vec3;

    fn camera(w: u32, h: u32) -> Camera {
        Camera {
            eye: Vec3::new(0.0, 0.0, 10.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            projection: Projection::Perspective { fov_y_deg: 30.0 },
            near: 1.0,
            far: 20.0,
            width: w,
            height: h,
            window: None,
        }
    }

    #[test]
    fn scaled_camera_keeps_square_pixels_and_covers_the_width() {
        let c = scaled_camera(&camera(512, 300), 0.3).unwrap();
        assert_eq!(c.height, 90);
        assert_eq!(c.width, 154); // 512 * 90 / 300 = 153.6, rounded up
        assert_eq!(scaled_camera(&camera(512, 512), 1.0).unwrap(), camera(512, 512));
        for bad in [0.0, -0.5, 1.5, f32::NAN, f32::INFINITY, MIN_RENDER_SCALE * 0.5] {
            assert!(scaled_camera(&camera(64, 64), bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn upsample_rows_are_the_rows_of_the_whole_upsample() {
        let mut low = ImageF32::new(7, 5);
        for (i, p) in low.pixels.iter_mut().enumerate() {
            *p = [i as f32, (i * i % 11) as f32, 1.0, 0.5];
        }
        let whole = upsample(&low, 23, 17).unwrap();
        let mut joined = Vec::new();
        for (first, rows) in [(0, 6), (6, 1), (7, 10)] {
            let band = upsample_rows(&low, 23, 17, first, rows).unwrap();
            assert_eq!((band.width, band.height), (23, rows));
            joined.extend_from_slice(&band.pixels);
        }
        assert!(joined == whole.pixels);
        for (first, rows) in [(10, 8), (0, 0), (u32::MAX, 2)] {
            assert!(upsample_rows(&low, 23, 17, first, rows).is_err(), "{first} {rows}");
        }
    }

    #[test]
    fn upsample_reproduces_linear_ramps_and_keeps_constants() {
        // A linear ramp in the coarse grid's coordinates is linear in the full grid's too: away from
        // the clamped border bilinear resampling is exact.
        let low = ImageF32 {
            width: 8,
            height: 6,
            pixels: (0..48).map(|i| [(i % 8) as f32, (i / 8) as f32, 0.5, 1.0]).collect(),
        };
        let up = upsample(&low, 16, 12).unwrap();
        for y in 1..11u32 {
            for x in 1..15u32 {
                let p = up.pixels[(y * 16 + x) as usize];
                let expect = [(x as f32 + 0.5) * 0.5 - 0.5, (y as f32 + 0.5) * 0.5 - 0.5, 0.5, 1.0];
                for c in 0..4 {
                    assert!((p[c] - expect[c]).abs() < 1e-5, "({x}, {y}) {p:?} vs {expect:?}");
                }
            }
        }
        // Border pixels clamp: the corner holds the coarse corner.
        assert_eq!(up.pixels[0], [0.0, 0.0, 0.5, 1.0]);
        let one = ImageF32 { width: 1, height: 1, pixels: vec![[0.25, 0.5, 0.75, 1.0]] };
        assert!(upsample(&one, 5, 3).unwrap().pixels.iter().all(|p| *p == [0.25, 0.5, 0.75, 1.0]));
        assert!(upsample(&one, 0, 3).is_err());
        let bad = ImageF32 { width: 2, height: 2, pixels: vec![[0.0; 4]; 3] };
        assert!(upsample(&bad, 4, 4).is_err());
    }

    #[test]
    fn upsample_maps_about_the_shared_centre() {
        // The coarse grid of a non-divisible width is wider than the view: a pixel at the full
        // image's centre samples the coarse image's centre.
        let c = scaled_camera(&camera(10, 4), 0.5).unwrap();
        assert_eq!((c.width, c.height), (5, 2));
        let low = ImageF32 { width: 5, height: 2, pixels: (0..10).map(|i| [(i % 5) as f32, 0.0, 0.0, 1.0]).collect() };
        let up = upsample(&low, 10, 4).unwrap();
        // Full-size columns 4 and 5 straddle the centre (x = 5), coarse centre x = 2.5 → values
        // 2.5 ∓ 0.25 - 0.5 = 1.75 and 2.25.
        assert!((up.pixels[4][0] - 1.75).abs() < 1e-6);
        assert!((up.pixels[5][0] - 2.25).abs() < 1e-6);
    }
}
