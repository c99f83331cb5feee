#version 450
// Compute per-splat compositing, binning pass 1 of 4 (the count matrix is zeroed before): each invocation owns a chunk of the
// draw-list entries, records each one's footprint in screen space for the later stages and counts,
// serially and without atomics, how many of them each screen tile receives (its column of the
// tile x chunk count matrix). Mirror: cpu::tile::tile_count.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = TILE_BIN_WORKGROUP) in;
layout(std430, binding = 9) buffer Counts { uint counts[]; };
layout(std430, binding = 13) writeonly buffer Quads { ScreenQuad quads[]; };

void main() {
    uint chunk = gl_GlobalInvocationID.x;
    if (chunk >= pc.chunks) return;
    uvec2 grid = tile_grid();
    uvec2 range = chunk_entries(chunk);
    for (uint e = range.x; e < range.y; ++e) {
        uint splat = draw_list[e];
        ScreenQuad q = screen_record(params[splat]);
        quads[splat] = q;
        uvec4 r;
        if (!tile_range(q.box, r)) continue;
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
