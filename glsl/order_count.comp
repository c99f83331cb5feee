#version 450
// PBTF order, pass 1 of 3: per row, count the voxels on each side of the eye's i-split and store
// both counts at their segment's position in the front-to-back sequence. Mirror: cpu::order_count.
#include "types.glsl"
#include "pbtf.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 2) readonly buffer RowStart { uint row_start[]; };
layout(std430, binding = 3) buffer RowSplit { uint row_split[]; };
layout(std430, binding = 4) buffer Segments { uint segments[]; };

void main() {
    uint row = linear_invocation();
    uvec3 dims = frame.dims.xyz;
    if (row >= dims.y * dims.z) return;
    uint start = row_start[row];
    uint end = row_start[row + 1u];
    // Rows are sorted by i: binary search for the first voxel on the high side.
    uint lo = start;
    uint hi = end;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (splats[mid].ijk.x < frame.split.x) lo = mid + 1u; else hi = mid;
    }
    uint low = lo - start;
    row_split[row] = low;
    uint j = row % dims.y;
    uint k = row / dims.y;
    segments[segment_position(j, k, 0u, dims, frame.split.xyz)] = low;
    segments[segment_position(j, k, 1u, dims, frame.split.xyz)] = (end - start) - low;
}
