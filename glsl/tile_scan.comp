#version 450
// Compute per-splat compositing, binning pass 2 of 3: exclusive prefix sum of the tile x chunk count
// matrix (tile major, chunk minor) by one workgroup, then each tile's first entry and the total into
// tile_start (tiles + 1 entries). Mirror: cpu::tile::tile_scan.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = SCAN_WORKGROUP_SIZE) in;
layout(std430, binding = 9) buffer Counts { uint counts[]; };
layout(std430, binding = 10) writeonly buffer TileStart { uint tile_start[]; };
#include "count_scan.glsl"

void main() {
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    uint total = scan_counts(tiles * pc.chunks);
    for (uint t = gl_LocalInvocationID.x; t < tiles; t += SCAN_WORKGROUP_SIZE) tile_start[t] = counts[t * pc.chunks];
    if (gl_LocalInvocationID.x == 0u) tile_start[tiles] = total;
}
