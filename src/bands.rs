//! Large frames drawn in bands: a frame of more than `BAND_BYTES` of RGBA32F is drawn as
//! full-width windows of its camera (`Camera::windowed`), one after another. The device's images,
//! their read-back copies and the CPU engine's accumulators then hold one band, not the frame:
//! an 8192² frame drawn whole took 4.4 times its own 1 GiB. Every band projects with the whole
//! frame's projection and draws with its raster, so the bands meet without seams; each runs the
//! per-splat stages again (bonsai, 2048×2049 in two bands: 12 % slower than 2048² in one).
//!
//! ```no_run
//! // An 8192² PNG written band by band: no more than one band of it in memory.
//! let mut renderer = voxsplat::Renderer::new(&Default::default())?;
//! renderer.set_scene(voxsplat::scene::build("cube60")?)?;
//! let camera = voxsplat::Camera::framing(renderer.scene().unwrap().grid(), 8192, 8192);
//! let mut png = voxsplat::output::PngRows::create("big.png".as_ref(), 8192, 8192)?;
//! renderer.render_bands(&camera, &Default::default(), &mut |_first_row, band| png.push(band))?;
//! png.finish()?;
//! # Ok::<(), voxsplat::Error>(())
//! ```
use crate::camera::Camera;
use crate::error::{check_host_memory, Result};
use crate::image::ImageF32;
use crate::options::{add_time, FrameStats, Rendered, StageTime};

/// Most bytes of RGBA32F one band holds: 64 MiB, so frames up to 2048² are drawn whole.
pub const BAND_BYTES: u64 = 64 << 20;

/// Host bytes a drawn band takes per pixel at most: the image (f32 RGBA), its read-back copy, the
/// CPU engine's accumulators and an 8-bit copy (an 8192² frame drawn whole took 4.4 GB).
pub const BAND_HOST_BYTES_PER_PIXEL: u64 = 72;

/// The bands of `camera`'s image: (first row, rows), full width, all as tall but the last.
pub fn frame_bands(camera: &Camera) -> Vec<(u32, u32)> {
    let most = (BAND_BYTES / (camera.width as u64 * 16)).clamp(1, camera.height.max(1) as u64) as u32;
    let n = camera.height.div_ceil(most).max(1);
    let rows = camera.height.div_ceil(n);
    (0..n).map(|i| i * rows).take_while(|&y| y < camera.height).map(|y| (y, rows.min(camera.height - y))).collect()
}

/// Refuse a frame whose host memory would pass the host budget or what the host has available,
/// before anything of it is allocated: one band's drawing, and the whole frame's image when
/// `assembled` (`Renderer::render` returns it; `render_bands` hands the bands on).
pub fn check_memory(camera: &Camera, assembled: bool) -> Result<()> {
    let band = frame_bands(camera).first().map_or(0, |&(_, rows)| rows as u64) * camera.width as u64;
    let whole = camera.width as u64 * camera.height as u64;
    let bytes = band * BAND_HOST_BYTES_PER_PIXEL + if assembled && band < whole { whole * 16 } else { 0 };
    check_host_memory(bytes, &format!("a {}x{} frame", camera.width, camera.height))
}

/// Draw `camera`'s bands with `draw`, handing each to `sink` with its first row; the bands' stage
/// times summed and their stats merged (`FrameStats::busiest`).
pub fn each(
    camera: &Camera,
    mut draw: impl FnMut(&Camera) -> Result<(ImageF32, Vec<StageTime>, FrameStats)>,
    sink: &mut dyn FnMut(u32, &ImageF32) -> Result<()>,
) -> Result<(Vec<StageTime>, FrameStats)> {
    let (mut timings, mut stats) = (Vec::new(), FrameStats::default());
    for (y, rows) in frame_bands(camera) {
        let (image, t, s) = draw(&camera.windowed(0, y, camera.width, rows))?;
        sink(y, &image)?;
        for st in t {
            add_time(&mut timings, st.stage, st.ms);
        }
        stats = stats.busiest(&s);
    }
    Ok((timings, stats))
}

/// `low`, drawn on `resample::scaled_camera(camera, ..)`'s grid, resampled to `camera`'s size band
/// by band into `sink` (`Renderer::render_bands` under a render scale); `raster` is what the coarse
/// frame was drawn with.
pub fn upsampled(
    camera: &Camera,
    low: Rendered,
    raster: crate::RasterChoice,
    sink: &mut dyn FnMut(u32, &ImageF32) -> Result<()>,
) -> Result<crate::Delivered> {
    let mut timings = low.timings;
    for (y, rows) in frame_bands(camera) {
        let t = std::time::Instant::now();
        let band = crate::resample::upsample_rows(&low.image, camera.width, camera.height, y, rows)?;
        add_time(&mut timings, "upsample", t.elapsed().as_secs_f64() * 1e3);
        sink(y, &band)?;
    }
    Ok(crate::Delivered { timings, raster, stats: low.stats })
}

/// `draw`'s bands of `camera` put together into one frame.
pub fn assemble(camera: &Camera, mut draw: impl FnMut(&Camera) -> Result<Rendered>) -> Result<Rendered> {
    let mut frame = ImageF32::new(camera.width, camera.height);
    let mut raster = None;
    let (timings, stats) = each(
        camera,
        |band| {
            let r = draw(band)?;
            raster = r.raster.or(raster.take());
            Ok((r.image, r.timings, r.stats))
        },
        &mut |y, band| {
            let at = y as usize * camera.width as usize;
            frame.pixels[at..at + band.pixels.len()].copy_from_slice(&band.pixels);
            Ok(())
        },
    )?;
    Ok(Rendered { image: frame, timings, raster, stats })
}
