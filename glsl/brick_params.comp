#version 450
// variants: PAGED_RECORDS STREAMED_STORE GRADIENTS PROJECT_VOXELS
// Bricks, pass 3 (issue 23): per splat of a batch, in draw order, classify its voxel on the device
// (TF table, gradient weighting, headlight shading; gradients read through the store, or in the
// GRADIENTS build from each voxel's precomputed differences) and make its
// splat parameters (params.glsl, as splat_params does for a dense set; a projection's key from its
// density, project_emit); a voxel of a morphing brick
// grows toward its next level (levels of detail). Coarse cells are brick_lod_params': a branch to
// them here would cost every voxel, since llvmpipe runs a branch's code under a mask even where no
// lane takes it. Mirror: cpu::brick::brick_params.
#include "voxel_splats.glsl"
