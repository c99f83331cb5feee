// brick_params' and brick_quads' body: per splat of a batch, in draw order, its voxel classified
// and its splat made (brick_params.comp says how); brick_quads (SCREEN_QUADS) stores the splat's
// screen quad where brick_params stores its parameters (brick.glsl, splat_store).
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
    splat_store(s, p);
}
