// Segment arithmetic of the PBTF order (Swan 1997, section 2.3), shared by order_count and
// order_scatter. Mirror: src/cpu/order.rs (segment_position).
//
// Rows run along i. The eye splits every axis into a low side (indices < split) and a high side;
// each row (j, k) is cut into its low-i and high-i segment. Front to back, octants follow one another
// (o = si + 2 sj + 4 sk) and inside an octant rows are visited outward from the eye, k outer, j inner.
uint side_count(uint n, uint split, uint side) {
    return side == 0u ? split : n - split;
}

uint outward(uint idx, uint split, uint side) {
    return side == 0u ? split - 1u - idx : idx - split;
}

uint segment_position(uint j, uint k, uint si, uvec3 dims, uvec3 split) {
    uint sj = j < split.y ? 0u : 1u;
    uint sk = k < split.z ? 0u : 1u;
    uint octant = si + 2u * sj + 4u * sk;
    uint base = 0u;
    for (uint o = 0u; o < octant; ++o) {
        base += side_count(dims.y, split.y, (o >> 1u) & 1u) * side_count(dims.z, split.z, (o >> 2u) & 1u);
    }
    uint nj = side_count(dims.y, split.y, sj);
    return base + outward(k, split.z, sk) * nj + outward(j, split.y, sj);
}
