#version 450
// Isosurface splats, pass 1 of 4 (Mode::Iso): one lane per row of cells counts the cells the iso
// value crosses (some corner inside, some outside), sliding a face of four values along x; rows
// whose voxel rows' ranges cannot hold the value are skipped whole. Mirror: cpu::iso_count.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "iso.glsl"
#include "linear.glsl"

void main() {
    uint r = linear_invocation();
    if (r >= pc.rows) return;
    ivec2 jk = cell_row(r);
    uint n = 0u;
    if (row_crosses(jk)) {
        uvec4 f0 = uvec4(0u);
        for (int i = -1; i < int(frame.dims.x); ++i) {
            uvec4 f1 = iso_face(i + 1, jk);
            uint m = inside_bits(f0, f1);
            if (m != 0u && m != 255u) n++;
            f0 = f1;
        }
    }
    counts[r] = n;
}
