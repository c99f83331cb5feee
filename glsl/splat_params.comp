#version 450
// Per-splat parameters of a dense splat set (glsl/shared/params.glsl: footprint quad, culling,
// anti-aliasing and motion blur). Mirror: cpu::splat_params.
#include "types.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 2) writeonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 3) writeonly buffer ParamsHi { SplatParams params_hi[]; };
// A rectilinear grid's voxel positions: nx x, then ny y, then nz z coordinates (frame.rect.x = 1).
layout(std430, binding = 4) readonly buffer Coords { float coords[]; };
PAGED_WRITER(SplatParams, params_store, params_lo, params_hi)
#include "params.glsl"

// A voxel's extent along axis a of the rectilinear grid: half the span between its neighbours
// (the one gap at either end).
float cell_extent(uint a, uint i) {
    uint base = a == 0u ? 0u : (a == 1u ? frame.dims.x : frame.dims.x + frame.dims.y);
    uint n = frame.dims[a];
    if (n == 1u) return frame.spacing[a];
    float lo = coords[base + (i == 0u ? 0u : i - 1u)], hi = coords[base + min(i + 1u, n - 1u)];
    return (i == 0u || i == n - 1u) ? hi - lo : 0.5 * (hi - lo);
}

// A rectilinear grid's splat: at its coordinates, sized for the widest gap (frame.spacing.w),
// its optical depth weighted by its cell's volume over the widest gap's cube, so a ray crossing
// denser cells meets as much material as one crossing the widest (mirror:
// cpu::splat_params::params_rect).
SplatParams params_rect(uvec3 ijk, vec4 color) {
    vec3 center = vec3(coords[ijk.x], coords[frame.dims.x + ijk.y], coords[frame.dims.x + frame.dims.y + ijk.z]);
    float ks = frame.spacing.w / frame.origin.w;
    float weight = cell_extent(0u, ijk.x) / ks * (cell_extent(1u, ijk.y) / ks) * (cell_extent(2u, ijk.z) / ks);
    return params_world(center, 1.0, 1.0, color.rgb, optical_depth(color.a) * weight);
}

void main() {
    uint s = linear_invocation();
    if (s >= frame.dims.w) return;
    Splat sp = splats[s];
    SplatParams p = frame.rect.x != 0u ? params_rect(sp.ijk.xyz, sp.color) : params_of(sp.ijk.xyz, sp.color);
    if (frame.rect.z != PROJECT_NONE) p.emit = project_emit(frame.rect.z, uintBitsToFloat(sp.ijk.w), p.emit.a);
    params_store(s, p);
}
