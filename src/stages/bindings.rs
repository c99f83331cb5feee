//! What binding i of each stage's descriptor set holds, for the rows of the stage table.
use crate::dispatch::Res;

pub(super) const ORDER: &[Res] = &[Res::Frame, Res::Splats, Res::RowStart, Res::RowSplit, Res::Segments, Res::Order];
pub(super) const PARAMS: &[Res] = &[Res::Frame, Res::Splats, Res::Params, Res::ParamsHi, Res::Coords];
pub(super) const SLAB: &[Res] =
    &[Res::Params, Res::SlabCounts, Res::SlabPairs, Res::SlabStart, Res::ParamsHi, Res::BrickVoxels];
pub(super) const COMPOSITE: &[Res] = &[Res::Sums, Res::Accum, Res::Occlusion, Res::Fixed, Res::SheetTiles];
/// glsl/shared/footprint.glsl's bindings, shared by every footprint-reading stage.
pub(super) const FOOTPRINT: &[Res] = &[
    Res::Frame,
    Res::Params,
    Res::DrawList,
    Res::Splats,
    Res::Ranks,
    Res::Radial,
    Res::SliceTable,
    Res::Occlusion,
    Res::Fixed,
    Res::TileCounts,
    Res::TileStart,
    Res::TileEntries,
    Res::Accum,
    Res::Quads,
    Res::SheetTiles,
    Res::ParamsHi,
    Res::QuadsHi,
    Res::Status,
    Res::HostDepth,
];
/// glsl/shared/brick.glsl's bindings, shared by the brick stages.
pub(super) const BRICK: &[Res; 32] = &[
    Res::Frame,
    Res::BrickFrame,
    Res::Tf,
    Res::BrickHeaders,
    Res::BrickMasks,
    Res::BrickRecords,
    Res::BrickIndex,
    Res::BrickSlots,
    Res::BrickList,
    Res::Params,
    Res::ParamsHi,
    Res::Order,
    Res::BrickVoxels,
    Res::Occlusion,
    Res::BrickRecords1,
    Res::BrickRecords2,
    Res::BrickRecords3,
    Res::BrickRecords4,
    Res::BrickRecords5,
    Res::BrickRecords6,
    Res::BrickRecords7,
    Res::BrickHidden,
    Res::BatchRecords,
    Res::BrickCounts,
    Res::Pyramid,
    Res::LodSummary,
    Res::BrickMorph,
    Res::PyramidSlot,
    Res::Pyramid1,
    Res::Pyramid2,
    Res::Pyramid3,
    Res::LodSplats,
];
/// `brick_params`' and `brick_pyramid`'s bindings: their `GRADIENTS` builds' inputs in
/// `brick_hidden`'s places (the brick stages' list is at lavapipe's 32 storage buffers a stage).
const GRADIENTS_LIST: [Res; 32] =
    Res::replaced(Res::replaced(*BRICK, Res::BrickHidden, Res::BrickGradients), Res::Occlusion, Res::BrickGradientsHi);
pub(super) const BRICK_GRADIENTS: &[Res] = &GRADIENTS_LIST;
/// `brick_params`' bindings: `BRICK_GRADIENTS` with a projection's packed voxels
/// (`project_winners`) in the place of `LodSplats` (projections have no levels of detail).
const PARAMS_LIST: [Res; 32] = Res::replaced(GRADIENTS_LIST, Res::LodSplats, Res::ProjectVoxels);
pub(super) const BRICK_PARAMS: &[Res] = &PARAMS_LIST;
/// `list` with the screen quads in the parameters' place (`brick_quads`, `brick_lod_quads`).
const fn with_quads(list: [Res; 32]) -> [Res; 32] {
    Res::replaced(Res::replaced(list, Res::Params, Res::Quads), Res::ParamsHi, Res::QuadsHi)
}
/// `brick_quads`' bindings: `brick_params`' with the screen quads in the parameters' place.
pub(super) const BRICK_QUADS: &[Res] = &with_quads(PARAMS_LIST);
/// `brick_lod_quads`' bindings: the brick stages' with the screen quads in the parameters' place.
pub(super) const BRICK_LOD_QUADS: &[Res] = &with_quads(*BRICK);
/// `project_texels`' and `project_winners`' bindings: the brick stages' with the texels in the
/// place of `LodSplats`, the packed voxels in `brick_hidden`'s and each voxel's texel in the
/// occlusion map's.
pub(super) const BRICK_TEXELS: &[Res] = &Res::replaced(
    Res::replaced(Res::replaced(*BRICK, Res::LodSplats, Res::ProjectTexels), Res::BrickHidden, Res::ProjectVoxels),
    Res::Occlusion,
    Res::VoxelTexels,
);
/// glsl/shared/iso.glsl's bindings and `iso_splats`' outputs.
pub(super) const ISO: &[Res] =
    &[Res::Frame, Res::IsoField, Res::IsoRows, Res::IsoCounts, Res::Params, Res::ParamsHi, Res::Order, Res::IsoCells];
