#version 450
// Compute per-splat compositing, binning pass 3 of 4: exclusive prefix sum of the tiles' totals by
// one workgroup, in place, so tile_start holds each tile's first entry and, at [tiles], the total.
// Mirror: cpu::tile::tile_offsets.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"
#include "tiles.glsl"

layout(local_size_x = SCAN_WORKGROUP_SIZE) in;
layout(std430, binding = 10) buffer TileStart { uint tile_start[]; };
#define SCAN_BUFFER tile_start
#include "count_scan.glsl"

void main() {
    uvec2 grid = tile_grid();
    uint tiles = grid.x * grid.y;
    uint total = scan_counts(tiles);
    if (gl_LocalInvocationID.x == 0u) tile_start[tiles] = total;
}
