#version 450
// PBTF order, pass 3 of 3: every splat writes its own index at segment offset + rank within the
// segment (outward from the eye). Back-to-front is the reversed sequence. Mirror: cpu::order_scatter.
#include "types.glsl"
#include "pbtf.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 2) readonly buffer RowStart { uint row_start[]; };
layout(std430, binding = 3) readonly buffer RowSplit { uint row_split[]; };
layout(std430, binding = 4) readonly buffer Segments { uint segments[]; };
layout(std430, binding = 5) writeonly buffer Order { uint order_out[]; };

void main() {
    uint s = linear_invocation();
    uint n = frame.dims.w;
    if (s >= n) return;
    uvec3 dims = frame.dims.xyz;
    uvec3 ijk = splats[s].ijk.xyz;
    uint row = ijk.y + dims.y * ijk.z;
    uint local_idx = s - row_start[row];
    uint low = row_split[row];
    uint si = local_idx < low ? 0u : 1u;
    uint rank = si == 0u ? low - 1u - local_idx : local_idx - low;
    uint pos = segments[segment_position(ijk.y, ijk.z, si, dims, frame.split.xyz)] + rank;
    if (frame.split.w != 0u) pos = n - 1u - pos;
    order_out[pos] = s;
}
