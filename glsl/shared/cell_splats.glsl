// brick_lod_params' and brick_lod_quads' body: per coarse splat of a batch its pyramid cell's
// splat (brick_lod_params.comp says how); brick_lod_quads (SCREEN_QUADS) stores the splat's
// screen quad where brick_lod_params stores its parameters (brick.glsl, splat_store).
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
    splat_store(s, params_at(at, float(1u << level), grow, c.rgb, c.a));
}
