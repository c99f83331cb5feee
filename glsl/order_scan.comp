#version 450
// PBTF order, pass 2 of 3: exclusive prefix sum of the segment sizes, in place, by one workgroup
// walking the array in chunks. Linear work; no comparison sort. Mirror: cpu::order_scan.
#include "types.glsl"

layout(local_size_x = SCAN_WORKGROUP_SIZE) in;
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 4) buffer Segments { uint segments[]; };

shared uint partial[SCAN_WORKGROUP_SIZE];

void main() {
    uint count = 2u * frame.dims.y * frame.dims.z;
    uint t = gl_LocalInvocationID.x;
    uint carry = 0u;
    for (uint base = 0u; base < count; base += SCAN_WORKGROUP_SIZE) {
        uint idx = base + t;
        uint v = idx < count ? segments[idx] : 0u;
        partial[t] = v;
        barrier();
        // Hillis-Steele inclusive scan over the chunk.
        for (uint off = 1u; off < SCAN_WORKGROUP_SIZE; off <<= 1u) {
            uint add = t >= off ? partial[t - off] : 0u;
            barrier();
            partial[t] += add;
            barrier();
        }
        if (idx < count) segments[idx] = carry + partial[t] - v;
        carry += partial[SCAN_WORKGROUP_SIZE - 1u];
        barrier();
    }
}
