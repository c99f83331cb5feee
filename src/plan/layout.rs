//! Sizes and grids that a frame's plan and the recording decide by, and that the CPU mirrors read
//! too: the tile grids, the occlusion map's length, the node tree's and the pyramid's words and
//! buffers, the present stage's push constants, a splat's anti-aliasing scale. Mirrors import them
//! from here, never the other way round.
use crate::constants::{COMPOSITE_TILE, RASTER_TILE_H, RASTER_TILE_W};
use crate::dispatch::Res;
use crate::gpu_types::{Frame, PresentPush};

/// Tiles across and down an image of the frame's size.
pub fn tile_grid(frame: &Frame) -> (u32, u32) {
    ((frame.blur[2] as u32).div_ceil(RASTER_TILE_W), (frame.blur[3] as u32).div_ceil(RASTER_TILE_H))
}

/// The push constants of a frame whose final images are `sources` (bit 0 accumulation, bit 1 the
/// raster target), over a straight-alpha `background`, for a target that wants linear values or not.
pub fn present_push(background: Option<[f32; 4]>, sources: u32, linear: bool, width: u32, height: u32) -> PresentPush {
    let bg = background.map(|[r, g, b, a]| [r * a, g * a, b * a, a]).unwrap_or([0.0; 4]);
    PresentPush { background: bg, width, height, sources, linear: linear as u32 }
}

/// The `PresentPush::sources` bits for a frame over a host's image of `format`.
pub fn over_bits(format: crate::image::TargetFormat) -> u32 {
    use crate::gpu_types::{PRESENT_HOST_BGRA, PRESENT_HOST_HALF, PRESENT_OVER};
    let layout = match format {
        crate::image::TargetFormat::Rgba16Float => PRESENT_HOST_HALF,
        f if f.bgra() => PRESENT_HOST_BGRA,
        _ => 0,
    };
    PRESENT_OVER | layout
}

/// `Frame::aa[0]`: 0 for no anti-aliasing, Swan's, or the EWA low-pass (`params.glsl`).
pub const AA_SWAN: f32 = 1.0;
/// See `AA_SWAN`.
pub const AA_EWA: f32 = 2.0;

/// The anti-aliasing radius scale at eye-space `depth` (1 before k; Eq. 3.9 or the EWA low-pass).
pub fn footprint_scale(frame: &Frame, depth: f32) -> f32 {
    cell_footprint_scale(frame, depth, 1.0)
}

/// Mirror of `footprint_scale` in params.glsl: the scale of a splat `cell` voxels a side.
pub fn cell_footprint_scale(frame: &Frame, depth: f32, cell: f32) -> f32 {
    let voxel = cell * frame.spacing[3] / frame.origin[3];
    let ppv = if frame.eye[3] > 0.5 { voxel * frame.up[3] / depth.max(1e-6) } else { voxel * frame.up[3] };
    if frame.aa[0] == AA_SWAN {
        (1.0 / ppv).max(1.0)
    } else if frame.aa[0] == AA_EWA {
        let lp = frame.aa[2] / (frame.aa[1] * ppv);
        (1.0 + lp * lp).sqrt()
    } else {
        1.0
    }
}

/// Composite tiles across and in all of a `w` x `h` image.
pub fn tile_counts(w: u32, h: u32) -> (u32, u32) {
    let tiles_x = w.div_ceil(COMPOSITE_TILE);
    (tiles_x, tiles_x * h.div_ceil(COMPOSITE_TILE))
}

/// Entries of the occlusion map of a `w` x `h` frame: per composite tile its largest
/// transmittance left, then two words per tile (its open pixels, one bit each).
pub fn occlusion_len(w: u32, h: u32) -> u64 {
    3 * tile_counts(w, h).1 as u64
}

/// Words per node: the cell's 3, its error, its optical depth, the brick that draws it, and 1
/// when it may be drawn at all.
pub const NODE_WORDS: usize = 7;
/// Most tree levels above the brick (a voxel's level field holds 3 + 7).
pub const NODE_LEVELS: u32 = 7;
/// Mirror of `NODE_PIXELS`: a node's cell projects to at most this many pixels (and the bound).
pub const NODE_PIXELS: f32 = 1.0;
/// The nodes may take this many bytes, or the bricks' summaries' bytes where those are more: a
/// sparse store in a large grid would otherwise hold far more nodes than bricks.
pub const NODE_BYTES_FLOOR: u64 = 4 << 20;

/// Mirror of `node_grid`: nodes along x, y, z at tree level `k` of a `grid` of bricks.
pub fn node_grid(grid: [u32; 3], k: u32) -> [u32; 3] {
    grid.map(|g| (g + (1 << k) - 1) >> k)
}

/// Words of the node levels 1..=`levels` of a `grid` of bricks.
pub fn node_words(grid: [u32; 3], levels: u32) -> u64 {
    (1..=levels).map(|k| node_grid(grid, k).iter().map(|&n| n as u64).product::<u64>() * NODE_WORDS as u64).sum()
}

/// The node levels a `grid` of bricks with `headers` non-empty bricks gets: up to one root node,
/// at most `NODE_LEVELS`, and none when those would pass the nodes' share of memory.
pub fn node_levels(grid: [u32; 3], headers: usize) -> u32 {
    let most = grid.iter().copied().max().unwrap_or(1);
    let levels = (0..NODE_LEVELS).find(|&k| 1u32 << k >= most).unwrap_or(NODE_LEVELS);
    let cap = (headers as u64 * SUMMARY_WORDS as u64 * 4).max(NODE_BYTES_FLOOR);
    if node_words(grid, levels) * 4 > cap {
        0
    } else {
        levels
    }
}

/// Words of a `grid` of bricks' nodes over `levels` tree levels and of its frame's cut (one per
/// level-1 node), after the summaries.
pub fn node_and_cut_words(grid: [u32; 3], levels: u32) -> u64 {
    if levels == 0 {
        return 0;
    }
    node_words(grid, levels) + node_grid(grid, 1).iter().map(|&n| n as u64).product::<u64>()
}

/// Cells of levels 1-3 in a brick's pyramid (64 + 8 + 1).
pub const LOD_CELLS: usize = 73;
/// Words per pyramid cell: the optical depth along each axis, the normal, the colour (`brick.glsl`).
pub const CELL_WORDS: usize = 3;
/// Coarse levels (level l: cells of 2^l voxels a side).
pub const LOD_LEVELS: u32 = 3;
/// The octahedral bytes of a zero gradient.
pub(crate) const NO_NORMAL: u32 = 0x8080;

/// Cells of a brick's pyramid slot (level 1); levels 2 and 3 live in its summary.
pub const SLOT_CELLS: usize = 64;
/// Bytes of one brick's pyramid slot.
pub const PYRAMID_BYTES: u64 = (SLOT_CELLS * CELL_WORDS * 4) as u64;
/// Bytes of one brick's summary (resident whatever the budget).
pub const SUMMARY_BYTES: u64 = SUMMARY_WORDS as u64 * 4;

/// The buffers levels of detail add, and their bytes per non-empty brick: the pyramid's cells, its
/// summary, this frame's morph.
pub const LOD_BUFFERS: &[(Res, u64)] =
    &[(Res::Pyramid, PYRAMID_BYTES), (Res::LodSummary, SUMMARY_BYTES), (Res::BrickMorph, 4)];

/// The same for a store whose records stream, its pyramid resident: and each brick's slot
/// (its own header).
pub const SLOTTED_LOD_BUFFERS: &[(Res, u64)] =
    &[(Res::Pyramid, PYRAMID_BYTES), (Res::LodSummary, SUMMARY_BYTES), (Res::BrickMorph, 4), (Res::PyramidSlot, 4)];

/// The same for a streamed store whose pyramid holds one batch's bricks (`PYRAMID_BYTES` per
/// entry of the batch): the summary, the morph, and each brick's slot in the batch.
pub const STREAMED_LOD_BUFFERS: &[(Res, u64)] =
    &[(Res::LodSummary, SUMMARY_BYTES), (Res::BrickMorph, 4), (Res::PyramidSlot, 4)];

/// Resident device bytes of `buffers` for `bricks` non-empty bricks.
pub fn pyramid_bytes(buffers: &[(Res, u64)], bricks: usize) -> u64 {
    bricks as u64 * buffers.iter().map(|(_, per)| per).sum::<u64>()
}

/// Words per brick of the summary: 4 of summary, the 9 cells of levels 2 and 3, one spare.
pub const SUMMARY_WORDS: usize = 32;
