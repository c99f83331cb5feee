//! An embedder's program: it makes its own scalar field, classifies it with a transfer function,
//! renders an orbit of frames with voxsplat and writes the last one; then hands the same field to
//! voxsplat as a bricked volume (classified on the device) and changes its transfer function.
//! Usage: `embed [OUT.png]`.
use voxsplat::classify::{classify, TransferFunction};
use voxsplat::glam::{Quat, Vec3};
use voxsplat::volume::ScalarVolume;
use voxsplat::{Camera, RenderOptions, Renderer, RendererOptions};

fn main() -> Result<(), voxsplat::Error> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "embed.png".into());
    // The host's data: two overlapping Gaussian blobs on a 48³ grid, values in [0, 1].
    let n = 48u32;
    let mut values = Vec::with_capacity((n * n * n) as usize);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = Vec3::new(i as f32, j as f32, k as f32) / n as f32;
                let blob = |c: Vec3, r: f32| (-(p - c).length_squared() / (r * r)).exp();
                values.push((blob(Vec3::new(0.4, 0.5, 0.5), 0.2) + 0.8 * blob(Vec3::new(0.65, 0.45, 0.55), 0.12)).min(1.0));
            }
        }
    }
    let volume = ScalarVolume { dims: [n; 3], spacing: [1.0; 3], values };
    let set = classify(&volume, &TransferFunction::preset("ramp")?, None)?;
    println!("{} splats", set.len());

    let mut renderer = Renderer::new(&RendererOptions::default())?;
    renderer.set_scene(set)?;
    let start = Camera::framing(renderer.scene().expect("set above").grid(), 256, 256);
    let centre = renderer.scene().expect("set above").grid().center();
    let mut last = None;
    for f in 0..8 {
        let mut camera = start;
        camera.eye = centre + Quat::from_rotation_y(f as f32 * 45f32.to_radians()) * (start.eye - centre);
        let frame = renderer.render(&camera, &RenderOptions::default())?;
        let covered = frame.image.pixels.iter().filter(|p| p[3] > 0.1).count();
        println!("frame {f}: {covered} px covered, {:?}", frame.raster.map(|r| r.raster));
        if covered == 0 {
            return Err(voxsplat::Error::InvalidArgument(format!("frame {f} is empty")));
        }
        last = Some(frame.image);
    }
    voxsplat::output::write_image(&last.expect("eight frames"), out.as_ref())?;
    println!("-> {out} on {}", renderer.device_name());

    // The same field as a bricked store, classified on the device every frame: a new transfer
    // function is a table write, not a re-extraction.
    let mut options = RendererOptions::default();
    options.gpu_budget_bytes = Some(64 << 20);
    let mut bricked = Renderer::new(&options)?;
    bricked.set_volume(&volume, &TransferFunction::preset("ramp")?, None)?;
    let store = &bricked.volume().expect("set above").store;
    println!("bricked: {} voxels stored in {} bricks, {} bytes", store.len(), store.headers.len(), store.bytes());
    for tf in ["ramp", "ct"] {
        bricked.set_transfer_function(&TransferFunction::preset(tf)?, None)?;
        let frame = bricked.render(&start, &RenderOptions::default())?;
        let covered = frame.image.pixels.iter().filter(|p| p[3] > 0.1).count();
        println!("bricked, {tf}: {covered} px covered");
        if covered == 0 {
            return Err(voxsplat::Error::InvalidArgument(format!("the bricked {tf} frame is empty")));
        }
    }
    Ok(())
}
