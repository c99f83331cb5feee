#version 450
// Isosurface splats, pass 1 of 4 (Mode::Iso): one lane per row of cells counts the cells the iso
// value crosses (walk_row in iso.glsl). Mirror: cpu::iso_count.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "linear.glsl"

void main() {
    uint r = linear_invocation();
    if (r >= pc.rows) return;
    counts[r] = walk_row(r, 0u, false);
}
