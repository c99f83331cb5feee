#version 450
// Footprint stage, vertex half: one instanced quad per splat in draw-list order; in sheet mode each
// splat goes to the layer of its sheet. Mirror: cpu::footprint.
#extension GL_ARB_shader_viewport_layer_array : require
#include "types.glsl"

layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Params { SplatParams params[]; };
layout(std430, binding = 2) readonly buffer DrawList { uint draw_list[]; };
layout(std430, binding = 3) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 4) readonly buffer SheetRank { uint sheet_rank[]; };

layout(push_constant) uniform Push {
    uint sheet_mode;   // 0: per-splat compositing, 1: additive sheet summation
    uint axis;         // sheet axis
    uint rank_offset;  // start of this axis in sheet_rank
    uint rank_base;    // rank of the batch's first sheet
    int rank_dir;      // +1 or -1: direction of the batch in rank space
} pc;

layout(location = 0) out vec2 out_uv;
layout(location = 1) flat out vec4 out_emit;
layout(location = 2) flat out float out_stretch;

const vec2 CORNERS[4] = vec2[](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));

void main() {
    uint splat = draw_list[gl_InstanceIndex];
    SplatParams p = params[splat];
    vec2 c = CORNERS[gl_VertexIndex];
    out_uv = c;
    out_emit = vec4(p.emit.rgb, p.emit.a * p.axis_u.w);
    out_stretch = p.axis_v.w;
    if (p.center.w == 0.0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume: culled
    } else {
        vec3 pos = p.center.xyz + c.x * p.axis_u.xyz + c.y * p.axis_v.xyz;
        gl_Position = frame.view_proj * vec4(pos, 1.0);
    }
    if (pc.sheet_mode != 0u) {
        uint rank = sheet_rank[pc.rank_offset + splats[splat].ijk[pc.axis]];
        gl_Layer = pc.rank_dir > 0 ? int(rank - pc.rank_base) : int(pc.rank_base - rank);
    } else {
        gl_Layer = 0;
    }
}
