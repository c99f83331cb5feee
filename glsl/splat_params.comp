#version 450
// Per-splat parameters: world centre, eye-facing footprint quad (section 1.2.5), culling, and the
// energy scale. The single place where anti-aliasing (ch. 3) and motion blur (ch. 4) will scale and
// stretch the footprint. Mirror: cpu::splat_params.
#include "types.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std140, binding = 0) uniform FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 2) writeonly buffer Params { SplatParams params[]; };

const float MAX_OPACITY = 0.999;
const float CULL_RADII = 1.5;

void main() {
    uint s = linear_invocation();
    if (s >= frame.dims.w) return;
    Splat sp = splats[s];
    vec3 center = frame.origin.xyz + vec3(sp.ijk.xyz) * frame.spacing.xyz;
    vec3 forward = frame.forward.xyz;
    float depth = dot(center - frame.eye.xyz, forward);
    // Pixels per voxel spacing at this splat's depth (section 3.3.4: = k / d in perspective).
    float voxel = frame.spacing.w / frame.origin.w;
    float ppv = frame.eye.w > 0.5 ? voxel * frame.up.w / max(depth, 1e-6) : voxel * frame.up.w;
    float scale = 1.0;
    if (frame.aa.x == AA_SWAN) {
        scale = max(1.0, 1.0 / ppv);                      // Eq. 3.9: radius x d/k beyond k
    } else if (frame.aa.x == AA_EWA) {
        float lp = frame.aa.z / (frame.aa.y * ppv);       // low-pass std relative to the footprint's
        scale = sqrt(1.0 + lp * lp);
    }
    float radius = frame.spacing.w * scale;
    bool visible = depth >= frame.forward.w + CULL_RADII * radius && depth <= frame.right.w - CULL_RADII * radius;
    // The quad faces the eye->voxel ray (perspective) or the view direction (orthographic).
    vec3 w = frame.eye.w > 0.5 ? normalize(center - frame.eye.xyz) : forward;
    vec3 u = normalize(frame.right.xyz - dot(frame.right.xyz, w) * w);
    vec3 v = cross(w, u);
    float opacity = clamp(sp.color.a, 0.0, MAX_OPACITY);
    float tau = -log(1.0 - opacity);
    SplatParams p;
    p.center = vec4(center, visible && tau > 0.0 ? 1.0 : 0.0);
    p.axis_u = vec4(u * radius, 1.0 / (scale * scale));   // Eq. 3.13: energy x (k/d)^2
    p.axis_v = vec4(v * radius, 0.0);
    p.emit = vec4(sp.color.rgb, tau);
    float dist = length(center - frame.eye.xyz);
    float pixels = frame.eye.w > 0.5 ? radius * frame.up.w / max(depth, 1e-6) : radius * frame.up.w;
    p.screen = vec4(depth, dist, pixels, scale);
    params[s] = p;
}
