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

// A rectilinear grid's splat: at its coordinates, as wide as its own cell's widest extent (the
// mean of its neighbouring gaps; at most the widest gap, frame.spacing.w, which bounds every
// footprint), its optical depth weighted so that it deposits its cell's volume over the length
// opacities are per (frame.shear.w): a ray crossing denser cells meets as much material as one
// crossing wider ones, and one far slice widens only its neighbours (mirror:
// cpu::splat_params::params_rect).
SplatParams params_rect(uvec3 ijk, vec4 color) {
    vec3 center = vec3(coords[ijk.x], coords[frame.dims.x + ijk.y], coords[frame.dims.x + frame.dims.y + ijk.z]);
    float ks = frame.spacing.w / frame.origin.w;
    vec3 e = vec3(cell_extent(0u, ijk.x), cell_extent(1u, ijk.y), cell_extent(2u, ijk.z));
    float cell = min(max(e.x, max(e.y, e.z)) / ks, 1.0);
    float r = cell * ks;
    float weight = e.x * e.y * e.z / (frame.shear.w * r * r);
    return params_world(center, cell, 1.0, color.rgb, optical_depth(color.a) * weight);
}

void main() {
    uint s = linear_invocation();
    if (s >= frame.dims.w) return;
    Splat sp = splats[s];
    SplatParams p = frame.rect.x != 0u ? params_rect(sp.ijk.xyz, sp.color) : params_of(sp.ijk.xyz, sp.color);
    if (frame.rect.z != PROJECT_NONE) p.emit = project_emit(frame.rect.z, uintBitsToFloat(sp.ijk.w), p.emit.a);
    params_store(s, p);
}
