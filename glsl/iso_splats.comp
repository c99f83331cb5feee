#version 450
// Isosurface splats, pass 4 of 4 (Mode::Iso): one lane per surface splat (its cell from iso_cells)
// makes the splat at the mean of the cell's edge crossings moved onto the cell's trilinear surface
// (two Newton steps): a disc of ISO_DISC_VOXELS in the tangent plane (axis_u, axis_v), its
// (Lambert, specular) shading in emit.xy and the depth band in emit.a, its depth's steps along u and
// v in axis_v.w and screen.y (the tile compositor's per-pixel depth). The draw list is the storage
// order.
// Mirror: cpu::iso_splats.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "linear.glsl"
layout(std430, binding = 4) writeonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 5) writeonly buffer ParamsHi { SplatParams params_hi[]; };
layout(std430, binding = 6) writeonly buffer Order { uint order_out[]; };
PAGED_WRITER(SplatParams, params_store, params_lo, params_hi)
#include "params.glsl"
#include "surface.glsl"

// World gradient of an index-space one: U^-T g, U the cell matrix (upper triangular).
vec3 world_gradient(vec3 g) {
    vec3 s = frame.spacing.xyz;
    vec3 h = frame.shear.xyz;
    float x = g.x / s.x;
    float y = (g.y - h.x * x) / s.y;
    return vec3(x, y, (g.z - h.y * x - h.z * y) / s.z);
}

SplatParams surface_params(vec3 c, vec3 g) {
    vec3 forward = frame.forward.xyz;
    float depth = dot(c - frame.eye.xyz, forward);
    float radius = ISO_DISC_VOXELS * frame.spacing.w / frame.origin.w;
    float clear = min(depth - frame.forward.w, frame.right.w - depth);
    bool visible = clear >= CULL_RADII * radius;
    for (uint i = 0u; i < frame.rect.y; ++i) {
        visible = visible && dot(frame.clip[i].xyz, c) + frame.clip[i].w >= 0.0;
    }
    vec3 w = frame.eye.w > 0.5 ? normalize(c - frame.eye.xyz) : forward;
    float gl = length(g);
    vec3 n = gl > 0.0 ? g / gl : -w;
    if (dot(n, w) > 0.0) n = -n;
    // The disc's axes: one across the eye ray (its full radius on the screen), one up the slope.
    vec3 t = cross(n, w);
    float tl = length(t);
    t = tl > 1e-6 ? t / tl : normalize(frame.right.xyz - dot(frame.right.xyz, n) * n);
    vec3 b = cross(n, t);
    SplatParams p;
    p.center = vec4(c, visible ? 1.0 : 0.0);
    p.axis_u = vec4(t * radius, 1.0);
    p.axis_v = vec4(b * radius, dot(t, forward) * radius);
    p.emit = vec4(surface_light(n, w), 0.0, pc.band);
    float pixels = frame.eye.w > 0.5 ? radius * frame.up.w / max(depth, 1e-6) : radius * frame.up.w;
    p.screen = vec4(depth, dot(b, forward) * radius, pixels, 1.0);
    return p;
}

void main() {
    uint n = linear_invocation();
    if (n >= pc.splats) return;
    uvec2 cell = cells[n];
    ivec3 c0 = ivec3(int(cell.x & 0xffffu), int(cell.x >> 16u), int(cell.y & 0xffffu)) - 1;
    uint m = cell.y >> 16u;
    float v[8];
    for (int c = 0; c < 8; ++c) v[c] = float(iso_value(c0 + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1))) / ISO_Q;
    // The mean of the edges' crossings, then onto the cell's surface.
    vec3 sum = vec3(0.0);
    float crossings = 0.0;
    for (uint c = 0u; c < 8u; ++c) {
        for (uint b = 1u; b < 8u; b <<= 1u) {
            if ((c & b) != 0u || ((m >> c) & 1u) == ((m >> (c | b)) & 1u)) continue;
            float t = clamp((pc.iso - v[c]) / (v[c | b] - v[c]), 0.0, 1.0);
            vec3 p0 = vec3(c & 1u, (c >> 1u) & 1u, (c >> 2u) & 1u);
            vec3 p1 = vec3((c | b) & 1u, ((c | b) >> 1u) & 1u, ((c | b) >> 2u) & 1u);
            sum += mix(p0, p1, t);
            crossings += 1.0;
        }
    }
    vec3 p = sum / crossings;
    for (int s = 0; s < 2; ++s) {
        vec3 g = cell_gradient(v, p);
        float gg = dot(g, g);
        if (gg > 1e-12) p = clamp(p - (cell_value(v, p) - pc.iso) * g / gg, 0.0, 1.0);
    }
    params_store(n, surface_params(grid_point(vec3(c0) + p), world_gradient(cell_gradient(v, p))));
    order_out[n] = n;
}
