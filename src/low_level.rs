//! What the CLI and the lab reach below the facade, item by item: single-stage probes (as free
//! functions over a [`Renderer`], not its methods), the host's present pass, the render bands and a
//! few limits. An embedder needs none of this: [`Renderer`], its options and the loaders are the
//! top level. The engine's own tests use its internals from inside the crate (`tests/`, compiled
//! into the library's test build), not through here.
//!
//! ```
//! use voxsplat::{low_level, scene, Backend, Camera, Renderer, RendererOptions};
//! use voxsplat::order::Direction;
//! let mut o = RendererOptions::default();
//! o.backend = Backend::Cpu;
//! let mut r = Renderer::new(&o)?;
//! let set = scene::build("cube40")?;
//! let camera = Camera::framing(set.grid(), 32, 32);
//! let n = set.len();
//! r.set_scene(set)?;
//! // The PBTF draw sequence, as the order stages compute it: every splat once.
//! let order = low_level::pbtf_order(&mut r, &camera, Direction::BackToFront)?;
//! assert_eq!(order.len(), n);
//! # Ok::<(), voxsplat::Error>(())
//! ```

use crate::dispatch::Res;
use crate::options::{Antialias, Composite, Raster, RenderOptions};
use crate::order::Direction;
use crate::stages::StageId;
use crate::{kernel::Kernel, Camera, Error, ImageF32, Renderer, Result};

pub use crate::bands::{frame_bands, BAND_BYTES};
pub use crate::bisect::Bisect;
pub use crate::constants::{FOOTPRINT_TABLE_SIZE, MAX_GPU_SPLATS};
pub use crate::cpu::present::to_srgb;
pub use crate::gpu_types::SplatParams;
pub use crate::plan::{sheet_axis, FramePlan};
pub use crate::resample::{check_scale, MIN_RENDER_SCALE};

/// The bytes of the levels-of-detail pyramid (`--lod auto`) over a store of `bricks` bricks.
pub fn pyramid_bytes(bricks: usize) -> u64 {
    crate::plan::pyramid_bytes(crate::plan::LOD_BUFFERS, bricks)
}

/// The present pass's CPU mirror over a frame that had none (the reference renderers): `image`
/// (premultiplied, linear) over an opaque or translucent `background` (straight RGBA).
pub fn present_over(image: &mut ImageF32, background: [f32; 4]) {
    let push = crate::plan::present_push(Some(background), 1, false, image.width, image.height);
    crate::cpu::present::present(&push, image, &ImageF32::new(0, 0), &[]);
}

/// The PBTF draw sequence as the backend computes it (the GPU order stages, or their mirrors).
pub fn pbtf_order(renderer: &mut Renderer, camera: &Camera, direction: Direction) -> Result<Vec<u32>> {
    let opts = RenderOptions { raster: Raster::Graphics, direction: Some(direction), ..Default::default() };
    let n = renderer.prepared()?.set.len();
    let got = renderer.probe(camera, &opts, StageId::OrderScatter, &[Res::Order])?;
    Ok(got[0][..n].to_vec())
}

/// The `splat_params` stage's output for this camera (GPU stage, or its CPU mirror).
pub fn splat_params(
    renderer: &mut Renderer,
    camera: &Camera,
    kernel: Kernel,
    antialias: Antialias,
) -> Result<Vec<SplatParams>> {
    let opts = RenderOptions {
        raster: Raster::Graphics,
        direction: Some(Direction::BackToFront),
        kernel,
        antialias,
        ..Default::default()
    };
    let n = renderer.prepared()?.set.len();
    let got = renderer.probe(camera, &opts, StageId::SplatParams, &[Res::Params])?;
    Ok(bytemuck::cast_slice(&got[0][..n * std::mem::size_of::<SplatParams>() / 4]).to_vec())
}

/// The image-aligned sheets' binning for this camera: the (splat, slab) pairs, interleaved, in
/// visiting order (stages `splat_params`, `slab_count`, `slab_scan`, `slab_scatter`).
pub fn slab_pairs(renderer: &mut Renderer, camera: &Camera, options: &RenderOptions) -> Result<Vec<u32>> {
    let opts = RenderOptions { composite: Composite::Slab, render_scale: 1.0, ..options.clone() };
    let set = &renderer.prepared()?.set;
    let frame = crate::plan::frame_for(set, camera, &opts);
    let pc = crate::plan::slab::slab_geometry(&frame, set.grid(), set.len(), opts.slab_thickness, opts.direction())?;
    let got = renderer.probe(camera, &opts, StageId::SlabScatter, &[Res::SlabStart, Res::SlabPairs])?;
    let pairs = got[0][pc.slabs as usize] as usize * 2;
    Ok(got[1][..pairs].to_vec())
}

/// GPU roofline of the raster pass: milliseconds for `instances` additive `size`-pixel quads.
pub fn roofline_quads(renderer: &mut Renderer, width: u32, height: u32, size: u32, instances: u32) -> Result<f64> {
    match &mut renderer.gpu {
        Some(g) => g.roofline_quads(width, height, size.max(1), instances),
        None => Err(Error::Unsupported("the roofline needs a GPU backend".into())),
    }
}

/// GPU roofline of the compositing pass: (roofline ms, composite.comp ms) over `layers` layers.
pub fn roofline_composite(renderer: &mut Renderer, width: u32, height: u32, layers: u32) -> Result<(f64, f64)> {
    match &mut renderer.gpu {
        Some(g) => g.roofline_composite(width, height, layers.max(1)),
        None => Err(Error::Unsupported("the roofline needs a GPU backend".into())),
    }
}
