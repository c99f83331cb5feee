#version 450
// variants: AXIS_SHEETS
// Image-aligned sheets, binning pass 1 of 3: each invocation owns a chunk of SLAB_CHUNK splats and
// counts, serially and without atomics, how many of them each slab receives (its column of the
// slab x chunk count matrix, rows in visiting order). Mirror: cpu::slab::slab_count.
#include "types.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 4) readonly buffer ParamsHi { SplatParams params_hi[]; };
PAGED_READER(SplatParams, params_at, params_lo, params_hi)
// A bricked batch's voxels (brick_order): i | j << 16, k | value << 16.
layout(std430, binding = 5) readonly buffer Voxels { uvec2 voxels[]; };
layout(std430, binding = 1) buffer Counts { uint counts[]; };
#include "slab.glsl"

void main() {
    uint chunk = linear_invocation();
    if (chunk >= pc.chunks) return;
    for (uint pos = 0u; pos < pc.slabs; ++pos) counts[pos * pc.chunks + chunk] = 0u;
    uint end = min((chunk + 1u) * SLAB_CHUNK, pc.n);
    for (uint s = chunk * SLAB_CHUNK; s < end; ++s) {
        uint first, last;
        if (!slab_range(s, params_at(s), first, last)) continue;
        for (uint slab = first; slab <= last; ++slab) counts[slab_pos(slab) * pc.chunks + chunk] += 1u;
    }
}
