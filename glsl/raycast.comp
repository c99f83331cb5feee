#version 450
// Ray caster: the method a user would otherwise pick. One invocation per pixel marches front to back
// at a fixed step through the trilinearly reconstructed (colour * tau, tau) field, with the same
// emission-absorption model as the splats, early ray termination, and empty-space skipping: a
// sample in a brick whose every voxel (and a one-voxel margin) is empty jumps to the first sample
// past the brick, which skips exactly the samples that would add nothing. Mirror: cpu::raycast.
#include "types.glsl"
#include "trilinear.glsl"
#include "surface.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(std430, binding = 0) readonly buffer ParamsBlock { RaycastParams rc; };
layout(binding = 1) uniform sampler3D field;
layout(binding = 2, rgba32f) uniform writeonly image2D out_image;
layout(std430, binding = 3) readonly buffer Bricks { uint bricks[]; };  // 1: occupied

// World offset d in index units: the inverse cell matrix (upper triangular) times d.
vec3 to_index(vec3 d) {
    vec3 s = rc.inv_spacing.xyz;
    vec3 h = rc.inv_shear.xyz;
    return vec3(d.x * s.x + d.y * h.x + d.z * h.y, d.y * s.y + d.z * h.z, d.z * s.z);
}

// The first sample index past the empty brick `b` for a ray a + dir t (index space) sampled at
// t0 + (s + 0.5) step.
uint skip_brick(ivec3 b, ivec3 nb, uint bs, vec3 a, vec3 dir, float t0, float step, uint s) {
    vec3 lo = vec3(b) * float(bs);
    vec3 hi = lo + float(bs);
    float t_exit = 3.4e38;
    for (int ax = 0; ax < 3; ++ax) {
        // Edge bricks also hold the samples beyond the grid on their side.
        if (dir[ax] > 0.0 && b[ax] < nb[ax] - 1) t_exit = min(t_exit, (hi[ax] - a[ax]) / dir[ax]);
        if (dir[ax] < 0.0 && b[ax] > 0) t_exit = min(t_exit, (lo[ax] - a[ax]) / dir[ax]);
    }
    float next = ceil((t_exit - 1e-3 * step - t0) / step - 0.5);
    return next > float(s + 1u) ? (next < 4.0e9 ? uint(next) : 0xffffffffu) : s + 1u;
}

void main() {
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= rc.image.x || px.y >= rc.image.y) return;
    vec2 ndc = (vec2(px) + 0.5) / vec2(rc.image.xy) * 2.0 - 1.0;
    vec4 a4 = rc.inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec4 b4 = rc.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 a = a4.xyz / a4.w;
    vec3 d = b4.xyz / b4.w - a;
    float len = length(d);
    vec3 dir = d / len;
    // Slab test against the sampled box, in index space (a sheared grid's box is a parallelepiped
    // in the world; t is the same along the ray in both).
    vec3 ia = to_index(a - rc.origin.xyz);
    vec3 idir = to_index(dir);
    float t0 = 0.0;
    float t1 = len;
    for (int ax = 0; ax < 3; ++ax) {
        if (abs(idir[ax]) < 1e-30) {
            if (ia[ax] < rc.box_min[ax] || ia[ax] > rc.box_max[ax]) t1 = -1.0;
            continue;
        }
        float p = (rc.box_min[ax] - ia[ax]) / idir[ax];
        float q = (rc.box_max[ax] - ia[ax]) / idir[ax];
        t0 = max(t0, min(p, q));
        t1 = min(t1, max(p, q));
    }
    // Clipping planes and crop box: the part of the ray inside all of them.
    for (uint i = 0u; i < rc.image.w; ++i) {
        float na = dot(rc.clip[i].xyz, a) + rc.clip[i].w, nd = dot(rc.clip[i].xyz, dir);
        if (abs(nd) < 1e-30) {
            if (na < 0.0) t1 = -1.0;
        } else if (nd > 0.0) {
            t0 = max(t0, -na / nd);
        } else {
            t1 = min(t1, -na / nd);
        }
    }
    vec3 col = vec3(0.0);
    float trans = 1.0;
    // A projection mode (rc.inv_spacing.w): the largest or summed (key, weight) of the samples,
    // which project.comp then maps; no early ray termination.
    uint mode = uint(rc.inv_spacing.w);
    vec2 acc = vec2(0.0);
    vec2 prev = vec2(0.0);  // the isosurface's last sample below it: (t, value)
    float hit = 0.0;
    if (t1 > t0) {
        float step = rc.box_min.w;
        uint n = min(uint(ceil((t1 - t0) / step)), rc.dims.w);
        ivec3 dims = ivec3(rc.dims.xyz);
        uint bs = rc.image.z;
        ivec3 nb = (dims + int(bs) - 1) / max(int(bs), 1);
        for (uint s = 0u; s < n; ++s) {
            // The last sample covers only what is left of the ray (a clip plane or a crop's face
            // cuts it there; a cast of tiles would count the rest twice).
            float seg_t = clamp(t1 - t0 - float(s) * step, 0.0, step);
            vec3 x = a + dir * (t0 + float(s) * step + 0.5 * seg_t);
            vec3 u = to_index(x - rc.origin.xyz);
            if (bs > 0u) {
                ivec3 b = clamp(ivec3(floor(u / float(bs))), ivec3(0), nb - 1);
                if (bricks[(b.z * nb.y + b.y) * nb.x + b.x] == 0u) {
                    s = skip_brick(b, nb, bs, ia, idir, t0, step, s) - 1u;
                    continue;
                }
            }
            vec4 v = trilinear(field, u, dims);
            // The isosurface (value rc.inv_shear.w): the first sample at or above it, the crossing
            // refined linearly from the sample before, shaded by its cell's trilinear gradient.
            if (mode == PROJECT_ISO) {
                float t = t0 + float(s) * step + 0.5 * seg_t;
                if (v.r < rc.inv_shear.w || hit < 0.0) {
                    // A ray that starts inside (an iso value at or below the outside's 0) meets
                    // no crossing.
                    hit = v.r < rc.inv_shear.w ? 0.0 : -1.0;
                    prev = vec2(t, v.r);
                    continue;
                }
                if (s == 0u) {
                    hit = -1.0;
                    continue;
                }
                float th = prev.x + (rc.inv_shear.w - prev.y) / (v.r - prev.y) * (t - prev.x);
                vec3 h = to_index(a + dir * th - rc.origin.xyz);
                ivec3 cell = ivec3(floor(h));
                float corner[8];
                for (int c = 0; c < 8; ++c) {
                    corner[c] = fetch_or_zero(field, cell + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1), dims).r;
                }
                vec3 g = cell_gradient(corner, h - vec3(cell));
                // World gradient: the inverse cell matrix's transpose times g.
                vec3 is = rc.inv_spacing.xyz, ih = rc.inv_shear.xyz;
                vec3 gw = vec3(is.x * g.x, ih.x * g.x + is.y * g.y, ih.y * g.x + ih.z * g.y + is.z * g.z);
                float gl = length(gw);
                acc = surface_light(gl > 0.0 ? gw / gl : -dir, dir);
                hit = 1.0;
                break;
            }
            if (v.a <= 0.0) continue;
            float seg = rc.origin.w * seg_t;  // the step in voxel lengths
            if (mode == PROJECT_MIP) {
                acc = max(acc, v.rg);
            } else if (mode == PROJECT_MINIP) {
                acc = max(acc, vec2(v.g - v.r, v.g));
            } else if (mode == PROJECT_AVERAGE) {
                acc += v.rg * seg;
            } else if (mode == PROJECT_XRAY) {
                acc.x += v.a * seg;
            }
            if (mode != PROJECT_NONE) continue;
            float alpha = 1.0 - exp(-v.a * seg);
            col += trans * alpha * (v.rgb / v.a);
            trans *= 1.0 - alpha;
            if (trans < rc.box_max.w) break;
        }
    }
    imageStore(out_image, ivec2(px), mode != PROJECT_NONE ? vec4(acc, max(hit, 0.0), 0.0) : vec4(col, 1.0 - trans));
}
