// Exclusive prefix sum, in place and by one workgroup of SCAN_WORKGROUP_SIZE, of the first `count`
// cells of the includer's `counts` buffer; returns the total. Shared by slab_scan and tile_scan.
shared uint partial[SCAN_WORKGROUP_SIZE];

uint scan_counts(uint count) {
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
    return carry;
}
