#version 450
// Compute per-splat compositing: one workgroup per screen tile of RASTER_TILE_H rows by RASTER_TILE_W
// columns, run as the RASTER_LANES lanes of one SIMD group: lane (row, phase) owns the columns
// phase, phase + RASTER_PHASES, ... of its row (src/constants.rs). Every lane walks the tile's list
// in draw-list (PBTF) order; for each footprint it visits only its pixels inside the footprint's
// box and composites them front to back (under) or back to front (over). Front to
// back, a pixel stops once its transmittance is at most pc.occluded and the tile stops when all its
// pixels have (early termination): no pixel then differs by more than that threshold.
// A dispatch takes TILE_SEGMENT entries of each list (segment pc.first), carrying the accumulators
// in the image between segments: llvmpipe silently ends every loop once an invocation has made
// 65535 loop iterations in all, which longer lists would pass.
// Per-pixel tests of every entry (one invocation per pixel) cost llvmpipe ~5x more.
// Mirror: cpu::tile::tile_composite.
// ONE_PAGE: scenes of at most SPLAT_PAGE splats read the first page only (types.glsl).
// variants: SHUFFLE ONE_PAGE SHUFFLE+ONE_PAGE
#extension GL_KHR_shader_subgroup_vote : require
#ifdef SHUFFLE
// llvmpipe loads a buffer lane by lane, so every row loading the same entry costs eight loads;
// instead each lane loads one entry of a batch and the batch is passed round by shuffles (~1.3x).
#extension GL_KHR_shader_subgroup_shuffle : require
#endif
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"

layout(local_size_x = RASTER_LANES) in;
// The direction and early termination are fixed per pipeline (llvmpipe runs both sides of a branch
// on a push constant: ~5 % here); the push constants carry the same for the CPU mirror.
layout(constant_id = 1) const bool BACK_TO_FRONT = false;
layout(constant_id = 2) const bool TERMINATE = false;  // front to back, pc.occluded > 0
// Whether the frame is motion-blurred (else every splat's stretch is 0: one shuffle and the
// stretch's arithmetic per pixel less).
layout(constant_id = 3) const bool MOTION_BLUR = true;
layout(std430, binding = 10) readonly buffer TileStart { uint tile_start[]; };
layout(std430, binding = 11) readonly buffer TileEntries { uint tile_entries[]; };
layout(binding = 12, rgba32f) uniform image2D accum;
layout(std430, binding = 13) readonly buffer Quads { ScreenQuad quads_lo[]; };
layout(std430, binding = 16) readonly buffer QuadsHi { ScreenQuad quads_hi[]; };
PAGED_READER(ScreenQuad, quads_at, quads_lo, quads_hi)

void main() {
    uvec2 size = uvec2(frame.blur.zw);
    int tx0 = int(gl_WorkGroupID.x * RASTER_TILE_W);
    int y = int(gl_WorkGroupID.y * RASTER_TILE_H + gl_LocalInvocationID.x / RASTER_PHASES);
    // This lane's column i is x0 + i * RASTER_PHASES.
    int x0 = tx0 + int(gl_LocalInvocationID.x % RASTER_PHASES);
    int x_end = min(tx0 + int(RASTER_TILE_W), int(size.x)) - 1;
    uint tiles_x = (size.x + RASTER_TILE_W - 1u) / RASTER_TILE_W;
    uint tile = gl_WorkGroupID.y * tiles_x + gl_WorkGroupID.x;
    uint list_end = tile_start[tile + 1u];
    uint begin = tile_start[tile] + pc.first * TILE_SEGMENT;
    // A later segment with nothing of this list leaves its pixels as they are.
    if (pc.first > 0u && begin >= list_end) return;
    uint end = min(list_end, begin + TILE_SEGMENT);
    const bool btf = BACK_TO_FRONT;
    const bool terminate = !btf && TERMINATE;
    vec4 acc[RASTER_COLUMNS];
    // The lane's last column in the image (-1: none).
    int d = x_end - x0;
    int i_last = y < int(size.y) && d >= 0 ? d / int(RASTER_PHASES) : -1;
    // Pixels of this lane still open (all of them when not terminating early).
    int open = 0;
    for (int i = 0; i < int(RASTER_COLUMNS); ++i) {
        int x = x0 + i * int(RASTER_PHASES);
        bool inside = y < int(size.y) && x <= x_end;
        acc[i] = pc.first > 0u && inside ? imageLoad(accum, ivec2(x, y)) : vec4(0.0);
        open += inside && (!terminate || 1.0 - acc[i].a > pc.occluded) ? 1 : 0;
    }
#ifdef SHUFFLE
    // A workgroup narrower than its subgroup fills the subgroup's first lanes.
    uint lane = gl_SubgroupInvocationID;
    uint batch = min(gl_SubgroupSize, RASTER_LANES);
#else
    uint batch = 1u;
#endif
    // The loops stay uniform across the rows (no divergent continue or exit), so every entry is
    // loaded once for all of them. A closed pixel takes no more entries, so testing for early
    // termination once per batch changes no pixel.
    for (uint k0 = begin; k0 < end; k0 += batch) {
        if (terminate && subgroupAll(open == 0)) break;
#ifdef SHUFFLE
        ScreenQuad mine;
        if (lane < batch && k0 + lane < end) {
            uint e = tile_entries[k0 + lane];
            mine = quads_at(e);
        }
        // Box corners are at most 16383 (camera.rs, MAX_IMAGE_SIDE): two shuffles instead of four.
        uvec2 box_packed = uvec2(mine.box.xy) | (uvec2(mine.box.zw) << 16);
        uint n = min(batch, end - k0);
#else
        uint n = 1u;
#endif
        // do-while, here and below: llvmpipe runs the body of a loop once more, masked, for the test
        // that ends it at the top; tested at the bottom it ends right away (n >= 1 and every entry's
        // box meets the tile, so both loops take at least one pass).
        uint j = 0u;
        do {
#ifdef SHUFFLE
            ScreenQuad q;
            q.inv0.xyz = subgroupShuffle(mine.inv0.xyz, j);
            q.inv0.w = MOTION_BLUR ? subgroupShuffle(mine.inv0.w, j) : 0.0;
            q.inv1.xyz = subgroupShuffle(mine.inv1.xyz, j);
            q.inv2.xyz = subgroupShuffle(mine.inv2.xyz, j);
            uvec2 b = subgroupShuffle(box_packed, j);
            q.box = ivec4(b & 0xffffu, b >> 16);
            q.emit = subgroupShuffle(mine.emit, j);
#else
            uint e = tile_entries[k0];
            ScreenQuad q = quads_at(e);
            if (!MOTION_BLUR) q.inv0.w = 0.0;
#endif
            bool row = y >= q.box.y && y <= q.box.w;
            // Only the box's columns: llvmpipe runs a masked branch whatever its mask, so a column
            // outside the box would cost as much as one inside. The index into acc[] is then not a
            // constant (a gather and a scatter per access), still 1.5x cheaper at 3 px, and at 7 px
            // once the loops are tested at the bottom (~1.25x with it). The steps cover the box's
            // columns for every phase, so a lane's first or last step may fall outside the box.
            int i1 = (min(q.box.z, x_end) - tx0) / int(RASTER_PHASES);
            int i = (max(q.box.x, tx0) - tx0) / int(RASTER_PHASES);
            // Homogeneous quad coordinates of the lane's pixel, stepped RASTER_PHASES columns at a time.
            vec3 p = vec3(float(x0 + i * int(RASTER_PHASES)) + 0.5, float(y) + 0.5, 1.0);
            vec3 h = vec3(dot(q.inv0.xyz, p), dot(q.inv1.xyz, p), dot(q.inv2.xyz, p));
            vec3 dh = float(RASTER_PHASES) * vec3(q.inv0.x, q.inv1.x, q.inv2.x);
            do {
                vec4 a = acc[i];
                vec2 uv = h.xy * (1.0 / h.z);
                float s = footprint_r2(uv, MOTION_BLUR ? q.inv0.w : 0.0);
                // No test against the box or the quad: beyond the footprint's disc (or its blur's
                // capsule) the radial table is exactly 0, which leaves a pixel as it is, and every
                // pixel outside the quad has s > 1 (behind the quad plane's horizon too); `s < 1`
                // also rejects a NaN there. Early termination counts only the lane's pixels.
                bool live = row && s < 1.0 && (!terminate || (i <= i_last && 1.0 - a.a > pc.occluded));
                if (live) {
                    float tau = q.emit.a * sample_radial(s);
                    float alpha = 1.0 - exp(-tau);
                    vec4 src = vec4(q.emit.rgb * alpha, alpha);
                    if (btf) {
                        a = src + (1.0 - alpha) * a;
                    } else {
                        a += (1.0 - a.a) * src;
                        if (terminate && 1.0 - a.a <= pc.occluded) open -= 1;
                    }
                    acc[i] = a;
                }
                h += dh;
            } while (++i <= i1);
        } while (++j < n);
    }
    for (int i = 0; i < int(RASTER_COLUMNS); ++i) {
        int x = x0 + i * int(RASTER_PHASES);
        if (y < int(size.y) && x <= x_end) imageStore(accum, ivec2(x, y), acc[i]);
    }
}
