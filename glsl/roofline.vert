#version 450
// Roofline: the cheapest instanced quad we can draw — a square of `size` pixels on a grid,
// no buffers. Measures the raster pipeline's best fragment rate for a footprint size.
layout(push_constant) uniform Push {
    uint columns;
    uint size;     // quad side in pixels
    uint width;
    uint height;
} pc;

layout(location = 0) out vec2 out_uv;

const vec2 CORNERS[4] = vec2[](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));

void main() {
    uint i = uint(gl_InstanceIndex);
    vec2 cell = vec2(i % pc.columns, (i / pc.columns) % max(1u, pc.height / pc.size));
    vec2 c = CORNERS[gl_VertexIndex];
    vec2 center = (cell + 0.5) * float(pc.size);
    vec2 px = center + c * 0.5 * float(pc.size);
    out_uv = c;
    gl_Position = vec4(px / vec2(pc.width, pc.height) * 2.0 - 1.0, 0.5, 1.0);
}
