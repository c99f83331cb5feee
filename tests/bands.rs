//! Frames drawn in parts: a camera's window (`Camera::windowed`) draws exactly its pixels of the
//! whole frame, on both backends, over the paths a frame takes; `render` draws a frame past one
//! band (`crate::bands::frame_bands`) in bands and `render_bands` hands them on in order.
use super::common;
use crate::{Antialias, Camera, Composite, Delivered, Mode, Motion, Projection, Raster, RenderOptions, Renderer};
use common::{assert_clean, cpu, gpu};
use glam::Mat4;

/// The whole frame put together from windows of it: bands of `rows` rows, each cut into columns
/// `cols` wide.
fn in_windows(cam: &Camera, rows: u32, cols: u32, mut draw: impl FnMut(&Camera) -> crate::ImageF32) -> crate::ImageF32 {
    let mut out = crate::ImageF32::new(cam.width, cam.height);
    for y in (0..cam.height).step_by(rows as usize) {
        for x in (0..cam.width).step_by(cols as usize) {
            let (w, h) = (cols.min(cam.width - x), rows.min(cam.height - y));
            let part = draw(&cam.windowed(x, y, w, h));
            assert_eq!((part.width, part.height), (w, h));
            for j in 0..h {
                for i in 0..w {
                    out.pixels[((y + j) * cam.width + x + i) as usize] = part.pixels[(j * w + i) as usize];
                }
            }
        }
    }
    out
}

/// Pixels where a channel differs by more than 1e-3 (a quarter of an 8-bit step).
fn off_pixels(a: &crate::ImageF32, b: &crate::ImageF32) -> usize {
    a.pixels.iter().zip(&b.pixels).filter(|(p, q)| (0..4).any(|k| (p[k] - q[k]).abs() > 1e-3)).count()
}

/// Largest channel difference and the number of covered pixels of `whole`.
fn compare(whole: &crate::ImageF32, parts: &crate::ImageF32) -> (f32, usize) {
    (common::diff(whole, parts).0, common::covered(whole))
}

/// The cases: a name, options and a camera, over splat sets and a bricked volume.
fn cases(grid: &crate::Grid) -> Vec<(&'static str, RenderOptions, Camera)> {
    let persp = Camera::framing(grid, 90, 70);
    let ortho = Camera { projection: Projection::Orthographic { height: 1.1 * grid.diagonal() }, ..persp };
    let with = |f: &dyn Fn(&mut RenderOptions)| {
        let mut o = RenderOptions::default();
        f(&mut o);
        o
    };
    let motion = Motion {
        previous: Mat4::from_rotation_z(0.08),
        middle: None,
        delta_px: 0.5,
        profile: crate::BlurProfile::default(),
    };
    vec![
        ("default", RenderOptions::default(), persp),
        ("orthographic", RenderOptions::default(), ortho),
        ("quads", with(&|o| o.raster = Raster::Graphics), persp),
        ("point sprites", with(&|o| o.raster = Raster::Points), persp),
        ("compute raster", with(&|o| o.raster = Raster::Compute), persp),
        ("sheets", with(&|o| o.composite = Composite::Sheet), persp),
        ("mip", with(&|o| o.mode = Mode::Mip), persp),
        ("ewa", with(&|o| o.antialias = Antialias::Ewa), persp),
        ("motion blur", with(&|o| o.motion = Some(motion)), ortho),
    ]
}

#[test]
fn a_window_draws_exactly_its_pixels_of_the_whole_frame() {
    let set = common::random_sparse(11, [20, 16, 18], 0.5);
    let vol = common::blob([24, 20, 22]);
    for (backend, mut r) in [("gpu", gpu()), ("cpu", cpu())] {
        for bricked in [false, true] {
            let grid = if bricked {
                r.set_volume(&vol, &common::blob_tf(), None).unwrap();
                r.volume().unwrap().store.grid().unwrap()
            } else {
                r.set_scene(set.clone()).unwrap();
                *set.grid()
            };
            for (name, o, cam) in cases(&grid) {
                let whole = r.render(&cam, &o).unwrap().image;
                for (rows, cols) in [(23, 90), (17, 31)] {
                    let parts = in_windows(&cam, rows, cols, |c| r.render(c, &o).unwrap().image);
                    let (max, covered) = compare(&whole, &parts);
                    let off = off_pixels(&whole, &parts);
                    eprintln!("{backend} bricked {bricked} {name} {rows}x{cols}: max {max:e}, {off} px off, {covered} covered");
                    assert!(covered > 300, "{backend} {name}: something drawn");
                    // Float rounding (the window's projection, batches of other sizes): measured at
                    // most 6e-4, the compositing of a sheet's near-opaque pixels. A MIP's texel
                    // winners may change where a voxel's centre lies on a texel's edge: 2 pixels off
                    // by at most 0.027 were measured. A window one pixel off moves every edge.
                    let tag = format!("{backend} bricked {bricked} {name} windows {rows}x{cols}");
                    assert!(off <= 2 && max <= 0.05, "{tag}: {off} px off, max diff {max}");
                }
            }
        }
        // The ray caster, two rays a pixel side (measured at most 9.5e-6 off).
        r.set_scene(set.clone()).unwrap();
        let cam = Camera::framing(set.grid(), 90, 70);
        let o = crate::RaycastOptions { supersample: 2, ..Default::default() };
        let whole = r.raycast(&cam, &o).unwrap().image;
        let parts = in_windows(&cam, 17, 31, |c| r.raycast(c, &o).unwrap().image);
        let (max, covered) = compare(&whole, &parts);
        eprintln!("{backend} raycast: max {max:e}, {covered} covered");
        assert!(covered > 300 && max <= 1e-4, "{backend} raycast in windows: max diff {max}");
        assert_clean(&r);
    }
}

#[test]
fn bands_cover_every_row_once_within_the_band_size() {
    for (w, h) in [(1, 1), (2048, 2048), (2049, 2048), (8192, 8192), (16384, 4096), (16384, 300), (3000, 1)] {
        let cam = Camera::framing(&crate::Grid::centered([4; 3], [1.0; 3]).unwrap(), w, h);
        let bands = crate::bands::frame_bands(&cam);
        let whole = w as u64 * h as u64 * 16;
        let least = whole.div_ceil(crate::bands::BAND_BYTES) as usize;
        assert!(bands.len() == least || bands.len() == least + 1, "{w}x{h}: {} bands, at least {least}", bands.len());
        let mut next = 0;
        for &(y, rows) in &bands {
            assert_eq!(y, next, "{w}x{h}: bands in order, none left out");
            assert!(rows > 0 && w as u64 * rows as u64 * 16 <= crate::bands::BAND_BYTES.max(w as u64 * 16));
            next += rows;
        }
        assert_eq!(next, h, "{w}x{h}: every row");
    }
}

/// Each band's (first row, width, height), the bands' pixels in order, and what `render_bands`
/// returns.
type Banded = (Vec<(u32, u32, u32)>, Vec<[f32; 4]>, Delivered);

/// What `render_bands` hands on.
fn banded(r: &mut Renderer, cam: &Camera, o: &RenderOptions) -> Banded {
    let (mut seen, mut pixels) = (Vec::new(), Vec::new());
    let delivered = r
        .render_bands(cam, o, &mut |y, band| {
            seen.push((y, band.width, band.height));
            pixels.extend_from_slice(&band.pixels);
            Ok(())
        })
        .unwrap();
    (seen, pixels, delivered)
}

#[test]
fn a_frame_past_one_band_is_drawn_in_bands_that_render_bands_hands_on_in_order() {
    let set = common::random_sparse(5, [24, 20, 16], 0.4);
    let mut r = gpu();
    r.set_scene(set.clone()).unwrap();
    // 16384 x 300: 256 rows a band, so two bands of 150 rows (4.9 M pixels).
    let cam = Camera { width: 16384, height: 300, ..Camera::framing(set.grid(), 16384, 300) };
    let o = RenderOptions::default();
    let whole = r.render(&cam, &o).unwrap();
    assert_eq!((whole.image.width, whole.image.height), (16384, 300));
    let (seen, pixels, delivered) = banded(&mut r, &cam, &o);
    assert_eq!(seen, vec![(0, 16384, 150), (150, 16384, 150)]);
    assert!(pixels == whole.image.pixels, "render puts together the bands render_bands hands on");
    assert!(common::covered(&whole.image) > 10_000, "something drawn");
    assert_eq!(Some(delivered.raster), whole.raster);
    // The same view drawn at a tenth of the size in one piece: the same picture (coverage within 2 %).
    let small = r.render(&Camera { width: 1638, height: 30, ..cam }, &o).unwrap().image;
    let ratio = common::covered(&whole.image) as f64 / (100.0 * common::covered(&small) as f64);
    assert!((0.9..1.1).contains(&ratio), "coverage against the small frame's: {ratio}");
    // Under a render scale the coarse frame is drawn whole and resampled band by band: the same
    // pixels as `render` at that scale (`voxsplat render --render-scale` refused such frames).
    let mut scaled = o.clone();
    scaled.render_scale = 0.5;
    let low = r.render(&cam, &scaled).unwrap();
    let (seen, pixels, delivered) = banded(&mut r, &cam, &scaled);
    assert_eq!(seen, vec![(0, 16384, 150), (150, 16384, 150)]);
    assert!(pixels == low.image.pixels, "render_bands at a render scale hands on render's frame");
    assert_eq!(Some(delivered.raster), low.raster);
    assert!(delivered.timings.iter().any(|t| t.stage == "upsample"));
    assert_clean(&r);
}
