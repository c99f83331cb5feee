#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Bricks, pass 3 (issue 23): per splat of a batch, in draw order, classify its voxel on the device
// (TF table, gradient weighting, headlight shading; gradients read through the store) and make its
// splat parameters (params.glsl, as splat_params does for a dense set), each at full size; with
// levels of detail, brick_lod_params then makes coarse cells' and morphing voxels'. Mirror:
// cpu::brick::brick_params.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

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
    uvec3 ijk = voxel_ijk(v);
    // Coarse cells are brick_lod_params' (levels of detail).
    if (voxel_level(v) != 0u) return;
    params_store(s, params_of(ijk, classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5)));
}
