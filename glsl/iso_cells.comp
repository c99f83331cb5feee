#version 450
// Isosurface splats, pass 3 of 4 (Mode::Iso): one lane per row of cells walks its cells again
// (walk_row in iso.glsl) and writes each crossed cell (its index and inside corners) at the row's
// first position + its rank, so that iso_splats' heavy part runs one lane per splat (a lane per
// row ran it for every row of a SIMD group where any one crossed). Mirror: cpu::iso_cells.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "linear.glsl"

void main() {
    uint r = linear_invocation();
    if (r >= pc.rows || counts[r + 1u] == counts[r]) return;
    walk_row(r, counts[r], true);
}
