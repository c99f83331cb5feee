#version 450
// Sheet compositing: turn each summed sheet (rgb * tau, tau) into colour and alpha = 1 - exp(-tau)
// and composite the batch's layers, in visiting order, into the accumulation image. Each workgroup
// also records its tile's largest remaining transmittance: the occlusion map that front-to-back
// early termination reads in footprint.vert (Mueller et al. 1999). Mirror: cpu::composite.
#include "types.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(binding = 0, rgba32f) uniform readonly image2DArray sums;
layout(binding = 1, rgba32f) uniform image2D accum;
layout(std430, binding = 2) writeonly buffer Occlusion { float occlusion[]; };
// The compute raster's layers: fixed-point (rgb * tau, tau), SUM_FIXED_SCALE per unit.
layout(std430, binding = 3) readonly buffer SumsFixed { uvec4 sums_fixed[]; };
// Per tile, the lowest sheet reaching it and the highest + 1 (sheet_tiles.comp).
layout(std430, binding = 4) readonly buffer SheetTiles { uint sheet_tiles[]; };
// 1: read the sums from sums_fixed (footprint_sum.comp), 0: from the sums image (the raster pass).
layout(constant_id = 0) const uint SUMS_FIXED = 0u;
layout(push_constant) uniform Push {
    uint layers;
    uint back_to_front;
    uint width;
    uint height;
    uint rank_base;  // global sheet of layer 0 (FootprintPush::rank_base)
    int rank_dir;    // +1 or -1: the batch's direction in sheet order
    uint tiles;      // composite tiles in the image
    uint pad;
} pc;

// The batch's layers [first, last] that footprints reach on this workgroup's tile.
ivec2 layer_range() {
    uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint lo = sheet_tiles[tile], hi = sheet_tiles[pc.tiles + tile];
    if (hi == 0u) return ivec2(0, -1);
    int a = int(lo) - int(pc.rank_base), b = int(hi) - 1 - int(pc.rank_base);
    ivec2 r = pc.rank_dir > 0 ? ivec2(a, b) : ivec2(-b, -a);
    return ivec2(max(r.x, 0), min(r.y, int(pc.layers) - 1));
}

shared float tile_transmittance[COMPOSITE_TILE * COMPOSITE_TILE];

void main() {
    uvec2 px = gl_GlobalInvocationID.xy;
    bool inside = px.x < pc.width && px.y < pc.height;
    float transmittance = 0.0; // outside the image: nothing left to cover
    if (inside) {
        vec4 acc = imageLoad(accum, ivec2(px));
        ivec2 range = layer_range();
        // Bottom-tested behind the emptiness test: llvmpipe runs a top-tested loop's body once more,
        // masked, for the test that ends it (the test is uniform per tile).
        int i = range.x;
        if (i <= range.y) do {
            uint l = uint(i);
            vec4 s;
            if (SUMS_FIXED != 0u) {
                s = vec4(sums_fixed[(l * pc.height + px.y) * pc.width + px.x]) / float(SUM_FIXED_SCALE);
            } else {
                s = imageLoad(sums, ivec3(px, l));
            }
            float t = s.a;
            if (t <= 0.0) continue;
            float a = 1.0 - exp(-t);
            vec3 rgb = s.rgb * (a / t);
            if (pc.back_to_front != 0u) {
                acc = vec4(rgb + (1.0 - a) * acc.rgb, a + (1.0 - a) * acc.a);
            } else {
                float r = 1.0 - acc.a;
                acc = vec4(acc.rgb + r * rgb, acc.a + r * a);
            }
        } while (++i <= range.y);
        imageStore(accum, ivec2(px), acc);
        transmittance = 1.0 - acc.a;
    }
    tile_transmittance[gl_LocalInvocationIndex] = transmittance;
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        float m = 0.0;
        for (uint i = 0u; i < COMPOSITE_TILE * COMPOSITE_TILE; ++i) m = max(m, tile_transmittance[i]);
        occlusion[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = m;
    }
}
