#version 450
// A projection's texels (texels.glsl), per voxel of a batch after every batch claimed: the voxels
// that draw (each texel's winner, and those that claim no texel), packed for brick_params in any
// order (a projection's blend is order-free), their count in word 0. Mirror: cpu::project_winners.
layout(local_size_x = WORKGROUP_SIZE) in;
#define PROJECT_TEXELS
#define PROJECT_WINNERS
#include "brick.glsl"
#include "linear.glsl"
#include "texels.glsl"

layout(push_constant) uniform Push {
    uint first;   // the batch's first entry of brick_list
    uint count;   // its entries
    uint splats;     // its splats
    float occluded;  // brick_hidden's threshold
} pc;

void main() {
    uint s = linear_invocation();
    if (s >= pc.splats) return;
    uvec2 v = voxels[s];
    uint t = voxel_texels[s];
    if (t == NO_TEXEL || project_texels[t] == claim_of(voxel_ijk(v), v.y >> 16u)) {
        project_out[atomicAdd(project_texels[0], 1u)] = v;
    }
}
