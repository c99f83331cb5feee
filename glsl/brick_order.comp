#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Bricks, pass 2 (issue 23): one workgroup per visible brick of a batch. Its lanes mark the cells
// the TF extracts at their dense PBTF positions in the brick (split at the eye's voxel split,
// clamped to the brick), so a voxel's rank among the marked cells is its place in the brick's PBTF
// sequence: the two-level order (docs/MODEL.md), no sort. Each extracted voxel is written (grid
// index and stored value) at the brick's first position + its rank, for brick_params. Bricks drawn
// at a coarser level of detail are brick_cells'.
// Mirror: cpu::brick::brick_order.
layout(local_size_x = BRICK_LANES) in;
#include "brick.glsl"

layout(push_constant) uniform Push {
    uint first;   // the batch's first entry of brick_list
    uint count;   // its entries
    uint splats;     // its splats
    float occluded;  // brick_hidden's threshold
} pc;

shared uint cells[MASK_WORDS];
shared uint below[MASK_WORDS + 1u];

void main() {
    uint e = workgroup_item();
    if (e >= pc.count) return;
    uvec4 entry = brick_list[pc.first + e];
    uvec4 hd = headers[entry.x];
    uvec3 b = brick_coords(hd.x);
    // Coarse bricks are brick_cells'.
    if ((entry.w >> 16u) != 0u) return;
    uint morphs = morph_bit(entry.x);
    uvec3 split = uvec3(clamp(ivec3(frame.split.xyz) - ivec3(b * BRICK_SIDE), ivec3(0), ivec3(BRICK_SIDE)));
    uint lane = gl_LocalInvocationID.x;
    for (uint w = lane; w < MASK_WORDS; w += BRICK_LANES) cells[w] = 0u;
    barrier();
    for (uint r = lane; r < hd.z; r += BRICK_LANES) {
        uint rec = record_at(entry.z + r);
        if (emits(rec >> 16u)) {
            uint p = dense_pbtf(local_cell(rec & 511u), uvec3(BRICK_SIDE), split);
            atomicOr(cells[p / 32u], 1u << (p % 32u));
        }
    }
    barrier();
    // Marked cells below each word.
    if (lane == 0u) {
        below[0] = 0u;
        for (uint w = 0u; w < MASK_WORDS; ++w) below[w + 1u] = below[w] + uint(bitCount(cells[w]));
    }
    barrier();
    uint total = below[MASK_WORDS];
    for (uint r = lane; r < hd.z; r += BRICK_LANES) {
        uint rec = record_at(entry.z + r);
        if (!emits(rec >> 16u)) continue;
        uvec3 lc = local_cell(rec & 511u);
        uint p = dense_pbtf(lc, uvec3(BRICK_SIDE), split);
        uint rank = below[p / 32u] + uint(bitCount(cells[p / 32u] & ((1u << (p % 32u)) - 1u)));
        uint pos = entry.y + (frame.split.w != 0u ? total - 1u - rank : rank);
        uvec3 ijk = b * BRICK_SIDE + lc;
        voxels[pos] = uvec2(ijk.x | (ijk.y << 16u), ijk.z | morphs | (rec & 0xffff0000u));
        order_out[pos] = pos;
    }
}
