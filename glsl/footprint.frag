#version 450
// Footprint stage, fragment half: weight of the pre-integrated kernel at this pixel's point on the
// quad, as optical depth. Per-splat mode emits premultiplied colour and alpha = 1 - exp(-tau) for
// over/under blending; sheet mode emits (rgb * tau, tau) for additive summation; slab mode weighs
// by the kernel slice between the slab's faces instead of the whole footprint. Mirror: cpu::footprint.
#include "types.glsl"
#include "footprint_table.glsl"

layout(binding = 5) uniform sampler2D table;
layout(binding = 6) uniform sampler2D slices;
// The mode is fixed per pipeline (a branch on the push constant made llvmpipe pay for both sides);
// the push constant's sheet_mode carries the same value for the CPU mirror.
layout(constant_id = 0) const uint SHEET_MODE = SHEET_MODE_SPLAT;

layout(push_constant) uniform Push {
    uint sheet_mode;
} pc;

layout(location = 0) in vec2 in_uv;
layout(location = 1) flat in vec4 in_emit;
layout(location = 2) flat in float in_stretch;
layout(location = 3) flat in vec2 in_slab;
layout(location = 0) out vec4 out_color;

void main() {
    // Distance beyond the motion segment along u (radius units); the kernel profile across it.
    float along = max(abs(in_uv.x) * (1.0 + in_stretch) - in_stretch, 0.0);
    float weight;
    if (SHEET_MODE == SHEET_MODE_SLAB) {
        float r = length(vec2(along, in_uv.y));
        weight = sample_slice_table(slices, r, in_slab.y) - sample_slice_table(slices, r, in_slab.x);
    } else {
        weight = sample_table(table, vec2(along, in_uv.y));
    }
    float tau = in_emit.a * weight;
    if (tau <= 0.0) discard;
    if (SHEET_MODE != SHEET_MODE_SPLAT) {
        out_color = vec4(in_emit.rgb * tau, tau);
    } else {
        float a = 1.0 - exp(-tau);
        out_color = vec4(in_emit.rgb * a, a);
    }
}
