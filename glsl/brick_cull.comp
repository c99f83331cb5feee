#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Bricks, pass 1 (issue 23): one workgroup per non-empty brick. A brick outside the view, or whose
// value range the transfer function leaves empty, is culled whole; otherwise its lanes count the
// voxels the TF extracts (with levels of detail, a coarse brick's count is its level's drawn
// cells), and the brick writes header << 10 | count at its position in the PBTF order of the
// brick grid (the host then lists the visible bricks in draw order and cuts batches within the
// memory budget: recording.rs). Mirror: cpu::brick::brick_cull.
layout(local_size_x = BRICK_LANES) in;
#include "brick.glsl"

shared uint drawn;

void main() {
    uint h = workgroup_item();
    if (h >= bf.grid.w) return;
    uvec4 hd = headers[h];
    uvec3 b = brick_coords(hd.x);
    if (tf_empty(hd.w & 0xffffu, hd.w >> 16u)) return;
    // Levels of detail: a coarse brick draws its pyramid's cells (brick_pyramid counted them).
    uint level = brick_level(h, b);
    if (outside_view(b, float(1u << level))) return;
    uint lane = gl_LocalInvocationID.x;
    if (level > 0u) {
        uint n = level_count(h, level);
        if (lane == 0u && n > 0u) slots[brick_slot(b)] = (h << 10u) | n;
        return;
    }
#ifdef STREAMED_STORE
    // The records stay on the host, which counted each brick's drawn voxels with the TF table.
    if (lane == 0u && brick_counts[h] > 0u) slots[brick_slot(b)] = (h << 10u) | brick_counts[h];
#else
    if (lane == 0u) drawn = 0u;
    barrier();
    uint n = 0u;
    for (uint r = lane; r < hd.z; r += BRICK_LANES) {
        if (emits(record_at(hd.y + r) >> 16u)) n++;
    }
    atomicAdd(drawn, n);
    barrier();
    if (lane == 0u && drawn > 0u) slots[brick_slot(b)] = (h << 10u) | drawn;
#endif
}
