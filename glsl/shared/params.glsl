// A splat's parameters from its grid index and colour: world centre, eye-facing footprint quad
// (section 1.2.5), culling and the energy scale; the single place where anti-aliasing (ch. 3) and
// motion blur (ch. 4) scale and stretch the footprint. Shared by splat_params (dense splat sets)
// and brick_params (bricked volumes); the includer declares `frame`. Mirror:
// cpu::splat_params::params_of.

#include "sweep.glsl"
#include "grid.glsl"

const float MAX_OPACITY = 0.999;
const float CULL_RADII = 1.5;

// The anti-aliasing radius scale at eye-space `depth` of a splat `cell` voxels a side (1 before
// k; Eq. 3.9 or the EWA low-pass).
float footprint_scale(float depth, float cell) {
    // Pixels per splat spacing at this depth (section 3.3.4: = k / d in perspective).
    float voxel = cell * frame.spacing.w / frame.origin.w;
    float ppv = frame.eye.w > 0.5 ? voxel * frame.up.w / max(depth, 1e-6) : voxel * frame.up.w;
    float scale = 1.0;
    if (frame.aa.x == AA_SWAN) {
        scale = max(1.0, 1.0 / ppv);                      // Eq. 3.9: radius x d/k beyond k
    } else if (frame.aa.x == AA_EWA) {
        float lp = frame.aa.z / (frame.aa.y * ppv);       // low-pass std relative to the footprint's
        scale = sqrt(1.0 + lp * lp);
    }
    return scale;
}

// MIP and MinIP draw each voxel's footprint at this share of the kernel's radius, its coverage
// full from PROJECT_FULL of its centre's weight (footprint_table.glsl): a covered pixel takes its
// voxels' largest value, and a footprint of under half the area costs less to bin and blend. Swept
// on the bonsai and the stent against the ray caster's MIP (docs/results-notes.md): 0.65 and 0.7
// gained 0.9 to 3.6 dB over the kernel's own footprint. Mirror: cpu::splat_params::PROJECT_SHRINK.
const float PROJECT_SHRINK = 0.65;

// A splat of `cell` voxels a side (a voxel, or a coarse cell of levels of detail: its kernel
// `cell` times wider) at grid position `at`, of straight colour rgb and optical depth tau per cell;
// `grow` widens it further with its energy scaled by 1 / grow^2 (levels of detail's morphing).
// (params_at, below, places it on the uniform grid; this takes its world centre.)
SplatParams params_world(vec3 center, float cell, float grow, vec3 rgb, float tau) {
    vec3 forward = frame.forward.xyz;
    float depth = dot(center - frame.eye.xyz, forward);
    // The splat's own kernel keeps CULL_RADII radii clear of the near and far planes, or it is
    // culled. Anti-aliasing's widening (a low-pass on the screen) is not: a widened cull margin
    // grew with depth and drew small frames empty. Nothing clips a widened quad at the planes
    // (footprint.vert flattens its depth); in perspective it stops short of the eye, behind which
    // a corner does not project (only frames a few pixels high reach that).
    float base = grow * cell * frame.spacing.w;
    if (frame.rect.z == PROJECT_MIP || frame.rect.z == PROJECT_MINIP) base *= PROJECT_SHRINK;
    float clear = min(depth - frame.forward.w, frame.right.w - depth);
    bool visible = clear >= CULL_RADII * base;
    float eye_room = frame.eye.w > 0.5 ? depth / (CULL_RADII * base) : 1e30;
    float scale = clamp(footprint_scale(depth, cell), 1.0, max(eye_room, 1.0));
    float radius = base * scale;
    // Clipping planes and crop box: splats whose centres lie outside any are not drawn.
    for (uint i = 0u; i < frame.rect.y; ++i) {
        visible = visible && dot(frame.clip[i].xyz, center) + frame.clip[i].w >= 0.0;
    }
    // The quad faces the eye->voxel ray (perspective) or the view direction (orthographic).
    vec3 w = frame.eye.w > 0.5 ? normalize(center - frame.eye.xyz) : forward;
    vec3 u = normalize(frame.right.xyz - dot(frame.right.xyz, w) * w);
    vec3 v = cross(w, u);
    // Chapter 4: stretch the footprint back along the projected path from t_{i-1} (Fig. 4.3), in
    // the plane facing the eye ray at t_i (Fig. 4.4), when the path exceeds delta pixels; an arc
    // path also bends through where the point was halfway (its offset across the chord).
    float stretch = 0.0;
    float bend = 0.0;
    vec3 quad_center = center;
    float energy = 1.0 / (scale * scale * grow * grow);
    if (frame.blur.x > 0.0 && visible) {
        vec3 prev = (frame.motion * vec4(center, 1.0)).xyz;
        vec4 c1 = frame.view_proj * vec4(center, 1.0);
        vec4 c0 = frame.view_proj * vec4(prev, 1.0);
        vec2 moved = (c1.xy / c1.w - c0.xy / c0.w) * 0.5 * frame.blur.zw;
        vec3 d = center - prev;
        vec3 dp = d - dot(d, w) * w;
        float len = length(dp);
        float moved_px = length(moved);
        vec3 off = vec3(0.0);
        if (frame.sweep.x > 0.5) {
            vec3 mid = (frame.motion_mid * vec4(center, 1.0)).xyz;
            vec4 cm = frame.view_proj * vec4(mid, 1.0);
            vec2 bulge = (cm.xy / cm.w - 0.5 * (c0.xy / c0.w + c1.xy / c1.w)) * 0.5 * frame.blur.zw;
            if (cm.w > 0.0) moved_px = max(moved_px, 2.0 * length(bulge));
            vec3 m = mid - 0.5 * (center + prev);
            off = m - dot(m, w) * w;
        }
        if (c0.w > 0.0 && moved_px > frame.blur.x && len > 1e-6 * radius) {
            u = dp / len;
            v = cross(w, u);
            stretch = 0.5 * len / radius;
            bend = dot(off, v) / radius;
            quad_center = center - 0.5 * dp;
            // Eq. 4.2 with effective area and width; the tapered and teardrop profiles average
            // the footprint over time, which keeps its energy.
            if (frame.sweep.y == float(SWEEP_UNIFORM)) energy /= 1.0 + sweep_length(stretch, bend) * frame.blur.y;
        }
    }
    SplatParams p;
    p.center = vec4(quad_center, visible && tau > 0.0 ? 1.0 : 0.0);
    p.axis_u = vec4(u * radius * (1.0 + stretch), energy);   // Eq. 3.13: energy x (k/d)^2
    p.axis_v = vec4(v * radius * (1.0 + abs(bend)), stretch);
    p.emit = vec4(rgb, tau);
    float pixels = frame.eye.w > 0.5 ? radius * frame.up.w / max(depth, 1e-6) : radius * frame.up.w;
    p.screen = vec4(depth, bend, pixels, scale);
    return p;
}

SplatParams params_at(vec3 at, float cell, float grow, vec3 rgb, float tau) {
    return params_world(grid_point(at), cell, grow, rgb, tau);
}

// Optical depth of one voxel-length of opacity a (clamped below 1). Mirror: volume::optical_depth.
float optical_depth(float a) {
    return -log(1.0 - clamp(a, 0.0, MAX_OPACITY));
}

// A projection's emit: the key its blend takes (types.glsl, PROJECT_*). Mirror:
// cpu::splat_params::project_emit.
vec4 project_emit(uint mode, float value, float tau) {
    float key = mode == PROJECT_MINIP ? 1.0 - value : (mode == PROJECT_XRAY ? 1.0 : value);
    return vec4(key, 0.0, 0.0, mode == PROJECT_AVERAGE ? 1.0 : tau);
}

SplatParams params_of(uvec3 ijk, vec4 color) {
    return params_at(vec3(ijk), 1.0, 1.0, color.rgb, optical_depth(color.a));
}
