#version 450
// Levels of detail above the brick, built after brick_pyramid when the classification changes: a
// lane per node of tree level pc.first (2^k bricks a side), from its 8 children: at level 1 the
// bricks' one level-3 cell (their summaries), above it the nodes of the level below. Prefiltered
// as brick_pyramid's levels are: opacity along each axis composited in pairs and averaged across,
// tau-weighted colour, sign-aligned normal, and the error (Laur-Hanrahan) of the largest over the
// children of their own error plus their departure from the node. So a node is one cell
// 2^(3+k) voxels a side, and a frame's cut (node_level) can draw a whole subtree as one splat.
// Each node also keeps the first header below it whose cell draws (that brick draws the node), and
// whether it may be drawn at all: inside the drawn bricks, its bricks consecutive in their order.
// Mirror: cpu::brick_nodes::brick_nodes.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

layout(push_constant) uniform Push {
    uint first;      // the tree level built
    uint count;      // its nodes
    uint splats;     // unused
    float occluded;  // unused
} pc;

void main() {
    uint i = linear_invocation();
    if (i >= pc.count) return;
    uint k = pc.first;
    uvec3 g = node_grid(k);
    uvec3 below = node_grid(k - 1u);
    uvec3 n = uvec3(i % g.x, (i / g.x) % g.y, i / (g.x * g.y));
    float voxels = float(1u << (3u * (3u + k)));
    float tk[8];
    vec3 ck[8];
    float ek[8];
    float ak[3][8];
    float t = 0.0;
    vec3 col = vec3(0.0);
    vec3 grad = vec3(0.0);
    uint rep = 0xffffffffu;
    for (uint d = 0u; d < 8u; ++d) {
        uvec3 c = 2u * n + (uvec3(d, d >> 1u, d >> 2u) & 1u);
        // A child outside the grid, or an empty brick: nothing.
        uvec3 words = uvec3(0u, NO_NORMAL << 16u, 0u);
        float e = 0.0;
        float tc = 0.0;
        uint r = 0xffffffffu;
        if (all(lessThan(c, below))) {
            if (k == 1u) {
                uint h = brick_index[c.x + bf.grid.x * (c.y + bf.grid.y * c.z)];
                if (h != 0xffffffffu) {
                    uint s = h * SUMMARY_WORDS;
                    uint cell = s + 4u + (LOD_CELLS - 1u - SLOT_CELLS) * CELL_WORDS;
                    words = uvec3(lod_words[cell], lod_words[cell + 1u], lod_words[cell + 2u]);
                    e = uintBitsToFloat(lod_words[s + 3u]);
                    tc = uintBitsToFloat(lod_words[s + SUMMARY_WORDS - 1u]);
                    r = h;
                }
            } else {
                uint w = node_word(k - 1u, c, 0u);
                words = uvec3(lod_words[w], lod_words[w + 1u], lod_words[w + 2u]);
                e = uintBitsToFloat(lod_words[w + 3u]);
                tc = uintBitsToFloat(lod_words[w + 4u]);
                r = lod_words[w + 5u];
            }
        }
        if ((words.x & 0xffffu) != 0u) rep = min(rep, r);
        vec3 straight = vec3(uvec3(words.z, words.z >> 10u, words.z >> 20u) & 1023u) / 1023.0;
        tk[d] = tc;
        ck[d] = straight * tc;
        ek[d] = e;
        ak[0][d] = 1.0 - exp(-tau_decode(words.x & 0xffffu));
        ak[1][d] = 1.0 - exp(-tau_decode(words.x >> 16u));
        ak[2][d] = 1.0 - exp(-tau_decode(words.y & 0xffffu));
        t += tc;
        col += ck[d];
        grad += aligned(unpack_normal(words.y >> 16u) * tc, grad);
    }
    float len = float(1u << (3u + k));
    float a = 1.0 - exp(-t / voxels * len);
    vec3 straight = t > 0.0 ? col / t : vec3(0.0);
    float err = 0.0;
    for (uint d = 0u; d < 8u; ++d) err = max(err, child_error(a, straight, tk[d], ck[d], ek[d], voxels / 8.0, len));
    uint codes[3];
    for (uint x = 0u; x < 3u; ++x) codes[x] = tau_code(-log(1.0 - min(axis_opacity(ak[x], x), 0.9999999)));
    uint w = node_word(k, n, 0u);
    lod_words[w] = codes[0] | (codes[1] << 16u);
    lod_words[w + 1u] = codes[2] | (pack_normal(grad) << 16u);
    lod_words[w + 2u] = unorm10(straight.r) | (unorm10(straight.g) << 10u) | (unorm10(straight.b) << 20u);
    lod_words[w + 3u] = floatBitsToUint(err);
    lod_words[w + 4u] = floatBitsToUint(t);
    lod_words[w + 5u] = rep;
    uvec3 n0 = n << k;
    uvec3 n1 = min(n0 + (1u << k), bf.grid.xyz);
    bool inside = all(greaterThanEqual(n0, bf.lo.xyz)) && all(lessThanEqual(n1, bf.hi.xyz));
    lod_words[w + 6u] = inside && consecutive(n0, n1) ? 1u : 0u;
}
