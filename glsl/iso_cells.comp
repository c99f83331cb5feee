#version 450
// Isosurface splats, pass 3 of 4 (Mode::Iso): one lane per row of cells walks its cells again and
// writes each crossed cell (its index and inside corners) at the row's first position + its rank,
// so that iso_splats' heavy part runs one lane per splat (a lane per row ran it for every row of a
// SIMD group where any one crossed). Mirror: cpu::iso_cells.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "linear.glsl"

void main() {
    uint r = linear_invocation();
    if (r >= pc.rows) return;
    uint pos = counts[r];
    if (counts[r + 1u] == pos) return;
    ivec2 jk = cell_row(r);
    uvec4 f0 = uvec4(0u);
    int cells_x = int(frame.dims.x) + 1;
    for (int b = 0; b * int(ISO_SEGMENT) < cells_x; ++b) {
        if (!block_crosses(jk, b)) {
            f0 = uvec4(0u);
            continue;
        }
        // Cell c's voxels are c - 1 and c along x.
        for (int c = b * int(ISO_SEGMENT); c < min(cells_x, (b + 1) * int(ISO_SEGMENT)); ++c) {
            uvec4 f1 = iso_face(c, jk);
            uint m = inside_bits(f0, f1);
            if (m != 0u && m != 255u) {
                cells[pos] = uvec2(uint(c) | (uint(jk.x + 1) << 16u), uint(jk.y + 1) | (m << 16u));
                pos++;
            }
            f0 = f1;
        }
    }
}
