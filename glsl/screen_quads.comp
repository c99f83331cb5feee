#version 450
// Compute per-splat compositing, before the binning: each draw-list entry's footprint in screen
// space (its pixel box, the inverse projective map, its emission) for the tile stages, one
// invocation an entry. Made inside tile_count's serial walk of a chunk it cost 0.2 s of a 1 s
// bonsai frame at 512²; here the lanes make eight at once (the binning then reads the boxes alone).
// Mirror: cpu::screen_quads.
// ONE_PAGE: scenes within one page of splat records (types.glsl).
// variants: ONE_PAGE
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 13) writeonly buffer Quads { ScreenQuad quads_lo[]; };
layout(std430, binding = 16) writeonly buffer QuadsHi { ScreenQuad quads_hi[]; };
PAGED_WRITER(ScreenQuad, quads_store, quads_lo, quads_hi)

void main() {
    uint e = linear_invocation();
    if (e >= pc.count) return;
    uint splat = draw_list[e];
    quads_store(splat, screen_record(params_at(splat)));
}
