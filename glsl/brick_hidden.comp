#version 450
// Bricks, between batches drawn front to back with early termination (issue 23): per brick of the
// next batch, whether its footprints' screen box lies wholly over composite tiles whose
// transmittance is at most the termination threshold (tile_occlusion). The tile compositor would
// stop every pixel such a brick reaches before its first splat, so dropping it changes nothing:
// the tile compositor's early termination extended to whole bricks. Mirror: cpu::brick::brick_hidden.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

layout(push_constant) uniform Push {
    uint first;      // the batch's first entry of brick_list
    uint count;      // its entries
    uint splats;     // its splats
    float occluded;  // the early-termination threshold
} pc;

// Most composite tiles a brick may span and still be tested (larger ones are always drawn).
const int MAX_BRICK_TILES = 256;

bool hidden(uint h, uint level, uvec3 b) {
    vec3 lo;
    vec3 hi;
    // A node above the brick (level 3 + its tree level) does not morph.
    uint k = level > 3u ? level - 3u : 0u;
    footprint_box(b, k, float(1u << level) * (1.0 + (bf.grad.y > 0.0 ? brick_morph[h] : 0.0)), lo, hi);
    vec2 size = frame.blur.zw;
    vec2 slo = vec2(1e30);
    vec2 shi = vec2(-1e30);
    for (uint c = 0u; c < 8u; ++c) {
        vec4 q = frame.view_proj * vec4(mix(lo, hi, vec3(uvec3(c, c >> 1u, c >> 2u) & 1u)), 1.0);
        if (q.w <= 0.0) return false;
        vec2 s = (q.xy / q.w * 0.5 + 0.5) * size;
        slo = min(slo, s);
        shi = max(shi, s);
    }
    ivec2 tiles = ivec2(ceil(size / float(COMPOSITE_TILE)));
    ivec2 t0 = ivec2(floor(clamp(slo - 1.0, vec2(0.0), size - 1.0) / float(COMPOSITE_TILE)));
    ivec2 t1 = ivec2(floor(clamp(shi + 1.0, vec2(0.0), size - 1.0) / float(COMPOSITE_TILE)));
    if ((t1.x - t0.x + 1) * (t1.y - t0.y + 1) > MAX_BRICK_TILES) return false;
    for (int y = t0.y; y <= t1.y; ++y) {
        for (int x = t0.x; x <= t1.x; ++x) {
            if (occlusion[y * tiles.x + x] > pc.occluded) return false;
        }
    }
    return true;
}

void main() {
    uint e = linear_invocation();
    if (e >= pc.count) return;
    uvec4 entry = brick_list[pc.first + e];
    hidden_out[e] = hidden(entry.x, entry.w >> 16u, brick_coords(headers[entry.x].x)) ? 1u : 0u;
}
