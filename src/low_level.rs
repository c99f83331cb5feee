//! The engine's parts, for the tests, the lab studies and anyone extending the renderer. An
//! embedder needs none of this: `Renderer`, its options and the loaders are the top level.
//!
//! A frame is planned (`plan::frame`), then recorded (`recording`) as dispatches of the stages in
//! the stage table (`stages`, their builds in `builds`), which either engine runs: the Vulkan one,
//! or the CPU mirrors (`cpu`, `cpu_engine`) that compute the same frame; `bisect` splits a frame
//! between them. docs/DEVELOPING.md maps the files.

/// THE stage table and the engine interface.
pub mod stages {
    pub use crate::stages::{
        Args, Blend, Dispatch, DrawState, Engine, Feature, Kind, Limits, List, Mirror, Pass, Res, StageDesc, StageId,
        Variant, Workgroup, STAGES,
    };
}
/// Every stage's builds, by name.
pub mod builds {
    pub use crate::builds::{
        Build, CompositeLayers, Footprint, Only, Pages, Pyramids, Records, SheetMode, SheetTiles, SlabBins, Table,
        TileComposite, TileOrder, COMPOSITE_LAYERS, FOOTPRINT, ONLY, PAGES, PARAMS, PYRAMIDS, RECORDS,
        RECORDS_OR_GRADIENTS, SHEET_MODES, SHEET_TILES, SLAB_BINS, TABLES, TILE_COMPOSITE,
    };
}
/// What the stage table and the CPU mirrors share: resources, lists, builds' fixed-function state.
pub mod dispatch {
    pub use crate::dispatch::{Args, Blend, DrawState, Feature, Kind, Limits, List, Pass, Res, Variant, Workgroup};
}
/// Per-frame decisions made without a device: the frame's plan.
pub mod plan {
    pub use crate::plan::{
        binned_sheet_plan, brick_frame, bricked_min_budget, bricked_resident_bytes, cell_footprint_scale, color_map,
        composite_push, footprint_scale, frame, frame_for, groups_1d, groups_per_item, make_frame, mode_color_map,
        node_and_cut_words, node_grid, node_levels, node_words, occlusion_len, order_frame, over_bits, present_push,
        pyramid_bytes, raycast_params, sheet_axis, sheet_layers, sheet_pass, sheet_plan, sheet_tiles_pay,
        sheet_tiles_push, slab, texel_bytes, tile_counts, tile_grid, Batch, BrickedPlan, BrickedSheets, DepthSource,
        Draw, FieldKind, FramePlan, OrderSource, Prepared, Projection, SheetPass, SplatRaster, TileRule, AA_EWA,
        AA_NONE, AA_SWAN, ALL_SHEETS, BATCH_BYTES_PER_SPLAT, CELL_WORDS, LOD_BUFFERS, LOD_CELLS, LOD_LEVELS,
        MAX_TILE_CELLS, NODE_BYTES_FLOOR, NODE_LEVELS, NODE_PIXELS, NODE_WORDS, PYRAMID_BYTES, SHEET_TILES_MIN_RATIO,
        SLOTTED_LOD_BUFFERS, SLOT_CELLS, STREAMED_LOD_BUFFERS, SUMMARY_BYTES, SUMMARY_WORDS,
    };
}
/// THE recording of a frame, run on any engine.
pub mod recording {
    pub use crate::recording::{
        record_frame, record_plan, record_raycast, Recorded, HIDDEN_BATCHES, HIDDEN_BATCH_MIN, LOOP_BUDGET_BINNING,
        LOOP_BUDGET_SUMS, SURFACE_BYTES_PER_SPLAT,
    };
}
/// The CPU mirrors of the GPU stages, one file per stage.
pub mod cpu {
    pub use crate::cpu::{
        bindings, brick, brick_cells, brick_cull, brick_hidden, brick_lod_params, brick_lod_quads, brick_node_cut,
        brick_nodes, brick_order, brick_params, brick_pyramid, brick_quads, brick_words, composite, footprint,
        footprint_sum, host_depth, iso_cells, iso_count, iso_scan, iso_splats, lod, order, order_count, order_scan,
        order_scatter, present, project, project_texels, project_winners, raycast, sample_table, screen_quads,
        sheet_tiles, slab, slab_count, slab_scan, slab_scatter, splat_params, tile, tile_composite, tile_count,
        tile_occlusion, tile_offsets, tile_scan, tile_scatter, ImageF32,
    };
}
/// The engine that runs a recording on the CPU mirrors.
pub mod cpu_engine {
    pub use crate::cpu_engine::CpuEngine;
}
/// `#[repr(C)]` mirrors of `glsl/shared/types.glsl`.
pub mod gpu_types {
    pub use crate::gpu_types::{
        BrickFrame, BrickPush, CompositePush, DepthPush, FootprintPush, Frame, IsoPush, PresentPush, ProjectPush,
        RaycastParams, ScreenQuad, SlabPush, Splat, SplatParams, BLEND_COMPOSITE, BLEND_MAX, BLEND_SUM, BLEND_SURFACE,
        BLEND_SURFACE_DEPTH, PRESENT_HOST_BGRA, PRESENT_HOST_HALF, PRESENT_OVER, SHEET_MODE_AXIS, SHEET_MODE_BINNED,
        SHEET_MODE_SLAB, SHEET_MODE_SPLAT,
    };
}
/// Constants shared with the shaders (injected into GLSL as macros by build.rs).
pub mod constants {
    pub use crate::constants::{
        BRICK_LANES, BRICK_SIDE, CLIP_SLOTS, COLOR_MAP_SIZE, COMPOSITE_TILE, CULL_RADII, DEFAULT_GPU_BUDGET,
        FOOTPRINT_TABLE_SIZE, GLSL_DEFINES, ISO_SEGMENT, LOOP_BUDGET, MAX_CLIP_PLANES, MAX_GPU_RAY_STEPS,
        MAX_GPU_SPLATS, MAX_GROUPS_X, PYRAMID_PAGE, PYRAMID_PAGES, RADIAL_TABLE_SIZE, RASTER_LANES, RASTER_TILE_H,
        RASTER_TILE_W, RECORD_PAGE, RECORD_PAGES, SCAN_WORKGROUP_SIZE, SLAB_CHUNK, SPLAT_PAGE, SUM_FIXED_SCALE,
        TF_ENTRIES, TILE_BIN_WORKGROUP, TILE_CHUNK, TILE_SEGMENT, WORKGROUP_SIZE,
    };
}
/// Every shader's SPIR-V builds, by shader.
pub mod shaders {
    pub use crate::shaders::{
        brick_cells, brick_cull, brick_hidden, brick_lod_params, brick_lod_quads, brick_node_cut, brick_nodes,
        brick_order, brick_params, brick_pyramid, brick_quads, composite, footprint, footprint_sum, host_depth,
        iso_cells, iso_count, iso_scan, iso_splats, order_count, order_scan, order_scatter, present, project,
        project_texels, project_winners, raycast, roofline, screen_quads, sheet_tiles, slab_count, slab_scan,
        slab_scatter, spirv_build, splat_params, tile_composite, tile_count, tile_occlusion, tile_offsets, tile_scan,
        tile_scatter, Shaders, SPIRV,
    };
}
/// The raster auto rule and the tile compositor's limits.
pub mod raster {
    pub use crate::raster::{
        check_tile_cells, check_tile_entries, choose, footprint_size, Device, FootprintSize, Raster, RasterChoice,
        AUTO_COMPUTE_SUM_MAX_PX, AUTO_COMPUTE_TILES_MAX_PX, AUTO_POINTS_MIN_PX, MAX_TILE_CELLS, MAX_TILE_ENTRIES,
    };
}
/// Reduced-resolution frames, resampled to full size.
pub mod resample {
    pub use crate::resample::{check_scale, render_scaled, scaled_camera, upsample, MIN_RENDER_SCALE};
}
/// The k-d tree of the sorted-order and motion studies.
pub mod kdtree {
    pub use crate::kdtree::{build, cut, lower_in_front, Node, LEAF, TREE_DEPTH};
}
/// A frame split between the GPU and the CPU mirrors at a stage.
pub mod bisect {
    pub use crate::bisect::{Bisect, Split, Stop};
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
