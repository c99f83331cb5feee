#version 450
// Image-aligned sheets, binning pass 2 of 3: exclusive prefix sum of the count matrix in place
// (visiting position major, chunk minor) by one workgroup, then each slab's first pair and the
// total into slab_start (slabs + 1 entries). Mirror: cpu::slab::slab_scan.
#include "types.glsl"

layout(local_size_x = SCAN_WORKGROUP_SIZE) in;
layout(std430, binding = 0) readonly buffer Params { SplatParams params[]; };
layout(std430, binding = 1) buffer Counts { uint counts[]; };
layout(std430, binding = 3) writeonly buffer SlabStart { uint slab_start[]; };
#include "slab.glsl"

shared uint partial[SCAN_WORKGROUP_SIZE];

void main() {
    uint count = pc.slabs * pc.chunks;
    uint t = gl_LocalInvocationID.x;
    uint carry = 0u;
    for (uint base = 0u; base < count; base += SCAN_WORKGROUP_SIZE) {
        uint idx = base + t;
        uint v = idx < count ? counts[idx] : 0u;
        partial[t] = v;
        barrier();
        for (uint off = 1u; off < SCAN_WORKGROUP_SIZE; off <<= 1u) {
            uint add = t >= off ? partial[t - off] : 0u;
            barrier();
            partial[t] += add;
            barrier();
        }
        if (idx < count) counts[idx] = carry + partial[t] - v;
        carry += partial[SCAN_WORKGROUP_SIZE - 1u];
        barrier();
    }
    memoryBarrierBuffer();
    barrier();
    for (uint pos = t; pos < pc.slabs; pos += SCAN_WORKGROUP_SIZE) slab_start[pos] = counts[pos * pc.chunks];
    if (t == 0u) slab_start[pc.slabs] = carry;
}
