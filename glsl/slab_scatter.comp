#version 450
// variants: AXIS_SHEETS
// Image-aligned sheets, binning pass 3 of 3: each invocation walks its chunk again and writes its
// (splat, slab) pairs at its own cursors in the scanned matrix. Pairs end up grouped by slab in
// visiting order and, within a slab, in splat order: stable, so the additive blend sums in the same
// order every frame. Mirror: cpu::slab::slab_scatter.
#include "types.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 4) readonly buffer ParamsHi { SplatParams params_hi[]; };
PAGED_READER(SplatParams, params_at, params_lo, params_hi)
// A bricked batch's voxels (brick_order): i | j << 16, k | value << 16.
layout(std430, binding = 5) readonly buffer Voxels { uvec2 voxels[]; };
layout(std430, binding = 1) buffer Counts { uint counts[]; };
layout(std430, binding = 2) writeonly buffer Pairs { uint pairs[]; };
#include "slab.glsl"

void main() {
    uint chunk = linear_invocation();
    if (chunk >= pc.chunks) return;
    uint end = min((chunk + 1u) * SLAB_CHUNK, pc.n);
    for (uint s = chunk * SLAB_CHUNK; s < end; ++s) {
        uint first, last;
        if (!slab_range(s, params_at(s), first, last)) continue;
        for (uint slab = first; slab <= last; ++slab) {
            uint cell = slab_pos(slab) * pc.chunks + chunk;
            uint at = counts[cell];
            counts[cell] = at + 1u;
            pairs[2u * at] = s;
            pairs[2u * at + 1u] = slab;
        }
    }
}
