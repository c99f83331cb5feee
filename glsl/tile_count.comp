#version 450
// Compute per-splat compositing, binning pass 1 of 4 (the count matrix is zeroed before, and
// screen_quads has made each entry's footprint in screen space): each invocation owns a chunk of
// the draw-list entries and counts, serially and without atomics, how many of them each screen
// tile receives (its column of the tile x chunk count matrix). Mirror: cpu::tile_count.
// ONE_PAGE: scenes within one page of splat records (types.glsl).
// variants: ONE_PAGE
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = TILE_BIN_WORKGROUP) in;
layout(std430, binding = 9) buffer Counts { uint counts[]; };
layout(std430, binding = 13) readonly buffer Quads { ScreenQuad quads_lo[]; };
layout(std430, binding = 16) readonly buffer QuadsHi { ScreenQuad quads_hi[]; };
PAGED_FIELD_READER(ivec4, box_at, quads_lo, quads_hi, box)
// llvmpipe ends every loop of an invocation once it has made 65535 iterations in all: a chunk whose
// loops would pass LOOP_BUDGET says so here (bit 1) and the host bins again in shorter chunks
// (recording.rs, record_tiles). tile_scatter's loops are the same, so a chunk that fits here fits there.
layout(std430, binding = 17) buffer Status { uint loop_budget_spent; };

void main() {
    uint chunk = gl_GlobalInvocationID.x;
    if (chunk >= pc.chunks) return;
    uvec2 grid = tile_grid();
    uvec2 range = chunk_entries(chunk);
    uint planned = 0u;  // loop iterations so far: one per entry, per tile row and per tile
    for (uint e = range.x; e < range.y; ++e) {
        planned += 1u;
        uvec4 r;
        if (!tile_range(box_at(draw_list[e]), r)) continue;
        planned += (r.w - r.y + 1u) * (r.z - r.x + 2u);
        if (planned > LOOP_BUDGET) {
            atomicOr(loop_budget_spent, 1u);
            break;
        }
        // Bottom-tested: the range is not empty (see tile_composite.comp on llvmpipe's loops).
        uint ty = r.y;
        do {
            uint tx = r.x;
            do {
                counts[(ty * grid.x + tx) * pc.chunks + chunk] += 1u;
            } while (++tx <= r.z);
        } while (++ty <= r.w);
    }
}
