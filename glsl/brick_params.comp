#version 450
// variants: PAGED_RECORDS STREAMED_STORE GRADIENTS PROJECT_VOXELS
// Bricks, pass 3 (issue 23): per splat of a batch, in draw order, classify its voxel on the device
// (TF table, gradient weighting, headlight shading; gradients read through the store, or in the
// GRADIENTS build from each voxel's precomputed differences) and make its
// splat parameters (params.glsl, as splat_params does for a dense set; a projection's key from its
// density, project_emit); a voxel of a morphing brick
// grows toward its next level (levels of detail). Coarse cells are brick_lod_params': a branch to
// them here would cost every voxel, since llvmpipe runs a branch's code under a mask even where no
// lane takes it. Mirror: cpu::brick::brick_params.
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
#ifdef PROJECT_VOXELS
    // A projection with texels: the batch's voxels that draw (project_winners).
    uvec2 v = project_voxels[s];
#else
    uvec2 v = voxels[s];
#endif
    if (voxel_level(v) != 0u) return;
    uvec3 ijk = voxel_ijk(v);
    vec4 c = classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5);
    float grow = (v.y & VOXEL_MORPHS) != 0u ? splat_growth(vec3(ijk), 0u) : 1.0;
    SplatParams p = params_at(vec3(ijk), 1.0, grow, c.rgb, optical_depth(c.a));
    // A projection (no levels of detail there): the voxel's normalised density as its key.
    if (frame.rect.z != PROJECT_NONE) {
        float d = clamp(float(v.y >> 16u) / Q_MAX * bf.tf.x + bf.tf.y, 0.0, 1.0);
        p.emit = project_emit(frame.rect.z, d, p.emit.a);
    }
    params_store(s, p);
}
