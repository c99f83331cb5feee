//! The peers' comparison: every voxsplat mode timed on the shared scene of
//! `voxsplat::scene::peer`.
use voxsplat::scene::peer::{camera, transfer_function, volume};
use voxsplat::Result;

/// One voxsplat configuration in the peer comparison.
#[derive(Clone, Debug)]
pub struct PeerRun {
    pub label: String,
    /// Median wall time of a whole frame (render call to image on the host), ms.
    pub median_ms: f64,
    pub image: voxsplat::image::ImageF32,
}

/// The configurations compared with the peers on an `n`³ volume. Image-aligned slabs draw each of
/// the 1.7 M splats of the 256³ scene about five times (over a minute per frame on lavapipe), so
/// they are timed at 128³ only.
pub fn variants(n: u32) -> Vec<crate::stability::Variant> {
    use crate::stability::Variant;
    use voxsplat::{options::Composite, options::Raster};
    let mut v = vec![
        Variant::Splat(voxsplat::order::OrderKind::Pbtf),
        Variant::Rastered(Composite::Splat, Raster::Points),
        Variant::Rastered(Composite::Splat, Raster::Compute),
        Variant::Kernel(voxsplat::kernel::Kernel::Narrow, Raster::Points),
        // Drawn on a coarser grid and resampled (`RenderOptions::render_scale`): at 128³ a voxel
        // covers ~3.5 px, so the kernel is far wider than a pixel. Two scales of the compositor
        // trace its speed-accuracy curve beside VTK's image sample distances (scripts/peers.sh).
        Variant::Scaled(voxsplat::kernel::Kernel::Gaussian, Raster::Compute, 0.5),
        Variant::Scaled(voxsplat::kernel::Kernel::Narrow, Raster::Compute, 0.4),
        Variant::Scaled(voxsplat::kernel::Kernel::Narrow, Raster::Compute, 0.25),
        Variant::Scaled(voxsplat::kernel::Kernel::Narrow, Raster::Points, 0.4),
        Variant::Sheet,
        Variant::Rastered(Composite::Sheet, Raster::Compute),
    ];
    if n <= 128 {
        v.push(Variant::Slab(1.0));
    }
    v.extend([Variant::Raycast(1.0), Variant::Raycast(0.5)]);
    v
}

/// Time every variant on the `n`³ peer scene at `size`²: `warmup` frames, then the median wall
/// time of `frames` (the camera nudged ±0.5° about the vertical between frames, as the VTK script
/// does, so nothing can be cached).
pub fn time_variants(
    r: &mut voxsplat::Renderer,
    n: u32,
    size: u32,
    warmup: usize,
    frames: usize,
) -> Result<Vec<PeerRun>> {
    let set = voxsplat::classify::classify(&volume(n)?, &transfer_function(), None)?;
    r.set_scene(set)?;
    let base = camera(n, size);
    let mut out = Vec::new();
    for v in variants(n) {
        let mut times = Vec::new();
        for f in 0..warmup + frames.max(1) {
            let mut cam = base;
            let a = if f % 2 == 0 { 0.5f32 } else { -0.5 }.to_radians();
            cam.eye = glam::Quat::from_rotation_y(a) * cam.eye;
            let t = std::time::Instant::now();
            v.render(r, &cam)?;
            if f >= warmup {
                times.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        // The kept image is from the unrotated camera, for scoring.
        let img = v.render(r, &base)?.image;
        out.push(PeerRun { label: v.label(), median_ms: crate::bench::median(&mut times), image: img });
    }
    Ok(out)
}
