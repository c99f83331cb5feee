// The footprint stage's bindings, push constants and per-entry helpers, shared by its raster
// variants: footprint.vert (quads and point sprites), footprint_sum.comp (compute sheet summation)
// and tile_{count,scan,scatter,composite}.comp (compute per-splat compositing in screen tiles).
// Mirrors: src/cpu/footprint.rs, src/cpu/tile.rs.
#include "types.glsl"

layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 15) readonly buffer ParamsHi { SplatParams params_hi[]; };
PAGED_READER(SplatParams, params_at, params_lo, params_hi)
layout(std430, binding = 2) readonly buffer DrawList { uint draw_list[]; };
layout(std430, binding = 3) readonly buffer Splats { Splat splats[]; };
layout(std430, binding = 4) readonly buffer SheetRank { uint sheet_rank[]; };
layout(std430, binding = 5) readonly buffer Radial { vec2 radial[]; };  // Kernel::radial_pairs
layout(binding = 6) uniform sampler2D slices;
#include "footprint_table.glsl"
layout(std430, binding = 7) readonly buffer Occlusion { float occlusion[]; };

// The mode is fixed per pipeline (a branch on the push constant made llvmpipe pay for both sides);
// the push constant's sheet_mode carries the same value for the CPU mirror.
layout(constant_id = 0) const uint SHEET_MODE = SHEET_MODE_SPLAT;

layout(push_constant) uniform Push {
    uint sheet_mode;   // SHEET_MODE_*
    uint axis;         // sheet axis
    uint rank_offset;  // start of this axis in sheet_rank
    uint rank_base;    // rank of the batch's first sheet (slab mode: its first slab)
    int rank_dir;      // +1 or -1: direction of the batch in rank space
    float slab_z0;     // slab mode: eye-space depth of slab 0's near face
    float slab_dz;     // slab mode: slab thickness (world units)
    float occluded;    // early termination: skip a splat whose every tile has at most this
                       // transmittance left; the tile compositor stops a pixel there (0: off)
    uint first;        // compute raster: the batch's first draw-list entry; tile compositing: the
                       // segment (entries first * TILE_SEGMENT.. of each tile's list)
    uint count;        // compute raster: entries in the batch (tile binning: in the list)
    uint chunks;       // tile binning: draw-list chunks of ceil(count / chunks) entries
    uint back_to_front;// tile compositing: 1 = the list runs back to front
    uint carry;        // 1: a later part of a bricked frame, carrying on from the image (and
                       // layers) an earlier part drew
} pc;

#include "screen.glsl"
// Most tiles a footprint may span and still be tested (larger ones are always drawn).
const int MAX_OCCLUSION_TILES = 16;

// Whether the footprint quad lies wholly over composite tiles whose transmittance is at most
// pc.occluded. Mirror: cpu::footprint::occluded.
bool occluded(SplatParams p) {
    vec2 size = frame.blur.zw;
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    for (int k = 0; k < 4; ++k) {
        vec3 q = p.center.xyz + CORNERS[k].x * p.axis_u.xyz + CORNERS[k].y * p.axis_v.xyz;
        vec4 c = frame.view_proj * vec4(q, 1.0);
        if (c.w <= 0.0) return false;
        vec2 s = (c.xy / c.w * 0.5 + 0.5) * size;
        lo = min(lo, s);
        hi = max(hi, s);
    }
    ivec2 tiles = ivec2(ceil(size / float(COMPOSITE_TILE)));
    ivec2 t0 = ivec2(floor(clamp(lo, vec2(0.0), size - 1.0) / float(COMPOSITE_TILE)));
    ivec2 t1 = ivec2(floor(clamp(hi, vec2(0.0), size - 1.0) / float(COMPOSITE_TILE)));
    if ((t1.x - t0.x + 1) * (t1.y - t0.y + 1) > MAX_OCCLUSION_TILES) return false;
    for (int y = t0.y; y <= t1.y; ++y) {
        for (int x = t0.x; x <= t1.x; ++x) {
            if (occlusion[y * tiles.x + x] > pc.occluded) return false;
        }
    }
    return true;
}

// The splat of draw-list entry e (slab and binned modes: the list holds (splat, slab or sheet) pairs).
uint entry_splat(uint e) {
    return SHEET_MODE == SHEET_MODE_SLAB || SHEET_MODE == SHEET_MODE_BINNED ? draw_list[2u * e] : draw_list[e];
}

// The summation layer of entry e within its batch and, in slab mode, the slab's faces relative to
// the splat's centre (radius units).
int entry_layer(uint e, uint splat, SplatParams p, out vec2 faces) {
    faces = vec2(0.0);
    if (SHEET_MODE == SHEET_MODE_SLAB) {
        uint slab = draw_list[2u * e + 1u];
        // The quad spans 1 + |bend| radii; in depth the kernel keeps its own radius (anti-aliasing
        // widens it on the screen by p.screen.w: its depth profile widened as well put most of its
        // weight outside the slabs, and small far frames in slab mode lost it).
        float radius = length(p.axis_v.xyz) / (1.0 + abs(p.screen.y)) / p.screen.w;
        float near_face = pc.slab_z0 + float(slab) * pc.slab_dz - p.screen.x;
        faces = vec2(near_face, near_face + pc.slab_dz) / radius;
        return pc.rank_dir > 0 ? int(slab - pc.rank_base) : int(pc.rank_base - slab);
    } else if (SHEET_MODE == SHEET_MODE_AXIS || SHEET_MODE == SHEET_MODE_BINNED) {
        // Binned sheets (a bricked volume's) are ranked by their index: empty ones keep a layer.
        uint rank = SHEET_MODE == SHEET_MODE_BINNED ? draw_list[2u * e + 1u]
                                                    : sheet_rank[pc.rank_offset + splats[splat].ijk[pc.axis]];
        return pc.rank_dir > 0 ? int(rank - pc.rank_base) : int(pc.rank_base - rank);
    }
    return 0;
}

// Quad coordinates of pixel (x, y) under `inv`.
vec2 quad_uv(mat3 inv, ivec2 px) {
    vec3 q = inv * vec3(vec2(px) + 0.5, 1.0);
    return q.xy / q.z;
}
