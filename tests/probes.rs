//! Single-stage probes the engine's tests read (a frame run through one stage, its outputs).

/// The stage that makes a bricked batch's splats under `o` (a probe reads its outputs): the compute
/// tiles take them as screen quads (`brick_quads`), the other rasters as parameters.
pub fn splat_stage(o: &crate::RenderOptions) -> crate::stages::StageId {
    use crate::stages::StageId;
    if o.raster == crate::Raster::Compute {
        StageId::BrickQuads
    } else {
        StageId::BrickParams
    }
}

/// The compute tile compositor's binning for this frame (GPU stages or their CPU mirrors): each
/// screen tile's first entry plus the total, and the entries (splat indices, each tile's run in
/// draw-list order).
pub fn tile_lists(
    r: &mut crate::Renderer,
    camera: &crate::Camera,
    options: &crate::RenderOptions,
) -> crate::Result<(Vec<u32>, Vec<u32>)> {
    use crate::{dispatch::Res, plan, stages::StageId};
    let opts =
        crate::RenderOptions { raster: crate::Raster::Compute, composite: crate::Composite::Splat, ..options.clone() };
    let got = r.probe(camera, &opts, StageId::TileScatter, &[Res::TileStart, Res::TileEntries])?;
    let frame = plan::frame_for(&r.prepared()?.set, camera, &opts);
    let (tx, ty) = plan::tile_grid(&frame);
    let tiles = tx as usize * ty as usize;
    let starts = got[0][..tiles + 1].to_vec();
    let entries = got[1][..starts[tiles] as usize].to_vec();
    Ok((starts, entries))
}

/// The sheet modes' per-tile sheet ranges of this frame, as the backend computes them (the GPU
/// `sheet_tiles` stage, or its CPU mirror), of the grid actually drawn (the coarse one under a
/// render scale): for each composite tile, the lowest sheet (global rank; slab mode: slab) whose
/// footprints reach it (`u32::MAX`: none), then for each tile the highest + 1; every tile
/// `plan::ALL_SHEETS` where the pass would not pay (`plan::sheet_tiles_pay`).
pub fn sheet_tiles(
    r: &mut crate::Renderer,
    camera: &crate::Camera,
    options: &crate::RenderOptions,
) -> crate::Result<Vec<u32>> {
    use crate::{dispatch::Res, stages::StageId};
    if options.composite == crate::Composite::Splat {
        return Err(crate::Error::InvalidArgument("sheet ranges exist only in the sheet and slab modes".into()));
    }
    options.validate()?;
    let camera = if options.render_scale != 1.0 {
        crate::resample::scaled_camera(camera, options.render_scale)?
    } else {
        *camera
    };
    let opts = crate::RenderOptions { render_scale: 1.0, ..options.clone() };
    let got = r.probe(&camera, &opts, StageId::SheetTiles, &[Res::SheetTiles])?;
    let c = crate::constants::COMPOSITE_TILE;
    let tiles = camera.width.div_ceil(c) as usize * camera.height.div_ceil(c) as usize;
    Ok(got[0][..2 * tiles].to_vec())
}
