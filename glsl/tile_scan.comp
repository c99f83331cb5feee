#version 450
// Compute per-splat compositing, binning pass 2 of 4: one invocation per screen tile turns its row
// of the tile x chunk count matrix into exclusive offsets within the tile (chunk order = list
// order) and writes the tile's total to tile_start. Rows are independent, so this runs wide where a
// single-workgroup scan of the whole matrix took llvmpipe ~120 ms at 512² (4096 tiles x 204 chunks).
// Mirror: cpu::tile::tile_scan.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 9) buffer Counts { uint counts[]; };
layout(std430, binding = 10) writeonly buffer TileStart { uint tile_start[]; };

void main() {
    uint t = linear_invocation();
    uvec2 grid = tile_grid();
    if (t >= grid.x * grid.y) return;
    uint carry = 0u;
    for (uint c = 0u; c < pc.chunks; ++c) {
        uint v = counts[t * pc.chunks + c];
        counts[t * pc.chunks + c] = carry;
        carry += v;
    }
    tile_start[t] = carry;
}
