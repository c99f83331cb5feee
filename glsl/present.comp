#version 450
// The frame's last stage when it goes to a host's image (Renderer::render_to) or over a background:
// the mean of the final images (the slotted blur's two slots), composited over the background,
// clamped to [0, 1] and, for a target that encodes or stores linear values (sRGB, float), decoded
// from the display values a PNG of the frame holds, so the target's own sRGB encoding gives those
// bytes back. Written in place into the accumulation image, which the blit then reads.
// Mirror: cpu::present.
#include "types.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(binding = 0, rgba32f) uniform image2D accum;
layout(binding = 1, rgba32f) uniform readonly image2D color;
layout(push_constant) uniform Push {
    vec4 background;  // premultiplied
    uint width;
    uint height;
    uint sources;     // bit 0: accum, bit 1: the raster target
    uint linear_out;
} pc;

float to_linear(float c) {
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    vec4 sum = vec4(0.0);
    float n = 0.0;
    if ((pc.sources & 1u) != 0u) {
        sum += imageLoad(accum, p);
        n += 1.0;
    }
    if ((pc.sources & 2u) != 0u) {
        sum += imageLoad(color, p);
        n += 1.0;
    }
    vec4 c = sum / max(n, 1.0);
    c = clamp(c + (1.0 - c.a) * pc.background, 0.0, 1.0);
    if (pc.linear_out != 0u && c.a > 0.0) {
        float a = c.a;
        vec3 s = min(c.rgb / a, vec3(1.0));
        c.rgb = vec3(to_linear(s.r), to_linear(s.g), to_linear(s.b)) * a;
    }
    imageStore(accum, p, c);
}
