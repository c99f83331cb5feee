#version 450
// variants: PAGED_RECORDS STREAMED_STORE
// Levels of detail, beside brick_params (which makes the voxels' splats and skips coarse cells): a
// lane per coarse splat of the batch (lod_splats: their positions, listed by the host), its
// parameters from its pyramid cell seen along the view (its directional prefilter: colour shaded
// at that view's normal, optical depth per cell), a splat 2^l voxels wide at the middle of its voxels inside the grid, grown toward the
// next level when its brick morphs. Mirror: cpu::lod::brick_lod_params.
layout(local_size_x = WORKGROUP_SIZE) in;
#include "brick.glsl"
#include "linear.glsl"

layout(push_constant) uniform Push {
    uint first;      // unused
    uint count;      // unused
    uint splats;     // the batch's coarse splats
    float occluded;  // unused
} pc;

void main() {
    uint i = linear_invocation();
    if (i >= pc.splats) return;
    uint s = lod_splats[i];
    uvec2 v = voxels[s];
    uvec3 ijk = voxel_ijk(v);
    uint level = voxel_level(v);
    // The middle of its voxels inside the grid (a cell the grid's end cuts would otherwise sit up
    // to 3.5 voxels off a thin sheet).
    vec3 at = vec3(ijk) + 0.5 * (vec3(min(uvec3(1u << level), frame.dims.xyz - ijk)) - 1.0);
    float grow = (v.y & VOXEL_MORPHS) != 0u ? splat_growth(at, level) : 1.0;
    vec3 normal;
    vec3 centre = grid_point(at);
    vec3 view = grid_direction(frame.eye.w > 0.5 ? centre - frame.eye.xyz : frame.forward.xyz);
    // A node above the brick (level > 3) from its words after the summaries.
    vec4 c = level > 3u ? node_color(level - 3u, ijk >> level, view, normal)
                        : cell_color(header_of(ijk), v.y >> 16u, view, normal);
    if (bf.light.w > 0.5) c.rgb = shade(c.rgb, normal);
    params_store(s, params_at(at, float(1u << level), grow, c.rgb, c.a));
}
