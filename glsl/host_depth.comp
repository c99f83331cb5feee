#version 450
// The host's depth buffer as eye-space depth per pixel: each texel (D32's float, or D24's low 24
// bits unsigned normalised) at its pixel centre through the host's inverse projection, the depth
// along the view (-z of its eye space); +inf where the point is at or past infinity. The footprint
// stages then drop a splat at a pixel where its centre lies deeper. Mirror: cpu::host_depth.
#include "types.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(std430, binding = 0) readonly buffer Raw { uint raw[]; };
layout(std430, binding = 1) writeonly buffer Depth { float depth[]; };
layout(push_constant) uniform Push {
    mat4 inv_proj;
    uint width;
    uint height;
    uint format;  // 0: D32, 1: D24 in the low 24 bits
    uint pad;
} pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= pc.width || p.y >= pc.height) return;
    uint i = p.y * pc.width + p.x;
    uint t = raw[i];
    float z = pc.format == 0u ? uintBitsToFloat(t) : float(t & 0xffffffu) / 16777215.0;
    vec2 ndc = (vec2(p) + 0.5) / vec2(pc.width, pc.height) * 2.0 - 1.0;
    vec4 e = pc.inv_proj * vec4(ndc, z, 1.0);
    depth[i] = e.w > 0.0 ? -e.z / e.w : 1.0e30;
}
