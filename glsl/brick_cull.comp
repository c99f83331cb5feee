#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Bricks, pass 1 (issue 23): one lane per non-empty brick. A brick outside the view, or whose
// value range the transfer function leaves empty, is culled whole; otherwise it counts the voxels
// the TF extracts (with levels of detail, brick_pyramid counted every level's splats, and the
// brick takes its level's; a brick under a node drawn whole (brick_node_cut) is left to the node,
// which the first brick below it whose cell draws writes at its own position, as level 3 + the
// node's tree level), and writes header << 10 | slot_code(level, count) at its position in the
// brick order (brick_slot; the host then lists the visible bricks in draw order and cuts batches
// within the memory budget: recording.rs). Mirror: cpu::brick::brick_cull.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

void main() {
    uint h = linear_invocation();
    if (h >= bf.grid.w) return;
    uvec4 hd = headers[h];
    uvec3 b = brick_coords(hd.x);
    // Outside this rank's box (sort-last): held for its neighbours' gradients only.
    if (any(lessThan(b, bf.lo.xyz)) || any(greaterThanEqual(b, bf.hi.xyz))) return;
    if (tf_empty(hd.w & 0xffffu, hd.w >> 16u)) return;
    float morph;
    uint level = brick_level(h, b, morph);
    uint k = bf.grad.y > 0.0 && bf.hi.w > 0u ? lod_words[cut_word(b >> 1u)] : 0u;
    if (k > 0u) {
        brick_morph[h] = 0.0;
        uint w = node_word(k, b >> k, 0u);
        if (lod_words[w + 5u] != h || !(tau_decode(lod_words[w] & 0xffffu) > 0.0)) return;
        if (outside_view(b, k, float(BRICK_SIDE << k))) return;
        slots[brick_slot(b)] = (h << 10u) | slot_code(3u + k, 1u);
        return;
    }
    if (outside_view(b, 0u, float(1u << level) * (1.0 + morph))) return;
    uint n = 0u;
    if (bf.grad.y > 0.0) {
        n = level_count(h, level);
    } else {
#ifdef STREAMED_STORE
        // The records stay on the host, which counted each brick's drawn voxels with the TF table.
        n = brick_counts[h];
#else
        for (uint r = 0u; r < hd.z; ++r) {
            if (emits(record_at(hd.y + r) >> 16u)) n++;
        }
#endif
    }
    if (n > 0u) slots[brick_slot(b)] = (h << 10u) | slot_code(level, n);
    if (bf.grad.y > 0.0) brick_morph[h] = morph;
}
