#version 450
// Bricks, between waves drawn front to back with early termination: per entry of the next wave,
// whether its footprints' screen box covers no open pixel of the occlusion map (tile_occlusion;
// occlusion.glsl), that is, lies wholly over pixels with at most the termination threshold of
// transmittance left. The tile compositor would stop every pixel such a brick (or node) reaches
// before its first splat, so dropping it changes nothing: the compositor's early termination moved
// before the brick's voxels are ordered, classified or binned. Mirror: cpu::brick_hidden.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"
#include "occlusion.glsl"

layout(push_constant) uniform Push {
    uint first;      // the batch's first entry of brick_list
    uint count;      // its entries
    uint splats;     // its splats
    float occluded;  // the early-termination threshold (tile_occlusion's map is built for it)
} pc;

bool hidden(uint h, uint level, uvec3 b) {
    // A blurred quad reaches back along its path, past the footprint box.
    if (frame.blur.x > 0.0) return false;
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
    // A pixel's margin: the footprints' pixel boxes (screen_quad) lie inside.
    vec2 a = floor(clamp(slo - 1.0, vec2(0.0), size - 1.0));
    vec2 z = floor(clamp(shi + 1.0, vec2(0.0), size - 1.0));
    return box_hidden(ivec4(a, z));
}

void main() {
    uint e = linear_invocation();
    if (e >= pc.count) return;
    uvec4 entry = brick_list[pc.first + e];
    hidden_out[e] = hidden(entry.x, entry.w >> 16u, brick_coords(headers[entry.x].x)) ? 1u : 0u;
}
