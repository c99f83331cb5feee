#version 450
// Levels of detail above the brick, per frame before brick_cull: a lane per level-1 node (2 x 2 x 2
// bricks) finds the node above it that draws its bricks this frame (node_level, from the top) and
// writes its tree level, 0 for none, to the node's cut word; brick_cull reads it for each brick.
// Once per level-1 node rather than per brick: the tests are the same for all its bricks.
// Mirror: cpu::brick_nodes::brick_node_cut.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

void main() {
    uint i = linear_invocation();
    uvec3 g = node_grid(1u);
    if (i >= g.x * g.y * g.z) return;
    uvec3 n = uvec3(i % g.x, (i / g.x) % g.y, i / (g.x * g.y));
    // A level-1 node whose bricks draw nothing: no node above it draws them either.
    if (lod_words[node_word(1u, n, 5u)] == 0xffffffffu) {
        lod_words[cut_word(n)] = 0u;
        return;
    }
    uvec3 b = n << 1u;
    vec3 lo;
    vec3 hi;
    voxel_box(b, 1u, lo, hi);
    lod_words[cut_word(n)] = node_level(b, voxel_pixels(box_depths(lo, hi).x));
}
