#version 450
// Footprint stage, vertex half: one instanced quad per draw-list entry (or, in the point pipelines,
// one point sprite per entry, as wide as the footprint). In sheet mode each splat goes to the layer
// of its sheet; in slab mode (image-aligned sheets) the draw list holds (splat, slab) pairs and each
// pair goes to its slab's layer with the slab's faces relative to the splat. Mirror: cpu::footprint.
#extension GL_ARB_shader_viewport_layer_array : require
// The two-slot pass's pipelines load this stage's SLOTS build too (the same code).
// variants: SLOTS
#include "footprint.glsl"

// 1: point sprites (one vertex per entry, indexed by gl_VertexIndex), 0: instanced quads.
layout(constant_id = 1) const uint POINTS = 0u;

layout(location = 0) out vec2 out_uv;
layout(location = 1) flat out vec4 out_emit;
layout(location = 2) flat out vec3 out_sweep;  // motion stretch, bend, profile
layout(location = 4) flat out vec2 out_depth;  // eye-space depth; y: 1 = the host's depth test on
#ifndef SLOTS
layout(location = 3) flat out vec2 out_slab;
#endif

void main() {
    uint entry = POINTS != 0u ? uint(gl_VertexIndex) : uint(gl_InstanceIndex);
    uint splat = entry_splat(entry);
    SplatParams p = params_at(splat);
    vec2 c = CORNERS[gl_VertexIndex & 3];
    out_uv = c;
    out_emit = vec4(p.emit.rgb, p.emit.a * p.axis_u.w);
    out_sweep = vec3(p.axis_v.w, p.screen.y, frame.sweep.y);
    out_depth = vec2(p.screen.x, float(frame.rect.w));
    if (p.center.w == 0.0 || (SHEET_MODE != SHEET_MODE_SPLAT && pc.occluded > 0.0 && occluded(p))) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // outside the clip volume: culled
        gl_PointSize = 1.0;
    } else if (POINTS != 0u) {
        // A screen-aligned square 2r pixels wide around the projected centre (a circular footprint).
        gl_Position = frame.view_proj * vec4(p.center.xyz, 1.0);
        gl_PointSize = 2.0 * p.screen.z;
    } else {
        vec3 pos = p.center.xyz + c.x * p.axis_u.xyz + c.y * p.axis_v.xyz;
        gl_Position = frame.view_proj * vec4(pos, 1.0);
    }
    // No depth test reads it: halfway through the clip volume, so that no corner of a quad that
    // anti-aliasing widened past the far plane is clipped (the compute raster clips none either).
    if (p.center.w != 0.0) gl_Position.z = 0.5 * gl_Position.w;
#ifdef SLOTS
    vec2 faces;  // per-splat compositing: no slab
    gl_Layer = entry_layer(entry, splat, p, faces);
#else
    gl_Layer = entry_layer(entry, splat, p, out_slab);
#endif
}
