#version 450
// variants: PAGED_RECORDS STREAMED_STORE GRADIENTS
// brick_params for the compute tile compositor: each voxel's splat made as brick_params makes it,
// stored as its footprint in screen space (screen_record) for the tile stages, in the place of its
// parameters. Made here, in a lane per splat, the quads cost the bonsai's 512² frame 50 ms where
// a pass of their own (screen_quads, which reads the parameters back lane by lane) cost 150.
// Mirror: cpu::brick_quads.
#define SCREEN_QUADS
#include "voxel_splats.glsl"
