#version 450
// Isosurface splats, pass 2 of 4: each row's first splat, by an exclusive scan of the counts in
// place, and the total after them (read back: the frame's splats). Mirror: cpu::iso_scan.
layout(local_size_x = SCAN_WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "count_scan.glsl"

void main() {
    uint total = scan_counts(pc.rows);
    if (gl_LocalInvocationID.x == 0u) counts[pc.rows] = total;
}
