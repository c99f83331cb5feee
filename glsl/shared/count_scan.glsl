// Exclusive prefix sum, in place and by one workgroup of SCAN_WORKGROUP_SIZE, of the first `count`
// cells of the includer's SCAN_BUFFER (default `counts`); returns the total. Shared by slab_scan and
// tile_offsets.
#ifndef SCAN_BUFFER
#define SCAN_BUFFER counts
#endif
shared uint partial[SCAN_WORKGROUP_SIZE];

uint scan_counts(uint count) {
    uint t = gl_LocalInvocationID.x;
    uint carry = 0u;
    for (uint base = 0u; base < count; base += SCAN_WORKGROUP_SIZE) {
        uint idx = base + t;
        uint v = idx < count ? SCAN_BUFFER[idx] : 0u;
        partial[t] = v;
        barrier();
        for (uint off = 1u; off < SCAN_WORKGROUP_SIZE; off <<= 1u) {
            uint add = t >= off ? partial[t - off] : 0u;
            barrier();
            partial[t] += add;
            barrier();
        }
        if (idx < count) SCAN_BUFFER[idx] = carry + partial[t] - v;
        carry += partial[SCAN_WORKGROUP_SIZE - 1u];
        barrier();
    }
    memoryBarrierBuffer();
    barrier();
    return carry;
}
