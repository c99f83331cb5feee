#version 450
// Footprint stage, fragment half: weight of the pre-integrated kernel (radial table) at this pixel's point on the
// quad (or point sprite), as optical depth. Per-splat mode emits premultiplied colour and
// alpha = 1 - exp(-tau) for over/under blending; sheet mode emits (rgb * tau, tau) for additive
// summation; slab mode weighs by the kernel slice between the slab's faces instead of the whole
// footprint; a motion-blurred footprint is weighed along its path (footprint_value). Mirror:
// cpu::footprint.
#include "types.glsl"

layout(std430, binding = 5) readonly buffer Radial { vec2 radial[]; };  // Kernel::radial_pairs
layout(binding = 6) uniform sampler2D slices;
#include "footprint_table.glsl"
// The modes are fixed per pipeline (a branch on the push constant made llvmpipe pay for both
// sides); the push constant's sheet_mode carries the same value for the CPU mirror.
layout(constant_id = 0) const uint SHEET_MODE = SHEET_MODE_SPLAT;
layout(constant_id = 1) const uint POINTS = 0u;
// A projection mode's blend (BLEND_*, types.glsl): the pipeline blends by maximum or sum.
layout(constant_id = 2) const uint PROJECT = BLEND_COMPOSITE;

layout(location = 0) in vec2 in_uv;
layout(location = 1) flat in vec4 in_emit;
layout(location = 2) flat in vec3 in_sweep;  // motion stretch, bend, profile
layout(location = 4) flat in vec2 in_depth;    // the splat's eye-space depth; y: 1 = tested
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
// The host's eye-space depth per pixel: a fragment of a splat deeper than it is dropped.
layout(std430, binding = 18) readonly buffer HostDepth { float host_depth[]; };
#ifndef SLOTS
layout(location = 3) flat in vec2 in_slab;
#endif
layout(location = 0) out vec4 out_color;
// variants: SLOTS
#ifdef SLOTS
// Pass::Slots: the second half of the shutter (out_color takes the first).
layout(location = 1) out vec4 out_slot;
#endif

void main() {
    if (in_depth.y != 0.0) {
        uvec2 px = uvec2(gl_FragCoord.xy);
        if (in_depth.x > host_depth[px.y * uint(frame.blur.z) + px.x]) discard;
    }
    vec2 uv = POINTS != 0u ? gl_PointCoord * 2.0 - 1.0 : in_uv;
#ifdef SLOTS
    vec2 a = footprint_slots(uv, in_sweep, in_emit.a);
    if (max(a.x, a.y) <= 0.0) discard;
    out_color = vec4(in_emit.rgb * a.x, a.x);
    out_slot = vec4(in_emit.rgb * a.y, a.y);
#else
    if (PROJECT == BLEND_MAX) {
        // As tile_composite: the key weighed by the footprint over its centre's, and the coverage.
        float s = footprint_r2(uv, 0.0, 0.0);
        if (s >= 1.0) discard;
        float w = min(sample_radial(s) / (PROJECT_FULL * radial[0].x), 1.0);
        out_color = vec4(in_emit.r * w, w, 0.0, 0.0);
        return;
    }
    if (PROJECT == BLEND_SUM) {
        float s = footprint_r2(uv, 0.0, 0.0);
        if (s >= 1.0) discard;
        float d = in_emit.a * sample_radial(s);
        out_color = vec4(in_emit.r * d, d, 0.0, 0.0);
        return;
    }
    // Optical depth (sheets) or alpha (per splat).
    float v = footprint_value(slices, SHEET_MODE == SHEET_MODE_SLAB, uv, in_sweep, in_slab, in_emit.a,
                              SHEET_MODE == SHEET_MODE_SPLAT);
    if (v <= 0.0) discard;
    out_color = vec4(in_emit.rgb * v, v);
#endif
}
