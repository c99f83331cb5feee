#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Levels of detail, beside brick_params (which makes the voxels' splats and skips coarse cells): a
// lane per coarse splat of the batch (lod_splats: their positions, listed by the host), its
// parameters from its pyramid cell seen along the view (its directional prefilter: colour shaded
// at that view's normal, optical depth per cell), a splat 2^l voxels wide at the middle of its voxels inside the grid, grown toward the
// next level when its brick morphs. Mirror: cpu::lod::brick_lod_params.
#include "cell_splats.glsl"
