#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// brick_lod_params for the compute tile compositor: each coarse splat made as brick_lod_params
// makes it, stored as its footprint in screen space (screen_record) for the tile stages, in the
// place of its parameters (as brick_quads beside brick_params). Mirror: cpu::brick_lod_quads.
#define SCREEN_QUADS
#include "cell_splats.glsl"
