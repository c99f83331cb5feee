#version 450
// Image-aligned sheets, binning pass 2 of 3: exclusive prefix sum of the count matrix in place
// (visiting position major, chunk minor) by one workgroup, then each slab's first pair and the
// total into slab_start (slabs + 1 entries). Mirror: cpu::slab::slab_scan.
#include "types.glsl"

layout(local_size_x = SCAN_WORKGROUP_SIZE) in;
layout(std430, binding = 0) readonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 4) readonly buffer ParamsHi { SplatParams params_hi[]; };
layout(std430, binding = 1) buffer Counts { uint counts[]; };
layout(std430, binding = 3) writeonly buffer SlabStart { uint slab_start[]; };
#include "slab.glsl"

#include "count_scan.glsl"

void main() {
    uint total = scan_counts(pc.slabs * pc.chunks);
    for (uint pos = gl_LocalInvocationID.x; pos < pc.slabs; pos += SCAN_WORKGROUP_SIZE) {
        slab_start[pos] = counts[pos * pc.chunks];
    }
    if (gl_LocalInvocationID.x == 0u) slab_start[pc.slabs] = total;
}
