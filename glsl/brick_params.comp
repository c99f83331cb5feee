#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Bricks, pass 3 (issue 23): per splat of a batch, in draw order, classify its voxel on the device
// (TF table, gradient weighting, headlight shading; gradients read through the store) and make its
// splat parameters (params.glsl, as splat_params does for a dense set); a coarse cell of levels of
// detail reads its pyramid cell (brick_pyramid). Mirror:
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
    uint level = voxel_level(v);
    if (bf.grad.y <= 0.0) {
        params_store(s, params_of(ijk, classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5)));
        return;
    }
    uvec3 b = ijk / BRICK_SIDE;
    uint h = brick_index[b.x + bf.grid.x * (b.y + bf.grid.y * b.z)];
    vec3 at = vec3(ijk) + 0.5 * (float(1u << level) - 1.0);
    float grow = brick_morph[h] > 0.0 ? splat_growth(at, level) : 1.0;
    if (level == 0u) {
        vec4 c = classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5);
        float opacity = clamp(c.a, 0.0, MAX_OPACITY);
        params_store(s, params_at(at, 1.0, grow, c.rgb, -log(1.0 - opacity)));
        return;
    }
    // A coarse cell: its prefiltered colour, shaded at its gradient, and optical depth per cell.
    vec3 normal;
    vec4 c = cell_color(h, v.y >> 16u, normal);
    if (bf.light.w > 0.5) c.rgb = shade(c.rgb, normal);
    params_store(s, params_at(at, float(1u << level), grow, c.rgb, c.a));
}
