#version 450
// Compute per-splat compositing, binning pass 4 of 4: each invocation walks its chunk again and
// writes each entry's splat at its own cursor of every tile it overlaps. Chunks are laid out in
// list order inside every tile's run and each chunk is walked in list order, so every tile's list
// keeps the draw list's (PBTF) order: a stable counting sort, no depth sort.
// Mirror: cpu::tile::tile_scatter.
// ONE_PAGE: scenes within one page of splat records (types.glsl).
// variants: ONE_PAGE
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = TILE_BIN_WORKGROUP) in;
layout(std430, binding = 9) buffer Counts { uint counts[]; };
layout(std430, binding = 10) readonly buffer TileStart { uint tile_start[]; };
layout(std430, binding = 11) writeonly buffer TileEntries { uint tile_entries[]; };
layout(std430, binding = 13) readonly buffer Quads { ScreenQuad quads_lo[]; };
layout(std430, binding = 16) readonly buffer QuadsHi { ScreenQuad quads_hi[]; };
PAGED_FIELD_READER(ivec4, box_at, quads_lo, quads_hi, box)

void main() {
    uint chunk = gl_GlobalInvocationID.x;
    if (chunk >= pc.chunks) return;
    uvec2 grid = tile_grid();
    uvec2 range = chunk_entries(chunk);
    for (uint e = range.x; e < range.y; ++e) {
        uint splat = draw_list[e];
        uvec4 r;
        ivec4 box = box_at(splat);
        if (!tile_range(box, r)) continue;
        // Bottom-tested: the range is not empty (see tile_composite.comp on llvmpipe's loops).
        uint ty = r.y;
        do {
            uint tx = r.x;
            do {
                uint tile = ty * grid.x + tx;
                uint cell = tile * pc.chunks + chunk;
                uint at = counts[cell];
                counts[cell] = at + 1u;
                tile_entries[tile_start[tile] + at] = splat;
            } while (++tx <= r.z);
        } while (++ty <= r.w);
    }
}
