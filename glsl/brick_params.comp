#version 450
// variants: PAGED_RECORDS STREAMED_STORE LOD PAGED_RECORDS+LOD STREAMED_STORE+LOD
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
#ifndef LOD
    params_store(s, params_of(ijk, classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5)));
#else
    // Levels of detail (its own build: llvmpipe ran this path's loads and maths under a mask even
    // when levels of detail were off, and the frame's brick_params took 2.7x as long).
    uint level = voxel_level(v);
    uvec3 b = ijk / BRICK_SIDE;
    uint h = brick_index[b.x + bf.grid.x * (b.y + bf.grid.y * b.z)];
    // The cell's centre: the middle of its voxels inside the grid (a cell the grid's end cuts
    // would otherwise sit up to 3.5 voxels off a thin sheet).
    vec3 at = vec3(ijk) + 0.5 * (vec3(min(uvec3(1u << level), frame.dims.xyz - ijk)) - 1.0);
    float grow = brick_morph[h] > 0.0 ? splat_growth(at, level) : 1.0;
    vec4 c;
    if (level == 0u) {
        c = classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5);
        c.a = optical_depth(c.a);
    } else {
        // A coarse cell: its prefiltered colour, shaded at its gradient, and optical depth per cell.
        vec3 normal;
        c = cell_color(h, v.y >> 16u, normal);
        if (bf.light.w > 0.5) c.rgb = shade(c.rgb, normal);
    }
    params_store(s, params_at(at, float(1u << level), grow, c.rgb, c.a));
#endif
}
