// The brick stages' bindings and helpers (issue 23), shared by brick_cull and brick_params: the
// bricked store (src/bricks.rs: 16-byte headers, 64-byte occupancy masks, 4-byte records of local
// index | 16-bit value << 16), the transfer function as a small buffer, classification on the
// device, and the dense PBTF position of a cell in a split grid (the brick grid, or a brick's
// BRICK_SIDE^3 cells). Mirror: src/cpu/brick.rs.
#include "types.glsl"
#include "pbtf.glsl"

struct BrickFrame {
    uvec4 grid;    // bricks along x, y, z; w: non-empty bricks (headers)
    uvec4 split;   // the eye's PBTF split of the brick grid; w: unused
    vec4 tf;       // x, y: a stored value d is the TF's density d x + y (gradients); zw: unused
    vec4 light;    // direction the light travels; w: 1 = headlight shading
    vec4 shade;    // ambient, diffuse, specular, shininess
    vec4 grad;     // x: the volume's largest gradient magnitude (gradient weighting); y: levels of
                   // detail, largest cell spacing in pixels (0: off); z: their largest error
    uvec4 lo;      // the bricks drawn: lo <= b < hi (a rank's box in sort-last rendering; else the grid)
    uvec4 hi;      // w: levels of detail's node levels above the brick (0: none; brick_nodes)
};

layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(std430, binding = 1) readonly buffer BrickFrameBlock { BrickFrame bf; };
#include "grid.glsl"
// The transfer function tabulated per quantised value q (BrickScene::tf_words): straight RGBA,
// whether q is extracted (a bit), and the extracted values below each 32-value word.
layout(std430, binding = 2) readonly buffer Tf {
    vec4 tf_color[TF_ENTRIES];
    uint tf_emit[TF_ENTRIES / 32];
    uint tf_prefix[];
};
// brick (x | y << 10 | z << 20), first record, records, quantised min | max << 16.
layout(std430, binding = 3) readonly buffer Headers { uvec4 headers[]; };
// Per brick (MASK_STRIDE words) its stored voxels, a bit each in local index order (MASK_WORDS
// words), then per word the stored voxels in the words before it, 16 bits each (mask_below;
// BrickStore::mask_words): a voxel's record is a count and a popcount away, where summing the
// words before it cost a gradient up to 15 reads a neighbour (a third of brick_params' time on the
// shaded bonsai).
layout(std430, binding = 4) readonly buffer Masks { uint masks[]; };
layout(std430, binding = 5) readonly buffer Records { uint records_0[]; };
// A store larger than the budget allows stays on the host: each batch's bricks' records arrive in
// BatchRecords (STREAMED_STORE builds, which count a brick's drawn voxels from BrickCounts).
layout(std430, binding = 22) readonly buffer BatchRecords { uint batch_records[]; };
layout(std430, binding = 23) readonly buffer BrickCounts { uint brick_counts[]; };
// Stores of more than RECORD_PAGE records bind them as up to 8 pages (one storage binding may not
// pass maxStorageBufferRange); PAGED_RECORDS builds read through the pages.
#if defined(STREAMED_STORE)
uint stored_record(uint i) {
    return batch_records[i];
}
#elif defined(PAGED_RECORDS)
layout(std430, binding = 14) readonly buffer Records1 { uint records_1[]; };
layout(std430, binding = 15) readonly buffer Records2 { uint records_2[]; };
layout(std430, binding = 16) readonly buffer Records3 { uint records_3[]; };
layout(std430, binding = 17) readonly buffer Records4 { uint records_4[]; };
layout(std430, binding = 18) readonly buffer Records5 { uint records_5[]; };
layout(std430, binding = 19) readonly buffer Records6 { uint records_6[]; };
layout(std430, binding = 20) readonly buffer Records7 { uint records_7[]; };
uint stored_record(uint i) {
    uint j = i % RECORD_PAGE;
    switch (i / RECORD_PAGE) {
        case 0u: return records_0[j];
        case 1u: return records_1[j];
        case 2u: return records_2[j];
        case 3u: return records_3[j];
        case 4u: return records_4[j];
        case 5u: return records_5[j];
        case 6u: return records_6[j];
        default: return records_7[j];
    }
}
#else
uint stored_record(uint i) {
    return records_0[i];
}
#endif
// A uniform brick (a full brick whose voxels hold one value; src/bricks/build.rs) stores no
// records: its first record is UNIFORM_RECORDS | value << 9, and record first + r is r | value << 16.
const uint UNIFORM_RECORDS = 0x80000000u;
uint record_at(uint i) {
    if ((i & UNIFORM_RECORDS) != 0u) return (i & 511u) | (((i >> 9u) & 0xffffu) << 16u);
    return stored_record(i);
}
// Brick id (x + nx (y + ny z)) -> header, or 0xffffffff when the brick stores nothing.
layout(std430, binding = 6) readonly buffer BrickIndex { uint brick_index[]; };
// Per brick-grid position in draw order: header << 10 | voxels drawn, 0 when culled.
layout(std430, binding = 7) buffer BrickSlots { uint slots[]; };
// The batch's visible bricks in draw order: header, its first position in the batch, its first
// record (in the resident store, or in the batch's records when the store streams), its splats |
// its level of detail << 16.
layout(std430, binding = 8) readonly buffer BrickList { uvec4 brick_list[]; };
#ifdef SCREEN_QUADS
// brick_quads and brick_lod_quads: each splat's footprint in screen space (screen.glsl) in its
// parameters' place, for the compute tile compositor.
layout(std430, binding = 9) writeonly buffer Quads { ScreenQuad quads_lo[]; };
layout(std430, binding = 10) writeonly buffer QuadsHi { ScreenQuad quads_hi[]; };
#else
layout(std430, binding = 9) writeonly buffer Params { SplatParams params_lo[]; };
layout(std430, binding = 10) writeonly buffer ParamsHi { SplatParams params_hi[]; };
#endif
layout(std430, binding = 11) writeonly buffer Order { uint order_out[]; };
// The batch's voxels in draw order: i | j << 16, k | stored value << 16.
layout(std430, binding = 12) buffer Voxels { uvec2 voxels[]; };
#if defined(PROJECT_TEXELS)
// A projection's texels: per voxel of the batch the texel it claims (project_texels, for
// project_winners; texels.glsl), in the occlusion map's place.
layout(std430, binding = 13) buffer VoxelTexels { uint voxel_texels[]; };
#elif !defined(GRADIENTS)
// The occlusion map after the waves drawn so far (tile_occlusion; occlusion.glsl).
layout(std430, binding = 13) readonly buffer Occlusion { float occlusion[]; };
#endif
#ifdef GRADIENTS
// Per header its first word, then per stored voxel the first and second words of its packed
// central differences (BrickStore::gradient_words): brick_params' GRADIENTS build, in the places
// of brick_hidden's output and input (two bindings: each within maxStorageBufferRange).
layout(std430, binding = 21) readonly buffer Gradients { uint gradients[]; };
layout(std430, binding = 13) readonly buffer GradientsHi { uint gradients_hi[]; };
#elif defined(PROJECT_WINNERS)
// project_winners' output: a batch's voxels that draw in a projection, packed (texels.glsl).
layout(std430, binding = 21) writeonly buffer ProjectVoxels { uvec2 project_out[]; };
#else
// Per entry of the next wave, 1 when it is hidden (brick_hidden).
layout(std430, binding = 21) writeonly buffer Hidden { uint hidden_out[]; };
#endif

const float Q_MAX = 65535.0;
const uint MASK_WORDS = BRICK_SIDE * BRICK_SIDE * BRICK_SIDE / 32u;
const uint MASK_STRIDE = MASK_WORDS + MASK_WORDS / 2u;

// The stored voxels of header h's brick in its mask words before word w.
uint mask_below(uint h, uint w) {
    return (masks[h * MASK_STRIDE + MASK_WORDS + w / 2u] >> (16u * (w & 1u))) & 0xffffu;
}

// Workgroups spill into y past MAX_GROUPS_X (plan::groups_per_item): one workgroup per item.
uint workgroup_item() {
    return gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
}

uvec3 brick_coords(uint packed) {
    return uvec3(packed & 1023u, (packed >> 10u) & 1023u, packed >> 20u);
}

uvec3 local_cell(uint l) {
    return uvec3(l % BRICK_SIDE, (l / BRICK_SIDE) % BRICK_SIDE, l / (BRICK_SIDE * BRICK_SIDE));
}

// Position of cell c in the PBTF sequence of a dense n-cell grid split at s (front to back):
// octants in turn, inside each k outward, then j, then i (order.rs, pbtf_bricked's key).
uint dense_pbtf(uvec3 c, uvec3 n, uvec3 s) {
    uint si = c.x < s.x ? 0u : 1u;
    uint sj = c.y < s.y ? 0u : 1u;
    uint sk = c.z < s.z ? 0u : 1u;
    uint octant = si + 2u * sj + 4u * sk;
    uint base = 0u;
    for (uint o = 0u; o < octant; ++o) {
        base += side_count(n.x, s.x, o & 1u) * side_count(n.y, s.y, (o >> 1u) & 1u)
            * side_count(n.z, s.z, (o >> 2u) & 1u);
    }
    uint ni = side_count(n.x, s.x, si);
    uint nj = side_count(n.y, s.y, sj);
    return base + (outward(c.z, s.z, sk) * nj + outward(c.y, s.y, sj)) * ni + outward(c.x, s.x, si);
}

// Whether voxels of quantised value q are extracted (classify_field: at or above the threshold,
// opacity > 0).
bool emits(uint q) {
    return ((tf_emit[q >> 5u] >> (q & 31u)) & 1u) != 0u;
}

// Extracted values below q.
uint emitted_below(uint q) {
    uint w = q >> 5u;
    if ((q & 31u) == 0u) return tf_prefix[w];
    return tf_prefix[w] + uint(bitCount(tf_emit[w] & ((1u << (q & 31u)) - 1u)));
}

// Whether no value in [lo, hi] is extracted: a brick of that range draws nothing.
bool tf_empty(uint lo, uint hi) {
    return emitted_below(hi + 1u) == emitted_below(lo);
}

// The header of the brick holding voxel c (0xffffffff: an empty brick). Mirror:
// BrickStore::header_of.
uint header_of(uvec3 c) {
    uvec3 b = c / BRICK_SIDE;
    return brick_index[b.x + bf.grid.x * (b.y + bf.grid.y * b.z)];
}

// The rank of local voxel l's record among header h's (word: l's mask word): the brick's stored
// voxels below it in local index order. Mirror: BrickStore::stored_below.
uint stored_below(uint h, uint l, uint word) {
    return uint(bitCount(word & ((1u << (l % 32u)) - 1u))) + mask_below(h, l / 32u);
}

// The stored (normalised) value at voxel v, indices clamped to the grid: 0 where nothing is stored.
float stored_at(ivec3 v) {
    uvec3 c = uvec3(clamp(v, ivec3(0), ivec3(frame.dims.xyz) - 1));
    uint h = header_of(c);
    if (h == 0xffffffffu) return 0.0;
    uvec3 lc = c % BRICK_SIDE;
    uint l = lc.x + BRICK_SIDE * (lc.y + BRICK_SIDE * lc.z);
    uint word = masks[h * MASK_STRIDE + l / 32u];
    if (((word >> (l % 32u)) & 1u) == 0u) return 0.0;
#ifdef MASK_SUMS
    // brick_pyramid inlines this 48 times a cell: there the count cost more than the sum (llvmpipe:
    // the pyramid of the shaded stent 170 -> 345 ms), in brick_params it saves 25-35 %.
    uint below = uint(bitCount(word & ((1u << (l % 32u)) - 1u)));
    for (uint w = 0u; w < l / 32u; ++w) below += uint(bitCount(masks[h * MASK_STRIDE + w]));
#else
    uint below = stored_below(h, l, word);
#endif
    return float(record_at(headers[h].y + below) >> 16u) / Q_MAX;
}

float density_at(ivec3 v) {
    return stored_at(v) * bf.tf.x + bf.tf.y;
}

// The world gradient of the density from its central differences d along the grid's axes: a
// sheared grid's solves U^T g = d / 2 (Grid::gradient).
vec3 gradient_from(vec3 d) {
    vec3 s = frame.spacing.xyz;
    vec3 h = frame.shear.xyz;
    float gx = d.x / (2.0 * s.x);
    float gy = (d.y - 2.0 * h.x * gx) / (2.0 * s.y);
    float gz = (d.z - 2.0 * (h.y * gx + h.z * gy)) / (2.0 * s.z);
    return vec3(gx, gy, gz);
}

// Central-difference gradient of the density at voxel v, read through the store (classify_field).
vec3 gradient_at(ivec3 v) {
    return gradient_from(vec3(density_at(v + ivec3(1, 0, 0)) - density_at(v - ivec3(1, 0, 0)),
                              density_at(v + ivec3(0, 1, 0)) - density_at(v - ivec3(0, 1, 0)),
                              density_at(v + ivec3(0, 0, 1)) - density_at(v - ivec3(0, 0, 1))));
}

#ifdef GRADIENTS
// The density's central differences at the stored voxel of rank `rank` in header h's brick, from
// its two packed words (each difference plus 65536 in 17 bits: pack_differences). Mirror:
// BrickInputs::differences_at.
vec3 differences_at(uint h, uint rank) {
    uint i = gradients[h] + rank;
    uvec2 w = uvec2(gradients[i], gradients_hi[i]);
    ivec3 d = ivec3(uvec3(w.x & 0x1ffffu, (w.x >> 17u) | ((w.y & 3u) << 15u), w.y >> 2u)) - 65536;
    return vec3(d) * (bf.tf.x / Q_MAX);
}

// The same at stored voxel v: one lookup of the voxel's rank instead of six neighbours'.
vec3 stored_differences(ivec3 v) {
    uvec3 c = uvec3(v);
    uint h = header_of(c);
    uvec3 lc = c % BRICK_SIDE;
    uint l = lc.x + BRICK_SIDE * (lc.y + BRICK_SIDE * lc.z);
    return differences_at(h, stored_below(h, l, masks[h * MASK_STRIDE + l / 32u]));
}
#endif

// Headlight shading (two-sided) of colour rgb at a gradient g.
vec3 shade(vec3 rgb, vec3 g) {
    float len = length(g);
    vec3 n = len > 0.0 ? g / len : vec3(0.0);
    float ndl = abs(dot(n, -bf.light.xyz));
    float lit = bf.shade.x + bf.shade.y * ndl;
    float spec = bf.shade.z * pow(ndl, bf.shade.w);
    return min(rgb * lit + spec, vec3(1.0));
}

// Colour and opacity of the voxel at v of quantised value q: the TF, its gradient weighting and
// headlight shading (`shaded`), gradients read through the store (classify_field).
vec4 classify_voxel(ivec3 v, uint q, bool shaded) {
    vec4 c = tf_color[q];
    bool weighted = bf.tf.w > 0.0;
    if (weighted || shaded) {
#ifdef GRADIENTS
        vec3 g = gradient_from(stored_differences(v));
#else
        vec3 g = gradient_at(v);
#endif
        if (weighted) c.a *= pow(length(g) / bf.grad.x, bf.tf.w);
        if (shaded) c.rgb = shade(c.rgb, g);
    }
    return c;
}

// Levels of detail: per header a pyramid of LOD_CELLS cells, levels 1..3 of a brick (64 + 8 + 1
// cells of 2^l voxels a side). A cell is prefiltered along the six axis directions (as voxel cone
// tracing's anisotropic cells are): seen along each, its columns are composited front to back and
// their opacities averaged across, so a half-covered cell keeps half its coverage and a thin sheet
// covers what it covers from each side. The opacity along an axis is the same from either side,
// so a cell keeps three (brick_pyramid), and one colour and normal over the six directions. Words:
// tau_code along x | along y << 16 (optical depth per cell length), along z | octahedral normal
// << 16 (snorm 8 + 8), straight colour (unorm 10:10:10).
// Level 1 (64 cells) lives in the pyramid's slot of the brick; levels 2 and 3 (9 cells), with a
// summary, in the brick's SUMMARY_WORDS of LodSummary, which stays resident whatever the budget,
// so a brick drawn at level 2 or 3 never needs its records: words 0..3, x: drawn cells of level 1
// | level 2 << 8 | level 3 << 12 | drawn voxels << 16, yzw: the largest error of levels 1..3;
// words 4..30: the 9 cells.
// Built by brick_pyramid when the classification changes. Mirror: cpu::lod.
// Up to 4 storage bindings of PYRAMID_PAGE words (one binding may not pass maxStorageBufferRange).
layout(std430, binding = 24) buffer Pyramid { uint pyramid_0[]; };
layout(std430, binding = 28) buffer Pyramid1 { uint pyramid_1[]; };
layout(std430, binding = 29) buffer Pyramid2 { uint pyramid_2[]; };
layout(std430, binding = 30) buffer Pyramid3 { uint pyramid_3[]; };

uint pyramid_word(uint i) {
    uint j = i % PYRAMID_PAGE;
    switch (i / PYRAMID_PAGE) {
        case 0u: return pyramid_0[j];
        case 1u: return pyramid_1[j];
        case 2u: return pyramid_2[j];
        default: return pyramid_3[j];
    }
}

void pyramid_put(uint i, uint v) {
    uint j = i % PYRAMID_PAGE;
    switch (i / PYRAMID_PAGE) {
        case 0u: pyramid_0[j] = v; break;
        case 1u: pyramid_1[j] = v; break;
        case 2u: pyramid_2[j] = v; break;
        default: pyramid_3[j] = v; break;
    }
}
// A batch's coarse splats' positions (brick_lod_params).
#if defined(PROJECT_TEXELS)
// A projection's texels (texels.glsl), in the place of LodSplats (projections have no levels of
// detail).
layout(std430, binding = 31) buffer ProjectTexels { uint project_texels[]; };
#elif defined(PROJECT_VOXELS)
// brick_params' voxels in a projection with texels: project_winners' (texels.glsl).
layout(std430, binding = 31) readonly buffer ProjectVoxels { uvec2 project_voxels[]; };
#else
layout(std430, binding = 31) readonly buffer LodSplats { uint lod_splats[]; };
#endif
layout(std430, binding = 25) buffer LodSummary { uint lod_words[]; };
const uint LOD_CELLS = 73u;
// Cells in a brick's pyramid slot (level 1), and words per brick of LodSummary.
const uint SLOT_CELLS = 64u;
const uint SUMMARY_WORDS = 32u;

uvec4 lod_summary(uint h) {
    uint b = h * SUMMARY_WORDS;
    return uvec4(lod_words[b], lod_words[b + 1u], lod_words[b + 2u], lod_words[b + 3u]);
}
const uint CELL_WORDS = 3u;
// The octahedral bytes of a zero gradient (-128 is never written for a unit vector).
const uint NO_NORMAL = 0x8080u;

// First cell of level l (1..3) in a brick's pyramid.
uint level_offset(uint l) {
    return l == 1u ? 0u : (l == 2u ? 64u : 72u);
}

// The eye's PBTF split of level l's cells (2^l voxels a side) inside brick b: a cell lies on the
// eye's low side when its lowest voxel does (as a brick does; order.rs, brick_split).
uvec3 level_split(uvec3 b, uint l) {
    uint side = BRICK_SIDE >> l;
    ivec3 global = ivec3((frame.split.xyz + (1u << l) - 1u) >> l);
    return uvec3(clamp(global - ivec3(b * side), ivec3(0), ivec3(side)));
}

// The world box of the voxel centres of brick b's node of tree level k (k = 0: the brick; a
// sheared grid's: the box around its corners). Mirror: Grid::world_box.
void voxel_box(uvec3 b, uint k, out vec3 lo, out vec3 hi) {
    uvec3 first_voxel = ((b >> k) << k) * BRICK_SIDE;
    vec3 first = vec3(first_voxel);
    vec3 last = vec3(min(first_voxel + (BRICK_SIDE << k), frame.dims.xyz) - 1u);
    lo = vec3(1e30);
    hi = vec3(-1e30);
    for (uint c = 0u; c < 8u; ++c) {
        vec3 p = grid_point(mix(first, last, vec3(uvec3(c, c >> 1u, c >> 2u) & 1u)));
        lo = min(lo, p);
        hi = max(hi, p);
    }
}

// Pixels per voxel spacing at eye-space depth `depth`.
float voxel_pixels(float depth) {
    float voxel = frame.spacing.w / frame.origin.w;
    return frame.eye.w > 0.5 ? voxel * frame.up.w / max(depth, frame.forward.w) : voxel * frame.up.w;
}

// Octaves of projected size a level-l splat at eye-space `depth` has before the next level takes
// over: 0 where its cells project to bf.grad.y pixels, 1 where the next level's do.
float level_octaves(float depth, uint l) {
    return log2(bf.grad.y / voxel_pixels(depth)) - float(l);
}

// Per brick, 1 when its splats may morph toward the next level this frame (brick_cull).
layout(std430, binding = 26) buffer BrickMorph { float brick_morph[]; };

// VOXEL_MORPHS when header h's brick morphs this frame (levels of detail on), for its voxels.
uint morph_bit(uint h) {
    return bf.grad.y > 0.0 && brick_morph[h] > 0.0 ? VOXEL_MORPHS : 0u;
}

// Geomorphing (levels of detail): over the last bf.grad.w octaves of projected size before the
// next level's threshold, a level-l splat at grid position `at` widens toward the next level's
// footprint (twice as wide) by its own depth, so the growth is continuous from splat to splat and
// brick to brick and reaches 2 where the next level takes over. Its energy falls by growth^2 (the
// optical depth over its footprint is kept). The splats stay on their lattice: moving them toward
// their parent's centre made a flat slab's summed footprints ripple by 5 %, and a growth per brick
// left 2 % steps at brick faces.
float splat_growth(vec3 at, uint l) {
    vec3 center = grid_point(at);
    float octaves = level_octaves(dot(center - frame.eye.xyz, frame.forward.xyz), l);
    return 1.0 + clamp((octaves - (1.0 - bf.grad.w)) / bf.grad.w, 0.0, 1.0);
}

// Drawn cells of level l in header h's brick (level 0: its drawn voxels).
uint level_count(uint h, uint l) {
    uint x = lod_words[h * SUMMARY_WORDS];
    if (l == 0u) return x >> 16u;
    return l == 1u ? x & 255u : (l == 2u ? (x >> 8u) & 15u : (x >> 12u) & 1u);
}

// A brick's slot code for n splats at level l, in 10 bits (bricks::slot_entry decodes it); a node
// above the brick (l > 3, one splat) 585 + its tree level.
uint slot_code(uint l, uint n) {
    return l == 0u ? n : (l == 1u ? 512u + n : (l == 2u ? 576u + n : 582u + l));
}

// A streamed store's pyramid holds a batch's bricks (brick_pyramid's STREAMED_STORE build): per
// header, its slot in the batch.
layout(std430, binding = 27) buffer PyramidSlot { uint pyramid_slot[]; };

// Header h's place in the pyramid: h, or its slot in the batch when the store streams.
uint pyramid_index(uint h) {
#ifdef STREAMED_STORE
    return pyramid_slot[h];
#else
    return h;
#endif
}

// A cell's optical depth in 16 bits: an f32's exponent from 2^-23 to 2^7 and 11 bits of mantissa,
// rounded; 0 for none. Integer steps, so the mirror (cpu::lod::tau_code) packs the same bits.
uint tau_code(float t) {
    if (!(t >= 1.1920929e-7)) return 0u;
    uint b = floatBitsToUint(min(t, 255.0));
    return ((b + 0x800u) >> 12u) - (103u << 11u);
}

float tau_decode(uint code) {
    return code == 0u ? 0.0 : uintBitsToFloat((code + (103u << 11u)) << 12u);
}

// Word k of cell i (level_offset) of header h's pyramid: level 1 in its pyramid slot, levels 2
// and 3 in its summary.
uint cell_word(uint h, uint i, uint k) {
    if (i < SLOT_CELLS) return pyramid_word((pyramid_index(h) * SLOT_CELLS + i) * CELL_WORDS + k);
    return lod_words[h * SUMMARY_WORDS + 4u + (i - SLOT_CELLS) * CELL_WORDS + k];
}

// Cell i of header h's pyramid: its optical depth per cell length along x (0 when it draws
// nothing; every axis's is 0 together).
float cell_tau(uint h, uint i) {
    return tau_decode(cell_word(h, i, 0u) & 0xffffu);
}

// Octahedral normals fold the lower hemisphere with the signs of x and y, 0 counted positive.
vec2 sign_not_zero(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// The direction of octahedral bytes w (0 for NO_NORMAL).
vec3 unpack_normal(uint w) {
    if (w == NO_NORMAL) return vec3(0.0);
    vec2 oct = unpackSnorm4x8(w).xy;
    vec3 n = vec3(oct, 1.0 - abs(oct.x) - abs(oct.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
    return normalize(n);
}

// A cell (words xy, zn, c) seen along `view` (index space): the opacities along the three axes
// weighted by the squares of the view's components; returns straight colour and optical depth per
// cell length.
vec4 cell_seen(uint xy, uint zn, uint c, vec3 view, out vec3 normal) {
    vec3 w = view * view / max(dot(view, view), 1e-30);
    vec3 tau = vec3(tau_decode(xy & 0xffffu), tau_decode(xy >> 16u), tau_decode(zn & 0xffffu));
    float trans = dot(w, exp(-min(tau, vec3(80.0))));
    normal = unpack_normal(zn >> 16u);
    return vec4(vec3(uvec3(c, c >> 10u, c >> 20u) & 1023u) / 1023.0, -log(max(trans, 1e-30)));
}

// Cell i of header h seen along `view` (cell_seen).
vec4 cell_color(uint h, uint i, vec3 view, out vec3 normal) {
    return cell_seen(cell_word(h, i, 0u), cell_word(h, i, 1u), cell_word(h, i, 2u), view, normal);
}

// Octahedral bytes (snorm 8 + 8) of gradient g, NO_NORMAL when it is zero.
uint pack_normal(vec3 g) {
    float len = abs(g.x) + abs(g.y) + abs(g.z);
    if (!(len > 0.0)) return NO_NORMAL;
    vec3 n = g / len;
    vec2 o = n.xy;
    if (n.z < 0.0) o = (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
    return packSnorm4x8(vec4(o, 0.0, 0.0)) & 0xffffu;
}

// g turned to agree with `with` (shading is two-sided, so a normal's sign is free; the opposite
// gradients of a thin shell's two faces would otherwise cancel).
vec3 aligned(vec3 g, vec3 with) {
    return dot(g, with) < 0.0 ? -g : g;
}

// The opacity along `axis` of a cell whose children have opacities a (along that axis): its four
// columns of two children composited, then averaged across (the same from either side).
float axis_opacity(float a[8], uint axis) {
    float sum = 0.0;
    for (uint p = 0u; p < 4u; ++p) {
        // Insert a 0 bit along the axis into p's two bits: the low child of the column.
        uint low = (p & ((1u << axis) - 1u)) | ((p >> axis) << (axis + 1u));
        sum += 1.0 - (1.0 - a[low]) * (1.0 - a[low | (1u << axis)]);
    }
    return 0.25 * sum;
}

uint unorm10(float v) {
    return uint(floor(clamp(v, 0.0, 1.0) * 1023.0 + 0.5));
}

// The error of a cell of opacity a (over `len` voxel lengths) and colour straight against a child
// (sums tk, ck; error ek) of `voxels` voxels, its opacity taken over the same length. The pyramid
// measures over a brick's side, the depth the cut draws at one level: so opacity that piles up
// along a ray through a translucent brick counts, not one voxel's share of it (per voxel, the
// trilinear heptane 2x lay 3.4 dB below full detail at the old bound).
float child_error(float a, vec3 straight, float tk, vec3 ck, float ek, float voxels, float len) {
    float ak = 1.0 - exp(-tk / voxels * len);
    vec3 sk = tk > 0.0 ? ck / tk : vec3(0.0);
    vec3 dc = abs(sk - straight);
    return ek + max(abs(ak - a), ak * max(dc.x, max(dc.y, dc.z)));
}


// Levels of detail above the brick: a node of tree level k (1..bf.hi.w) covers 2^k bricks a side
// and is one cell 2^(3+k) voxels a side, prefiltered from its 8 children as brick_pyramid's
// levels are (brick_nodes). NODE_WORDS per node, after the bricks' summaries in LodSummary, level
// by level, each level's nodes x fastest: the cell's 3 words, its error, its optical depth, the
// first header below it whose cell draws (the brick that draws the node; 0xffffffff: none), and 1
// when it may be drawn at all (inside the drawn bricks, its bricks consecutive: consecutive).
const uint NODE_WORDS = 7u;
// A node's cell projects to at most this many pixels (and the bound): wider, its one footprint
// blurs the silhouette of what it stands for (a uniform cube at 8 x 8 pixels drawn with 1.5-pixel
// nodes covered 20 % more than at full detail). Mirror: cpu::brick_nodes::NODE_PIXELS.
const float NODE_PIXELS = 1.0;

// Nodes along x, y, z at tree level k.
uvec3 node_grid(uint k) {
    return (bf.grid.xyz + (1u << k) - 1u) >> k;
}

// Word w of node n (node coordinates) of tree level k.
uint node_word(uint k, uvec3 n, uint w) {
    uint base = max(bf.grid.w, 1u) * SUMMARY_WORDS;
    for (uint j = 1u; j < k; ++j) {
        uvec3 g = node_grid(j);
        base += g.x * g.y * g.z * NODE_WORDS;
    }
    uvec3 g = node_grid(k);
    return base + (n.x + g.x * (n.y + g.y * n.z)) * NODE_WORDS + w;
}

// This frame's cut over the nodes (brick_node_cut), per level-1 node after the nodes: the tree
// level of the node that draws its bricks, 0 for none.
uint cut_word(uvec3 n1) {
    uvec3 g = node_grid(1u);
    return node_word(bf.hi.w + 1u, uvec3(0u), 0u) + n1.x + g.x * (n1.y + g.y * n1.z);
}

// Node n of tree level k seen along `view` (cell_seen).
vec4 node_color(uint k, uvec3 n, vec3 view, out vec3 normal) {
    uint w = node_word(k, n, 0u);
    return cell_seen(lod_words[w], lod_words[w + 1u], lod_words[w + 2u], view, normal);
}

#include "params.glsl"
#ifdef SCREEN_QUADS
#include "screen.glsl"
PAGED_WRITER(ScreenQuad, quads_store, quads_lo, quads_hi)
// The splat's screen quad where brick_params would write its parameters.
void splat_store(uint s, SplatParams p) {
    quads_store(s, screen_record(p));
}
#else
PAGED_WRITER(SplatParams, params_store, params_lo, params_hi)
void splat_store(uint s, SplatParams p) {
    params_store(s, p);
}
#endif

// The depths along the view of the box lo..hi's nearest and farthest corners.
vec2 box_depths(vec3 lo, vec3 hi) {
    vec2 d = vec2(1e30, -1e30);
    for (uint c = 0u; c < 8u; ++c) {
        vec3 p = mix(lo, hi, vec3(uvec3(c, c >> 1u, c >> 2u) & 1u));
        float z = dot(p - frame.eye.xyz, frame.forward.xyz);
        d = vec2(min(d.x, z), max(d.y, z));
    }
    return d;
}

// How far a splat `cell` voxels a side at eye-space `depth` reaches from its centre: CULL_RADII
// radii, params_at's culling margin (anti-aliasing widens it with depth).
float cull_reach(float depth, float cell) {
    return CULL_RADII * cell * frame.spacing.w * footprint_scale(max(depth, 1e-6), cell);
}

// A coarse cell's error as the picture sees it, the cell projecting to `size` pixels: the error
// already counts a brick's depth of the departure along a ray, and a cell smaller than a pixel
// covers size² of the pixel's area, which the pixel's filter averages its departure over (times
// that share, up to 1; along the grid's axes view_coherence counts more).
float seen_error(float err, float size) {
    float s = min(size, 1.0);
    return err * s * s;
}

// How many cells' departures a ray adds up seen along `view` (index space): the error counts a
// brick's side (8 voxels), but a ray near a grid axis stays in one column of a coarse cell's
// children for about COHERENT_DRIFT / tan(its angle to the axis) cells, through row after row of
// bricks, so their departures keep one sign along it; an oblique ray crosses to other columns
// and mixes them. 1 from about 27 degrees off every axis, up to MAX_COHERENCE along one.
// Mirror: cpu::lod::view_coherence.
const float COHERENT_DRIFT = 0.5;
const float MAX_COHERENCE = 4.0;
float view_coherence(vec3 view) {
    vec3 g = abs(view);
    float m = max(g.x, max(g.y, g.z));
    float across = sqrt(max(dot(g, g) - m * m, 0.0));
    return clamp(COHERENT_DRIFT * m / max(across, 1e-30), 1.0, MAX_COHERENCE);
}

// The direction a brick (world box lo..hi) is seen along, in index space.
vec3 seen_along(vec3 lo, vec3 hi) {
    return grid_direction(frame.eye.w > 0.5 ? 0.5 * (lo + hi) - frame.eye.xyz : frame.forward.xyz);
}

// Brick b's (header h) level this frame: the coarsest whose cell spacing projects to at most
// bf.grad.y pixels at the brick's nearest depth, whose error is at most bf.grad.z (0: off) and
// whose splats keep clear of the near and far planes;
// `morph`: 1 when its splats may morph toward the next level (allowed there too, and some of its
// splats within the band; splat_growth).
uint brick_level(uint h, uvec3 b, out float morph) {
    morph = 0.0;
    if (bf.grad.y <= 0.0) return 0u;
    vec3 lo;
    vec3 hi;
    voxel_box(b, 0u, lo, hi);
    vec2 depths = box_depths(lo, hi);
    float px = voxel_pixels(depths.x);
    uvec4 s = lod_summary(h);
    float coh = view_coherence(seen_along(lo, hi));
    uint level = 0u;
    for (uint l = 1u; l <= 3u; ++l) {
        if (px * float(1u << l) > bf.grad.y || seen_error(uintBitsToFloat(s[l]) * coh, px * float(1u << l)) > bf.grad.z)
            break;
        // Splats within CULL_RADII radii of the near or far plane are dropped (params_at): no level
        // whose wider splats (morphed: up to twice) would be dropped where the brick reaches a plane.
        float cell = float(1u << l);
        float near_reach = 2.0 * cull_reach(depths.x, cell);
        float far_reach = 2.0 * cull_reach(depths.y, cell);
        if (depths.x < frame.forward.w + near_reach || depths.y > frame.right.w - far_reach) break;
        level = l;
    }
    // Its splats grow (splat_growth) only within the band, which its farthest reaches first.
    float octaves = level_octaves(depths.y, level);
    float next = seen_error(uintBitsToFloat(s[min(level + 1u, 3u)]) * coh, px * float(2u << level));
    if (level < 3u && bf.grad.w > 0.0 && next <= bf.grad.z && octaves > 1.0 - bf.grad.w)
        morph = 1.0;
    return level;
}

// Whether the bricks of the aligned block n0..n1 (clipped to the grid) are consecutive in the
// brick order (brick_slot): the block is one of the k-d tree's boxes or lies inside one of its
// leaves (an octree there); a block the tree cuts is not. Only then can one splat at one of its
// bricks' places stand for them all in a visibility order. Mirror: cpu::brick_nodes::consecutive.
bool consecutive(uvec3 n0, uvec3 n1) {
    uint total = bf.grid.x * bf.grid.y * bf.grid.z;
    uvec3 lo = uvec3(0u), hi = bf.grid.xyz;
    uint n = bf.lo.w > 0u ? 0u : 0xffffffffu;
    for (;;) {
        if (all(equal(lo, n0)) && all(equal(hi, n1))) return true;
        // Inside a leaf: an aligned block, consecutive in its octree order.
        if (n == 0xffffffffu) return all(greaterThanEqual(n0, lo)) && all(lessThanEqual(n1, hi));
        uint code = brick_index[total + 4u * n];
        uint axis = code & 3u, plane = code >> 2u;
        if (plane <= n0[axis]) {
            lo[axis] = plane;
            n = brick_index[total + 4u * n + 2u];
        } else if (plane >= n1[axis]) {
            hi[axis] = plane;
            n = brick_index[total + 4u * n + 1u];
        } else {
            return false;
        }
    }
    return false;
}

// The tree level of the node above brick b (or any brick of b's level-1 node) that draws it this
// frame, 0 for none: the highest whose one cell projects to at most min(bf.grad.y, NODE_PIXELS)
// pixels at the node's nearest depth, whose seen error is at most bf.grad.z, whose splat keeps
// clear of the near and far planes and which may be drawn at all (brick_nodes: inside the drawn
// bricks, its bricks consecutive in their order). `px`: pixels per voxel spacing at the nearest depth of b's level-1
// node, which bounds every node above it from below (their nearest depths are no farther), so the
// cheap tests come first. Run per level-1 node (brick_node_cut).
uint node_level(uvec3 b, float px) {
    float bound = min(bf.grad.y, NODE_PIXELS);
    if (bf.grad.y <= 0.0 || px * float(2u * BRICK_SIDE) > bound) return 0u;
    for (uint k = bf.hi.w; k >= 1u; --k) {
        // Cheap tests first: the brick's own pixels per voxel bound the node's from below.
        float cell = float(BRICK_SIDE << k);
        if (px * cell > bound) continue;
        uint w = node_word(k, b >> k, 0u);
        float err = uintBitsToFloat(lod_words[w + 3u]);
        if (seen_error(err, px * cell) > bf.grad.z || lod_words[w + 6u] == 0u) continue;
        vec3 lo;
        vec3 hi;
        voxel_box(b, k, lo, hi);
        vec2 depths = box_depths(lo, hi);
        float size = voxel_pixels(depths.x) * cell;
        if (size > bound || seen_error(err * view_coherence(seen_along(lo, hi)), size) > bf.grad.z) continue;
        float near_reach = 2.0 * cull_reach(depths.x, cell);
        float far_reach = 2.0 * cull_reach(depths.y, cell);
        if (depths.x < frame.forward.w + near_reach || depths.y > frame.right.w - far_reach) continue;
        return k;
    }
    return 0u;
}

// The world box holding every footprint of brick b's node of tree level k (0: the brick) drawn
// with cells `cell` voxels a side: its voxel centres' box widened by the footprint reach at its far
// side (anti-aliasing widens with depth).
void footprint_box(uvec3 b, uint k, float cell, out vec3 lo, out vec3 hi) {
    voxel_box(b, k, lo, hi);
    float reach = cull_reach(box_depths(lo, hi).y, cell);
    lo -= reach;
    hi += reach;
}

// Whether the footprints of brick b's node of tree level k (0: the brick) all miss the view: its
// footprint box lies beyond the near or far plane, or wholly outside one side plane. Not with
// motion blur (a blurred quad reaches back along its path).
bool outside_view(uvec3 b, uint k, float cell) {
    if (frame.blur.x > 0.0) return false;
    vec3 lo;
    vec3 hi;
    footprint_box(b, k, cell, lo, hi);
    float dmin = 1e30;
    float dmax = -1e30;
    bool front = true;
    uvec4 out_lo = uvec4(1u);  // every corner beyond x = -w, x = w, y = -w, y = w
    for (uint c = 0u; c < 8u; ++c) {
        vec3 p = mix(lo, hi, vec3(uvec3(c, c >> 1u, c >> 2u) & 1u));
        float d = dot(p - frame.eye.xyz, frame.forward.xyz);
        dmin = min(dmin, d);
        dmax = max(dmax, d);
        vec4 q = frame.view_proj * vec4(p, 1.0);
        front = front && q.w > 0.0;
        out_lo &= uvec4(q.x < -q.w, q.x > q.w, q.y < -q.w, q.y > q.w);
    }
    if (dmax < frame.forward.w || dmin > frame.right.w) return true;
    // Clipping planes: the whole footprint box outside one of them.
    for (uint i = 0u; i < frame.rect.y; ++i) {
        bool out_all = true;
        for (uint c = 0u; c < 8u; ++c) {
            vec3 p = mix(lo, hi, vec3(uvec3(c, c >> 1u, c >> 2u) & 1u));
            out_all = out_all && dot(frame.clip[i].xyz, p) + frame.clip[i].w < 0.0;
        }
        if (out_all) return true;
    }
    return front && any(notEqual(out_lo, uvec4(0u)));
}

// Brick b's position among the bricks of the box lo..hi visited front to back as an octree of
// aligned blocks (2^l bricks a side at multiples of 2^l, clipped to the box), from the smallest
// holding the box: at each block its 8 children in PBTF order for the eye's brick split s
// (dense_pbtf over 2 x 2 x 2, a child on the low side when its lowest brick is). A visibility order
// for the same reason PBTF is (two 6-adjacent bricks are ordered by the children their lowest
// common block splits them into, across the plane between them), in which every aligned block
// inside the box is consecutive, so a node above the brick can stand at any of its bricks' places.
// Mirror: cpu::brick::octree_pbtf.
uint octree_pbtf(uvec3 b, uvec3 lo, uvec3 hi, uvec3 s) {
    uint l = 0u;
    while (any(notEqual(lo >> l, (hi - 1u) >> l))) l++;
    uvec3 o = (lo >> l) << l;
    uint p = 0u;
    for (; l > 0u; --l) {
        uint half_side = 1u << (l - 1u);
        uvec3 cs = uvec3(clamp((ivec3(s) - ivec3(o) + int(half_side) - 1) / int(half_side), 0, 2));
        uvec3 mine = uvec3(greaterThanEqual(b, o + half_side));
        uint rank = dense_pbtf(mine, uvec3(2u), cs);
        for (uint d = 0u; d < 8u; ++d) {
            uvec3 c = uvec3(d, d >> 1u, d >> 2u) & 1u;
            if (dense_pbtf(c, uvec3(2u), cs) >= rank) continue;
            uvec3 clo = max(o + c * half_side, lo);
            uvec3 chi = min(o + (c + 1u) * half_side, hi);
            if (all(lessThan(clo, chi))) {
                uvec3 e = chi - clo;
                p += e.x * e.y * e.z;
            }
        }
        o += mine * half_side;
    }
    return p;
}

// Brick b's position in the draw order of the brick grid: the k-d tree's (after the brick index;
// kdtree.rs), front to back: every node's near side first, its leaves' boxes as octrees
// (octree_pbtf); reversed back to front.
// Mirror: cpu::brick::tree_pbtf.
uint brick_slot(uvec3 b) {
    uint total = bf.grid.x * bf.grid.y * bf.grid.z;
    uvec3 lo = uvec3(0u), hi = bf.grid.xyz;
    uint p = 0u;
    uint n = bf.lo.w > 0u ? 0u : 0xffffffffu;
    while (n != 0xffffffffu) {
        uint code = brick_index[total + 4u * n];
        uint axis = code & 3u, plane = code >> 2u;
        bool high = b[axis] >= plane;
        if (high == (plane >= bf.split[axis])) {
            uvec3 e = hi - lo;
            e[axis] = high ? plane - lo[axis] : hi[axis] - plane;
            p += e.x * e.y * e.z;
        }
        if (high) lo[axis] = plane; else hi[axis] = plane;
        n = brick_index[total + 4u * n + (high ? 2u : 1u)];
    }
    p += octree_pbtf(b, lo, hi, bf.split.xyz);
    return frame.split.w != 0u ? total - 1u - p : p;
}
