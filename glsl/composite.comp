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
// 1: read the sums from sums_fixed (footprint_sum.comp), 0: from the sums image (the raster pass).
layout(constant_id = 0) const uint SUMS_FIXED = 0u;
layout(push_constant) uniform Push {
    uint layers;
    uint back_to_front;
    uint width;
    uint height;
} pc;

shared float tile_transmittance[COMPOSITE_TILE * COMPOSITE_TILE];

void main() {
    uvec2 px = gl_GlobalInvocationID.xy;
    bool inside = px.x < pc.width && px.y < pc.height;
    float transmittance = 0.0; // outside the image: nothing left to cover
    if (inside) {
        vec4 acc = imageLoad(accum, ivec2(px));
        for (uint l = 0u; l < pc.layers; ++l) {
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
        }
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
