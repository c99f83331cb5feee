#version 450
// Sheet compositing: turn each summed sheet (rgb * tau, tau) into colour and alpha = 1 - exp(-tau)
// and composite the batch's layers, in visiting order, into the accumulation image.
// Mirror: cpu::composite.
#include "types.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(binding = 0, rgba32f) uniform readonly image2DArray sums;
layout(binding = 1, rgba32f) uniform image2D accum;
layout(push_constant) uniform Push {
    uint layers;
    uint back_to_front;
    uint width;
    uint height;
} pc;

void main() {
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= pc.width || px.y >= pc.height) return;
    vec4 acc = imageLoad(accum, ivec2(px));
    for (uint l = 0u; l < pc.layers; ++l) {
        vec4 s = imageLoad(sums, ivec3(px, l));
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
}
