// Shared by the slab binning stages (slab_count, slab_scan, slab_scatter): push constants and the
// slab range of a splat. Mirror: src/cpu/slab.rs.
layout(push_constant) uniform SlabPush {
    float z0;       // eye-space depth of slab 0's near face
    float dz;       // slab thickness (world units)
    uint slabs;     // slab count
    uint chunks;    // splat chunks of SLAB_CHUNK (columns of the count matrix)
    uint ftb;       // 1: slabs visited near to far, 0: far to near
    uint n;         // splat count
    uint axis;      // AXIS_SHEETS: the sheet axis
    uint pad1;
} pc;

// Visiting position of a slab.
uint slab_pos(uint slab) {
    return pc.ftb != 0u ? slab : pc.slabs - 1u - slab;
}

uint slab_of(float z) {
    return uint(clamp(floor((z - pc.z0) / pc.dz), 0.0, float(pc.slabs - 1u)));
}

// First and last slab the splat's kernel overlaps (a hair wide, so no slice is ever dropped);
// false for a culled splat. AXIS_SHEETS builds (a bricked volume's axis-aligned sheets): the
// splat's voxel plane along pc.axis, read from the batch's voxels (brick_order).
bool slab_range(uint s, SplatParams p, out uint first, out uint last) {
    if (p.center.w == 0.0) return false;
#ifdef AXIS_SHEETS
    first = voxel_ijk(voxels[s])[pc.axis];
    last = first;
#else
    // The kernel's depth extent: anti-aliasing widens it on the screen only (p.screen.w).
    float r = length(p.axis_v.xyz) / p.screen.w * 1.0001;
    first = slab_of(p.screen.x - r);
    last = slab_of(p.screen.x + r);
#endif
    return true;
}
