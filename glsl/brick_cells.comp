#version 450
// variants: STREAMED_STORE
// Levels of detail (issue 24), pass 2 for the coarse bricks of a batch: one lane per entry of
// brick_list. A brick drawn at level l > 0 writes its pyramid's drawn cells, visiting the brick's
// cells of 2^l voxels in PBTF order (split like the brick grid: level_split), each as (lowest
// voxel, level, cell) at the brick's first position + its rank: the two-level order with cells for
// voxels, no sort; a node above the brick (level 3 + its tree level) writes its one cell. Voxel
// bricks are brick_order's. A streamed store's pyramid holds the batch's
// bricks (STREAMED_STORE: pyramid_index). Mirror: cpu::lod::brick_cells.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

layout(push_constant) uniform Push {
    uint first;      // the batch's first entry of brick_list
    uint count;      // its entries
    uint splats;     // its splats
    float occluded;  // brick_hidden's threshold
} pc;

// Cells visited along one axis from the split outward: first the low side downward, then the
// high side upward (side 0: indices below s, side 1: the rest).
int axis_cell(uint side, uint s, uint t) {
    return side == 0u ? int(s) - 1 - int(t) : int(s + t);
}

void main() {
    uint e = linear_invocation();
    if (e >= pc.count) return;
    uvec4 entry = brick_list[pc.first + e];
    uint level = entry.w >> 16u;
    if (level == 0u) return;
    uvec3 b = brick_coords(headers[entry.x].x);
    if (level > 3u) {
        // A node above the brick: one splat at its lowest voxel, its tree level in the first word.
        uint k = level - 3u;
        uvec3 ijk = ((b >> k) << k) * BRICK_SIDE;
        voxels[entry.y] = uvec2(ijk.x | (k << 13u) | (ijk.y << 16u), ijk.z | (3u << 13u));
        order_out[entry.y] = entry.y;
        return;
    }
    uint n = BRICK_SIDE >> level;
    uint off = level_offset(level);
    uint morphs = morph_bit(entry.x);
    uvec3 split = level_split(b, level);
    uint total = entry.w & 0xffffu;
    uint rank = 0u;
    // Octants in turn; inside each, k outward, then j, then i (dense_pbtf's sequence).
    for (uint o = 0u; o < 8u; ++o) {
        uvec3 side = uvec3(o, o >> 1u, o >> 2u) & 1u;
        uvec3 len = uvec3(side_count(n, split.x, side.x), side_count(n, split.y, side.y), side_count(n, split.z, side.z));
        for (uint tk = 0u; tk < len.z; ++tk) {
            for (uint tj = 0u; tj < len.y; ++tj) {
                for (uint ti = 0u; ti < len.x; ++ti) {
                    uvec3 cc = uvec3(axis_cell(side.x, split.x, ti), axis_cell(side.y, split.y, tj), axis_cell(side.z, split.z, tk));
                    uint c = cc.x + n * (cc.y + n * cc.z);
                    if (!(cell_tau(entry.x, off + c) > 0.0)) continue;
                    uint pos = entry.y + (frame.split.w != 0u ? total - 1u - rank : rank);
                    uvec3 ijk = b * BRICK_SIDE + (cc << level);
                    voxels[pos] = uvec2(ijk.x | (ijk.y << 16u), ijk.z | (level << 13u) | morphs | ((off + c) << 16u));
                    order_out[pos] = pos;
                    rank++;
                }
            }
        }
    }
}
