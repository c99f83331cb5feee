#version 450
// Roofline of the compute compositing: read every layer of the summation array once and write the
// accumulation image, with no per-layer arithmetic beyond an add.
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
    for (uint l = 0u; l < pc.layers; ++l) acc += imageLoad(sums, ivec3(px, l));
    imageStore(accum, ivec2(px), acc);
}
