// The isosurface stages' bindings and cells (issue 46), shared by iso_count, iso_scan and
// iso_splats: the scene's values as 16-bit pairs (iso::IsoField), each voxel row's range, and per
// row of cells its surface splats (counted, then scanned in place into first positions). A cell
// (i, j, k) spans voxels i..=i+1, j..=j+1, k..=k+1 from -1 (voxels outside the grid hold 0, as in
// the ray caster's field); its corner c is (c & 1, c >> 1 & 1, c >> 2). Mirror: cpu::iso_count.
#include "types.glsl"

layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer IsoField { uint field[]; };
// Per voxel row, per segment of ISO_SEGMENT voxels along x, its largest value.
layout(std430, binding = 2) readonly buffer IsoRows { uint row_range[]; };
layout(std430, binding = 3) buffer IsoCounts { uint counts[]; };
// Per surface splat its cell: i + 1 | (j + 1) << 16, k + 1 | inside bits << 16 (iso_cells).
layout(std430, binding = 7) buffer IsoCells { uvec2 cells[]; };
layout(push_constant) uniform Push {
    float iso;        // normalised
    uint threshold;   // a corner is inside when its quantised value is at least this
    uint rows;        // rows of cells, (ny + 1)(nz + 1)
    float band;       // the depth band the nearest surface's discs blend over (world units)
    uint splats;      // the frame's surface splats (iso_splats' lanes)
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

const float ISO_Q = 65535.0;

// The quantised value at voxel v, 0 outside the grid.
uint iso_value(ivec3 v) {
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(frame.dims.xyz)))) return 0u;
    uint i = uint(v.x) + frame.dims.x * (uint(v.y) + frame.dims.y * uint(v.z));
    return (field[i >> 1u] >> (16u * (i & 1u))) & 0xffffu;
}

// Row r of cells: its (j, k).
ivec2 cell_row(uint r) {
    return ivec2(int(r % (frame.dims.y + 1u)) - 1, int(r / (frame.dims.y + 1u)) - 1);
}

// Segments of a voxel row (ISO_SEGMENT voxels each) and blocks of a row of cells (ISO_SEGMENT
// cells each: block b holds the cells whose upper x voxel is b ISO_SEGMENT + 0 .. 31).
uint iso_segments() {
    return (frame.dims.x + ISO_SEGMENT - 1u) / ISO_SEGMENT;
}

// The largest value of segment s of voxel row (j, k); 0 outside the grid.
uint segment_max(int j, int k, int s) {
    if (j < 0 || k < 0 || s < 0 || j >= int(frame.dims.y) || k >= int(frame.dims.z) || s >= int(iso_segments())) {
        return 0u;
    }
    return row_range[(uint(j) + frame.dims.y * uint(k)) * iso_segments() + uint(s)];
}

// Whether block b of row jk's cells can hold the surface: a voxel of it lies inside (its voxels
// are those of segments b - 1, for its first cell's lower voxel, and b, of its four voxel rows);
// at threshold 0 every voxel is inside (the 0 outside the grid too) and nothing is crossed.
bool block_crosses(ivec2 jk, int b) {
    uint hi = 0u;
    for (int c = 0; c < 4; ++c) {
        ivec2 v = jk + ivec2(c & 1, c >> 1);
        hi = max(hi, max(segment_max(v.x, v.y, b - 1), segment_max(v.x, v.y, b)));
    }
    return pc.threshold > 0u && hi >= pc.threshold;
}

// The four values of the face x = i of row jk's cells (corner order: dy + 2 dz).
uvec4 iso_face(int i, ivec2 jk) {
    return uvec4(iso_value(ivec3(i, jk.x, jk.y)), iso_value(ivec3(i, jk.x + 1, jk.y)),
                 iso_value(ivec3(i, jk.x, jk.y + 1)), iso_value(ivec3(i, jk.x + 1, jk.y + 1)));
}

// The inside bits of a cell's eight corners from its faces x = i (f0) and x = i + 1 (f1).
uint inside_bits(uvec4 f0, uvec4 f1) {
    uint m = 0u;
    for (uint c = 0u; c < 4u; ++c) {
        uint dy = c & 1u, dz = c >> 1u;
        if (f0[c] >= pc.threshold) m |= 1u << (2u * dy + 4u * dz);
        if (f1[c] >= pc.threshold) m |= 1u << (1u + 2u * dy + 4u * dz);
    }
    return m;
}

// Walk row r's cells, sliding a face of four values along x; blocks of ISO_SEGMENT cells whose
// voxels all lie outside are skipped whole (they cross nothing and leave their last face
// outside). Returns the crossed cells (some corner inside, some outside); with `list`, each is
// written (c = i + 1 | (j + 1) << 16, k + 1 | inside bits << 16) from `first` on. iso_count and
// iso_cells walk alike, so their counts and lists agree. Mirror: IsoInputs::crossed.
uint walk_row(uint r, uint first, bool list) {
    ivec2 jk = cell_row(r);
    uint n = 0u;
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
                if (list) cells[first + n] = uvec2(uint(c) | (uint(jk.x + 1) << 16u), uint(jk.y + 1) | (m << 16u));
                n++;
            }
            f0 = f1;
        }
    }
    return n;
}
