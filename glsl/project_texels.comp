#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// A projection's texels (texels.glsl; MIP and MinIP of a store, in brick_order's place): one
// workgroup per visible brick of a batch. Its extracted voxels are written from the brick's first
// position in any order (a projection's blend is order-free: no PBTF ranks), each with the texel
// it claims, and each claim kept where it is the texel's largest so far. Every batch claims
// before any batch's project_winners reads the texels. Mirror: cpu::project_texels.
layout(local_size_x = BRICK_LANES) in;
#define PROJECT_TEXELS
#include "brick.glsl"
#include "texels.glsl"

layout(push_constant) uniform Push {
    uint first;   // the batch's first entry of brick_list
    uint count;   // its entries
    uint splats;     // its splats
    float occluded;  // brick_hidden's threshold
} pc;

shared uint written;
shared bool claims;

void main() {
    uint e = workgroup_item();
    if (e >= pc.count) return;
    uvec4 entry = brick_list[pc.first + e];
    uvec3 b = brick_coords(headers[entry.x].x);
    uint records = headers[entry.x].z;
    uint lane = gl_LocalInvocationID.x;
    if (lane == 0u) {
        written = 0u;
        claims = brick_claims(b);
    }
    barrier();
    bool claiming = claims;
    for (uint r = lane; r < records; r += BRICK_LANES) {
        uint rec = record_at(entry.z + r);
        if (!emits(rec >> 16u)) continue;
        uvec3 ijk = b * BRICK_SIDE + local_cell(rec & 511u);
        uint pos = entry.y + atomicAdd(written, 1u);
        voxels[pos] = uvec2(ijk.x | (ijk.y << 16u), ijk.z | (rec & 0xffff0000u));
        order_out[pos] = pos;
        uint t = claiming ? texel_of(ijk) : NO_TEXEL;
        uint claim = claim_of(ijk, rec >> 16u);
        voxel_texels[pos] = t;
        // Most voxels lose to one already there: read before the atomic.
        if (t != NO_TEXEL && project_texels[t] < claim) atomicMax(project_texels[t], claim);
    }
}
