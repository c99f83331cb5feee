// A projection's texels (MIP, MinIP; bf.split.w texels a pixel side, 0: off): per texel the claim
// of the brightest voxel whose centre falls in it (project_texels), so that only that voxel of
// the texel draws (project_winners packs them for brick_params). The others lie within a texel of it at no higher key: their
// footprints, the same but for that shift, add next to nothing (docs/MODEL.md, "Projections").
// Mirror: cpu::project_texels.
#ifndef TEXELS_GLSL
#define TEXELS_GLSL

const uint NO_TEXEL = 0xffffffffu;
// ProjectTexels' words: a batch's drawn voxels (project_winners' count), then the texels.
const uint TEXELS_FIRST = 1u;

// Voxel ijk's claim (stored value q): its key as brick_params makes it (16 bits) over a hash of
// ijk, so that a tie of keys has one winner.
uint claim_of(uvec3 ijk, uint q) {
    float d = clamp(float(q) / Q_MAX * bf.tf.x + bf.tf.y, 0.0, 1.0);
    float key = frame.rect.z == PROJECT_MINIP ? 1.0 - d : d;
    uint h = (ijk.x * 73856093u) ^ (ijk.y * 19349663u) ^ (ijk.z * 83492791u);
    return (uint(round(key * 65535.0)) << 16u) | (h >> 16u);
}

// Whether brick b's voxels claim texels: each of them draws wherever it falls (clear of the near
// and far planes, inside every clipping plane: params_world), tested once on the brick's box. A
// brick across one claims nothing and draws every voxel (per voxel, those tests cost llvmpipe
// more than the rest of the pass). An extracted voxel is never transparent here (recording.rs).
bool brick_claims(uvec3 b) {
    vec3 lo;
    vec3 hi;
    voxel_box(b, 0u, lo, hi);
    vec2 d = box_depths(lo, hi);
    float margin = CULL_RADII * frame.spacing.w * PROJECT_SHRINK;
    if (d.x - frame.forward.w < margin || frame.right.w - d.y < margin) return false;
    for (uint i = 0u; i < frame.rect.y; ++i) {
        for (uint c = 0u; c < 8u; ++c) {
            vec3 p = mix(lo, hi, vec3(uvec3(c, c >> 1u, c >> 2u) & 1u));
            if (dot(frame.clip[i].xyz, p) + frame.clip[i].w < 0.0) return false;
        }
    }
    return true;
}

// The texel voxel ijk of a claiming brick falls in (its word in ProjectTexels), NO_TEXEL where its
// centre falls outside the image: such a voxel takes no texel and hides no other.
uint texel_of(uvec3 ijk) {
    vec4 c = frame.view_proj * vec4(grid_point(vec3(ijk)), 1.0);
    vec2 n = frame.blur.zw * float(bf.split.w);
    vec2 t = floor((c.xy / c.w * 0.5 + 0.5) * n);
    bool inside = c.w > 0.0 && all(greaterThanEqual(t, vec2(0.0))) && all(lessThan(t, n));
    return inside ? TEXELS_FIRST + uint(t.y) * uint(n.x) + uint(t.x) : NO_TEXEL;
}

#endif
