//! The engine's parts, for the tests, the lab studies and anyone extending the renderer. An
//! embedder needs none of this: `Renderer`, its options and the loaders are the top level.
//!
//! A frame is planned (`plan::frame`), then recorded (`recording`) as dispatches of the stages in
//! the stage table (`stages`, their builds in `builds`), which either engine runs: the Vulkan one,
//! or the CPU mirrors (`cpu`, `cpu_engine`) that compute the same frame; `bisect` splits a frame
//! between them. docs/DEVELOPING.md maps the files.

/// THE stage table and the engine interface.
pub mod stages {
    pub use crate::stages::*;
}
/// Every stage's builds, by name.
pub mod builds {
    pub use crate::builds::*;
}
/// What the stage table and the CPU mirrors share: resources, lists, builds' fixed-function state.
pub mod dispatch {
    pub use crate::dispatch::*;
}
/// Per-frame decisions made without a device: the frame's plan.
pub mod plan {
    pub use crate::plan::*;
}
/// THE recording of a frame, run on any engine.
pub mod recording {
    pub use crate::recording::*;
}
/// The CPU mirrors of the GPU stages, one file per stage.
pub mod cpu {
    pub use crate::cpu::*;
}
/// The engine that runs a recording on the CPU mirrors.
pub mod cpu_engine {
    pub use crate::cpu_engine::*;
}
/// `#[repr(C)]` mirrors of `glsl/shared/types.glsl`.
pub mod gpu_types {
    pub use crate::gpu_types::*;
}
/// Constants shared with the shaders (injected into GLSL as macros by build.rs).
pub mod constants {
    pub use crate::constants::*;
}
/// Every shader's SPIR-V builds, by shader.
pub mod shaders {
    pub use crate::shaders::*;
}
/// The raster auto rule and the tile compositor's limits.
pub mod raster {
    pub use crate::raster::*;
}
/// Reduced-resolution frames, resampled to full size.
pub mod resample {
    pub use crate::resample::*;
}
/// The k-d tree of the sorted-order and motion studies.
pub mod kdtree {
    pub use crate::kdtree::*;
}
/// A frame split between the GPU and the CPU mirrors at a stage.
pub mod bisect {
    pub use crate::bisect::*;
}

/// Stage outputs the tests read, each a frame probed after its stage (here, so that lib.rs keeps
/// to the embedder's face).
impl crate::Renderer {
    /// The image-aligned sheets' binning for this camera: the (splat, slab) pairs, interleaved, in
    /// visiting order (stages `splat_params`, `slab_count`, `slab_scan`, `slab_scatter`).
    #[doc(hidden)]
    pub fn slab_pairs(&mut self, camera: &crate::Camera, options: &crate::RenderOptions) -> crate::Result<Vec<u32>> {
        let opts = crate::RenderOptions { composite: crate::Composite::Slab, render_scale: 1.0, ..options.clone() };
        let set = &self.prepared()?.set;
        let frame = crate::plan::frame_for(set, camera, &opts);
        let pc =
            crate::plan::slab::slab_geometry(&frame, set.grid(), set.len(), opts.slab_thickness, opts.direction())?;
        let got = self.probe(
            camera,
            &opts,
            crate::stages::StageId::SlabScatter,
            &[crate::dispatch::Res::SlabStart, crate::dispatch::Res::SlabPairs],
        )?;
        let pairs = got[0][pc.slabs as usize] as usize * 2;
        Ok(got[1][..pairs].to_vec())
    }

    /// The splat_params stage's output for this camera (GPU stage, or its CPU mirror).
    #[doc(hidden)]
    pub fn splat_params(
        &mut self,
        camera: &crate::Camera,
        kernel: crate::Kernel,
        antialias: crate::Antialias,
    ) -> crate::Result<Vec<crate::gpu_types::SplatParams>> {
        let opts = crate::RenderOptions {
            raster: crate::Raster::Graphics,
            direction: Some(crate::Direction::BackToFront),
            kernel,
            antialias,
            ..Default::default()
        };
        let n = self.prepared()?.set.len();
        let got = self.probe(camera, &opts, crate::stages::StageId::SplatParams, &[crate::dispatch::Res::Params])?;
        Ok(bytemuck::cast_slice(&got[0][..n * std::mem::size_of::<crate::gpu_types::SplatParams>() / 4]).to_vec())
    }
}
