#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Levels of detail, after brick_params (which made every voxel's splat at full size and skipped
// coarse cells): a workgroup per entry of the batch whose brick is coarse or morphs, its lanes over
// the brick's splats (contiguous from the entry's first position): a coarse cell from its pyramid
// cell (colour shaded at its gradient, optical depth per cell), a voxel grown toward the next
// level (splat_growth). Its own pass because llvmpipe runs a branch's code under a mask even where
// no lane takes it: in brick_params, this path cost every voxel of every frame (brick_params took
// twice as long with levels of detail on where none was coarse). Mirror:
// cpu::lod::brick_lod_params.
layout(local_size_x = BRICK_LANES) in;
#include "brick.glsl"

layout(push_constant) uniform Push {
    uint first;      // the batch's first entry of brick_list
    uint count;      // its entries
    uint splats;     // its splats
    float occluded;  // brick_hidden's threshold
} pc;

void main() {
    uint e = workgroup_item();
    if (e >= pc.count) return;
    uvec4 entry = brick_list[pc.first + e];
    uint h = entry.x;
    uint level = entry.w >> 16u;
    bool morphs = brick_morph[h] > 0.0;
    if (level == 0u && !morphs) return;
    for (uint r = gl_LocalInvocationID.x; r < (entry.w & 0xffffu); r += BRICK_LANES) {
        uint s = entry.y + r;
        uvec2 v = voxels[s];
        uvec3 ijk = voxel_ijk(v);
        // The cell's centre: the middle of its voxels inside the grid (a cell the grid's end cuts
        // would otherwise sit up to 3.5 voxels off a thin sheet).
        vec3 at = vec3(ijk) + 0.5 * (vec3(min(uvec3(1u << level), frame.dims.xyz - ijk)) - 1.0);
        float grow = morphs ? splat_growth(at, level) : 1.0;
        vec4 c;
        if (level == 0u) {
            c = classify_voxel(ivec3(ijk), v.y >> 16u, bf.light.w > 0.5);
            c.a = optical_depth(c.a);
        } else {
            vec3 normal;
            c = cell_color(h, v.y >> 16u, normal);
            if (bf.light.w > 0.5) c.rgb = shade(c.rgb, normal);
        }
        params_store(s, params_at(at, float(1u << level), grow, c.rgb, c.a));
    }
}
