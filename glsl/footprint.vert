#version 450
// Footprint stage, vertex half: one instanced quad per splat in draw-list order; in sheet mode each
// splat goes to the layer of its sheet; in slab mode (image-aligned sheets) the draw list holds
// (splat, slab) pairs and each pair goes to its slab's layer with the slab's faces relative to the
// splat. Mirror: cpu::footprint.
#extension GL_ARB_shader_viewport_layer_array : require
#include "types.glsl"

layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Params { SplatParams params[]; };
layout(std430, binding = 2) readonly buffer DrawList { uint draw_list[]; };
layout(std430, binding = 3) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 4) readonly buffer SheetRank { uint sheet_rank[]; };
layout(std430, binding = 7) readonly buffer Occlusion { float occlusion[]; };

// The mode is fixed per pipeline (a branch on the push constant made llvmpipe pay for both sides);
// the push constant's sheet_mode carries the same value for the CPU mirror.
layout(constant_id = 0) const uint SHEET_MODE = SHEET_MODE_SPLAT;

layout(push_constant) uniform Push {
    uint sheet_mode;   // SHEET_MODE_*
    uint axis;         // sheet axis
    uint rank_offset;  // start of this axis in sheet_rank
    uint rank_base;    // rank of the batch's first sheet (slab mode: its first slab)
    int rank_dir;      // +1 or -1: direction of the batch in rank space
    float slab_z0;     // slab mode: eye-space depth of slab 0's near face
    float slab_dz;     // slab mode: slab thickness (world units)
    float occluded;    // front-to-back early termination: skip a splat whose every tile has at most
                       // this transmittance left (0: off)
} pc;

layout(location = 0) out vec2 out_uv;
layout(location = 1) flat out vec4 out_emit;
layout(location = 2) flat out float out_stretch;
layout(location = 3) flat out vec2 out_slab;

const vec2 CORNERS[4] = vec2[](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
// Most tiles a footprint may span and still be tested (larger ones are always drawn).
const int MAX_OCCLUSION_TILES = 16;

// Whether the footprint quad lies wholly over tiles whose transmittance is at most pc.occluded.
// Every vertex of the quad computes the same answer from the same four corners. Mirror:
// cpu::footprint::occluded.
bool occluded(SplatParams p) {
    vec2 size = frame.blur.zw;
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    for (int k = 0; k < 4; ++k) {
        vec3 q = p.center.xyz + CORNERS[k].x * p.axis_u.xyz + CORNERS[k].y * p.axis_v.xyz;
        vec4 c = frame.view_proj * vec4(q, 1.0);
        if (c.w <= 0.0) return false;
        vec2 s = (c.xy / c.w * 0.5 + 0.5) * size;
        lo = min(lo, s);
        hi = max(hi, s);
    }
    ivec2 tiles = ivec2(ceil(size / float(COMPOSITE_TILE)));
    ivec2 t0 = ivec2(floor(clamp(lo, vec2(0.0), size - 1.0) / float(COMPOSITE_TILE)));
    ivec2 t1 = ivec2(floor(clamp(hi, vec2(0.0), size - 1.0) / float(COMPOSITE_TILE)));
    if ((t1.x - t0.x + 1) * (t1.y - t0.y + 1) > MAX_OCCLUSION_TILES) return false;
    for (int y = t0.y; y <= t1.y; ++y) {
        for (int x = t0.x; x <= t1.x; ++x) {
            if (occlusion[y * tiles.x + x] > pc.occluded) return false;
        }
    }
    return true;
}

void main() {
    bool slab_mode = SHEET_MODE == SHEET_MODE_SLAB;
    uint splat = slab_mode ? draw_list[2 * gl_InstanceIndex] : draw_list[gl_InstanceIndex];
    SplatParams p = params[splat];
    out_slab = vec2(0.0);
    vec2 c = CORNERS[gl_VertexIndex];
    out_uv = c;
    out_emit = vec4(p.emit.rgb, p.emit.a * p.axis_u.w);
    out_stretch = p.axis_v.w;
    if (p.center.w == 0.0 || (SHEET_MODE != SHEET_MODE_SPLAT && pc.occluded > 0.0 && occluded(p))) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume: culled
    } else {
        vec3 pos = p.center.xyz + c.x * p.axis_u.xyz + c.y * p.axis_v.xyz;
        gl_Position = frame.view_proj * vec4(pos, 1.0);
    }
    if (slab_mode) {
        uint slab = draw_list[2 * gl_InstanceIndex + 1];
        float radius = length(p.axis_v.xyz);
        float near_face = pc.slab_z0 + float(slab) * pc.slab_dz - p.screen.x;
        out_slab = vec2(near_face, near_face + pc.slab_dz) / radius;
        gl_Layer = pc.rank_dir > 0 ? int(slab - pc.rank_base) : int(pc.rank_base - slab);
    } else if (SHEET_MODE == SHEET_MODE_AXIS) {
        uint rank = sheet_rank[pc.rank_offset + splats[splat].ijk[pc.axis]];
        gl_Layer = pc.rank_dir > 0 ? int(rank - pc.rank_base) : int(pc.rank_base - rank);
    } else {
        gl_Layer = 0;
    }
}
