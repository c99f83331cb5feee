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
PAGED_WRITER(SplatParams, params_store, params_lo, params_hi)
#include "params.glsl"

void main() {
    uint s = linear_invocation();
    if (s >= frame.dims.w) return;
    Splat sp = splats[s];
    params_store(s, params_of(sp.ijk.xyz, sp.color));
}
