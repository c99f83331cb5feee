#version 450
// Isosurface splats, pass 1 of 4 (Mode::Iso): one lane per row of cells counts the cells the iso
// value crosses (some corner inside, some outside), sliding a face of four values along x; blocks of
// ISO_SEGMENT cells whose voxels all lie outside are skipped whole. Mirror: cpu::iso_count.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "linear.glsl"

void main() {
    uint r = linear_invocation();
    if (r >= pc.rows) return;
    ivec2 jk = cell_row(r);
    uint n = 0u;
    uvec4 f0 = uvec4(0u);
    int cells = int(frame.dims.x) + 1;
    for (int b = 0; b * int(ISO_SEGMENT) < cells; ++b) {
        // A block with no voxel inside crosses nothing, and leaves its last face outside.
        if (!block_crosses(jk, b)) {
            f0 = uvec4(0u);
            continue;
        }
        for (int c = b * int(ISO_SEGMENT); c < min(cells, (b + 1) * int(ISO_SEGMENT)); ++c) {
            uvec4 f1 = iso_face(c, jk);
            uint m = inside_bits(f0, f1);
            if (m != 0u && m != 255u) n++;
            f0 = f1;
        }
    }
    counts[r] = n;
}
