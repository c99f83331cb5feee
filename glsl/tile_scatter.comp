#version 450
// Compute per-splat compositing, binning pass 3 of 3: each invocation walks its chunk again and
// writes each entry's splat at its own cursor of every tile it overlaps. Chunks are laid out in
// list order inside every tile's run and each chunk is walked in list order, so every tile's list
// keeps the draw list's (PBTF) order: a stable counting sort, no depth sort.
// Mirror: cpu::tile::tile_scatter.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = TILE_BIN_WORKGROUP) in;
layout(std430, binding = 9) buffer Counts { uint counts[]; };
layout(std430, binding = 11) writeonly buffer TileEntries { uint tile_entries[]; };
layout(std430, binding = 13) readonly buffer Quads { ScreenQuad quads[]; };

void main() {
    uint chunk = gl_GlobalInvocationID.x;
    if (chunk >= pc.chunks) return;
    uvec2 grid = tile_grid();
    uvec2 range = chunk_entries(chunk);
    for (uint e = range.x; e < range.y; ++e) {
        uint splat = draw_list[e];
        uvec4 r;
        if (!tile_range(quads[splat].box, r)) continue;
        for (uint ty = r.y; ty <= r.w; ++ty) {
            for (uint tx = r.x; tx <= r.z; ++tx) {
                uint cell = (ty * grid.x + tx) * pc.chunks + chunk;
                uint at = counts[cell];
                counts[cell] = at + 1u;
                tile_entries[at] = splat;
            }
        }
    }
}
