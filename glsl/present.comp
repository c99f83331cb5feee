#version 450
// The frame's last stage when it goes to a host's image (Renderer::render_to) or over a background:
// the mean of the final images (the slotted blur's two slots), composited over the background,
// clamped to [0, 1] and, for a target that encodes or stores linear values (sRGB, float), decoded
// from the display values a PNG of the frame holds, so the target's own sRGB encoding gives those
// bytes back. Over the host's image (PRESENT_OVER) its texels, as premultiplied display values,
// take the background's place pixel by pixel: the frame over a uniform host image is the frame
// over that background. Written in place into the accumulation image, which the blit then reads.
// Mirror: cpu::present.
#include "types.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(binding = 0, rgba32f) uniform image2D accum;
layout(binding = 1, rgba32f) uniform readonly image2D color;
// The host's image as the frame found it, texels as stored (a word each, two for halves).
layout(std430, binding = 2) readonly buffer HostColor { uint host_color[]; };
layout(push_constant) uniform Push {
    vec4 background;  // premultiplied
    uint width;
    uint height;
    uint sources;     // bit 0: accum, bit 1: the raster target; PRESENT_OVER, PRESENT_HOST_*
    uint linear_out;
} pc;

float to_linear(float c) {
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

float to_srgb(float c) {
    return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

// The host's texel i as premultiplied display values: 8-bit texels hold them as stored (an sRGB
// texel's bytes are its encoded, display value), half-float ones hold linear values, encoded here.
vec4 host_texel(uint i) {
    if ((pc.sources & PRESENT_HOST_HALF) != 0u) {
        vec4 t = vec4(unpackHalf2x16(host_color[2u * i]), unpackHalf2x16(host_color[2u * i + 1u]));
        t = clamp(t, 0.0, 1.0);
        if (t.a <= 0.0) return vec4(0.0);
        vec3 s = min(t.rgb / t.a, vec3(1.0));
        return vec4(vec3(to_srgb(s.r), to_srgb(s.g), to_srgb(s.b)) * t.a, t.a);
    }
    vec4 t = unpackUnorm4x8(host_color[i]);
    return (pc.sources & PRESENT_HOST_BGRA) != 0u ? t.zyxw : t;
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
    vec4 under = (pc.sources & PRESENT_OVER) != 0u ? host_texel(uint(p.y) * pc.width + uint(p.x)) : pc.background;
    c = clamp(c + (1.0 - c.a) * under, 0.0, 1.0);
    if (pc.linear_out != 0u && c.a > 0.0) {
        float a = c.a;
        vec3 s = min(c.rgb / a, vec3(1.0));
        c.rgb = vec3(to_linear(s.r), to_linear(s.g), to_linear(s.b)) * a;
    }
    imageStore(accum, p, c);
}
