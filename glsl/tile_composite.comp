#version 450
// Compute per-splat compositing: one workgroup per screen tile of RASTER_TILE_H rows by RASTER_TILE_W
// columns, run as the RASTER_LANES lanes of one SIMD group, the tile's accumulators in shared
// memory. The lanes walk the tile's list in draw-list (PBTF) order; for each footprint they deal
// out the pixels of its box inside the tile, RASTER_LANES at a time, and composite them front to
// back (under) or back to front (over); each entry ends with a barrier, since a pixel may pass
// to another lane with the next one. Front to back, a pixel stops once its transmittance is at
// most pc.occluded and the tile stops when all its pixels have (early termination): no pixel then
// differs by more than that threshold.
// A dispatch takes TILE_SEGMENT entries of each list (segment pc.first), carrying the accumulators
// in the image between segments: llvmpipe silently ends every loop once an invocation has made
// 65535 loop iterations in all, which longer lists would pass.
// Per-pixel tests of every entry (one invocation per pixel) cost llvmpipe ~5x more; a lane per row
// (or per row and column parity) with private accumulators took 1.4x more steps at 7 px.
// Mirror: cpu::tile::tile_composite.
// ONE_PAGE: scenes of at most SPLAT_PAGE splats read the first page only (types.glsl).
// variants: SHUFFLE ONE_PAGE SHUFFLE+ONE_PAGE
#ifdef SHUFFLE
// llvmpipe loads a buffer lane by lane, so every lane loading the same entry costs eight loads;
// instead each lane loads one entry of a batch and the batch is passed round by shuffles (~1.3x).
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_arithmetic : require
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
// A projection mode's blend (BLEND_*, types.glsl): order-independent, by maximum or sum; or one of
// the isosurface's two passes (BLEND_SURFACE_DEPTH, then BLEND_SURFACE over the same lists).
layout(constant_id = 4) const uint PROJECT = BLEND_COMPOSITE;
// The host's depth hides the splats behind it (frame.rect.w is then 1; a build of its own, since
// llvmpipe pays for a branch on a uniform even where it is never taken: 4.5 % here).
layout(constant_id = 5) const bool HOST_DEPTH = false;
layout(std430, binding = 10) readonly buffer TileStart { uint tile_start[]; };
layout(std430, binding = 11) readonly buffer TileEntries { uint tile_entries[]; };
layout(binding = 12, rgba32f) uniform image2D accum;
layout(std430, binding = 13) readonly buffer Quads { ScreenQuad quads_lo[]; };
layout(std430, binding = 16) readonly buffer QuadsHi { ScreenQuad quads_hi[]; };
// The host's eye-space depth per pixel (frame.rect.w = 1): a splat deeper than it adds nothing there.
layout(std430, binding = 18) readonly buffer HostDepth { float host_depth[]; };
PAGED_READER(ScreenQuad, quads_at, quads_lo, quads_hi)

const uint TILE_PIXELS = RASTER_TILE_W * RASTER_TILE_H;
// The least weight, over a footprint's centre's, of a surface disc that makes a pixel's visible
// depth (mirror: cpu::tile_composite::SURFACE_VISIBLE).
const float SURFACE_VISIBLE = 0.1;
// The first pass's depth where no disc is visible.
const float NO_SURFACE = 3.0e38;
// The tile's accumulators, pixel (x, y) of the tile at y * RASTER_TILE_W + x.
shared vec4 tile_acc[TILE_PIXELS];

// Between entries a pixel may pass from one lane to another. With subgroup operations the
// workgroup is one subgroup (Context::subgroup_shuffle: this build only where a subgroup holds
// RASTER_LANES).
void sync_lanes() {
#ifdef SHUFFLE
    subgroupBarrier();
#else
    barrier();
#endif
}

// Pixel t of the tile whose first pixel is t0 (row-major), in image coordinates.
ivec2 tile_pixel(ivec2 t0, uint t) {
    return t0 + ivec2(t % RASTER_TILE_W, t / RASTER_TILE_W);
}

#ifndef SHUFFLE
// The tile's open pixels, without subgroup arithmetic to sum the lanes' counts.
shared int tile_open;
#endif

void main() {
    uvec2 size = uvec2(frame.blur.zw);
    uint lane = gl_LocalInvocationID.x;
    ivec2 t0 = ivec2(gl_WorkGroupID.xy * uvec2(RASTER_TILE_W, RASTER_TILE_H));
    // The tile's last pixel inside the image.
    ivec2 t1 = min(t0 + ivec2(RASTER_TILE_W, RASTER_TILE_H), ivec2(size)) - 1;
    uint tiles_x = (size.x + RASTER_TILE_W - 1u) / RASTER_TILE_W;
    uint tile = gl_WorkGroupID.y * tiles_x + gl_WorkGroupID.x;
    uint list_end = tile_start[tile + 1u];
    uint begin = tile_start[tile] + pc.first * TILE_SEGMENT;
    // A later segment, or any segment of a later batch of a bricked volume (carry 1), carries
    // on from the image; with nothing of this list it leaves its pixels as they are.
    bool carry = pc.first > 0u || pc.carry != 0u;
    if (carry && begin >= list_end) return;
    uint end = min(list_end, begin + TILE_SEGMENT);
    const bool btf = BACK_TO_FRONT;
    bool swept = MOTION_BLUR && frame.sweep.y != float(SWEEP_UNIFORM);
    const bool depth_test = HOST_DEPTH;
    const bool surface = PROJECT == BLEND_SURFACE || PROJECT == BLEND_SURFACE_DEPTH;
    const bool terminate = !btf && TERMINATE;
    // Pixels still open, counted by the lanes that opened or closed them (only their sum means
    // anything).
    int open = 0;
    for (uint t = lane; t < TILE_PIXELS; t += RASTER_LANES) {
        ivec2 xy = tile_pixel(t0, t);
        bool inside = all(lessThanEqual(xy, t1));
        vec4 a = carry && inside ? imageLoad(accum, xy) : vec4(0.0, 0.0, 0.0, PROJECT == BLEND_SURFACE_DEPTH ? NO_SURFACE : 0.0);
        tile_acc[t] = a;
        open += inside && (!terminate || 1.0 - a.a > pc.occluded) ? 1 : 0;
    }
#ifndef SHUFFLE
    if (lane == 0u) tile_open = 0;
    barrier();
    atomicAdd(tile_open, open);
#endif
    sync_lanes();
#ifdef SHUFFLE
    // A workgroup narrower than its subgroup fills the subgroup's first lanes.
    uint batch = min(gl_SubgroupSize, RASTER_LANES);
#else
    uint batch = 1u;
#endif
    // The loops stay uniform across the lanes (no divergent continue or exit). A closed pixel
    // takes no more entries, so testing for early termination once per batch changes no pixel.
    for (uint k0 = begin; k0 < end; k0 += batch) {
#ifdef SHUFFLE
        if (terminate && subgroupAdd(open) == 0) break;
#else
        if (terminate) {
            // Every lane reads the count before any lane may change it again: the exit stays uniform.
            bool closed = tile_open == 0;
            barrier();
            if (closed) break;
        }
#endif
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
            q.inv0.w = MOTION_BLUR || surface ? subgroupShuffle(mine.inv0.w, j) : 0.0;
            q.inv1.xyz = subgroupShuffle(mine.inv1.xyz, j);
            q.inv1.w = MOTION_BLUR || surface ? subgroupShuffle(mine.inv1.w, j) : 0.0;
            q.inv2.xyz = subgroupShuffle(mine.inv2.xyz, j);
            if (depth_test || surface) q.inv2.w = subgroupShuffle(mine.inv2.w, j);
            uvec2 b = subgroupShuffle(box_packed, j);
            q.box = ivec4(b & 0xffffu, b >> 16);
            q.emit = subgroupShuffle(mine.emit, j);
#else
            uint e = tile_entries[k0];
            ScreenQuad q = quads_at(e);
            if (!MOTION_BLUR && !surface) q.inv0.w = q.inv1.w = 0.0;
#endif
            // The box's pixels inside the tile, dealt to the lanes in turn: every lane works on
            // every step but the last (a lane per row or column would idle on rows or columns the
            // box misses).
            ivec2 b0 = max(q.box.xy, t0);
            ivec2 bw = min(q.box.zw, t1) - b0 + 1;
            uint count = uint(bw.x * bw.y);
            float inv_w = 1.0 / float(bw.x);
            // Homogeneous quad coordinates at the first pixel's centre and their steps.
            vec3 p = vec3(vec2(b0) + 0.5, 1.0);
            vec3 h0 = vec3(dot(q.inv0.xyz, p), dot(q.inv1.xyz, p), dot(q.inv2.xyz, p));
            vec3 hx = vec3(q.inv0.x, q.inv1.x, q.inv2.x);
            vec3 hy = vec3(q.inv0.y, q.inv1.y, q.inv2.y);
            uint base = uint(b0.y - t0.y) * RASTER_TILE_W + uint(b0.x - t0.x);
            uint t = lane;
            do {
                // Row and column of pixel t of the box (exact: t < 2^8, so the quotient's
                // fraction is at least 1 / (2 bw.x) from a whole number).
                float r = floor((float(t) + 0.5) * inv_w);
                float c = float(t) - r * float(bw.x);
                // Masked into the tile for the last step's lanes past the box (they change nothing).
                uint at = (base + uint(r) * RASTER_TILE_W + uint(c)) & (TILE_PIXELS - 1u);
                vec3 h = h0 + c * hx + r * hy;
                vec2 uv = h.xy * (1.0 / h.z);
                float s = footprint_r2(uv, MOTION_BLUR ? q.inv0.w : 0.0, MOTION_BLUR ? q.inv1.w : 0.0);
                vec4 a = tile_acc[at];
                // No test against the quad: beyond the footprint's disc (or its blur's capsule)
                // the radial table is exactly 0, which leaves a pixel as it is, and every pixel
                // outside the quad has s > 1 (behind the quad plane's horizon too); `s < 1` also
                // rejects a NaN there.
                bool live = t < count && s < 1.0 && (!terminate || 1.0 - a.a > pc.occluded);
                if (depth_test && live) {
                    ivec2 xy = b0 + ivec2(int(c), int(r));
                    live = q.inv2.w <= host_depth[uint(xy.y) * size.x + uint(xy.x)];
                }
                if (live && PROJECT == BLEND_MAX) {
                    // A footprint covers fully from PROJECT_FULL of its centre's weight: the key of
                    // the splat there, its coverage 1.
                    float w = min(sample_radial(s) / (PROJECT_FULL * radial[0].x), 1.0);
                    tile_acc[at] = max(a, vec4(q.emit.r * w, w, 0.0, 0.0));
                } else if (live && surface) {
                    // Surface splats (iso_splats), at their plane's depth here (the depth's steps
                    // along u and v in inv0.w, inv1.w). First pass: the pixel's visible depth, the
                    // nearest of the discs weighing at least SURFACE_VISIBLE of a centre's (a
                    // disc's fringe past a crease or a silhouette hides nothing); second pass: the
                    // discs within the band (emit.a) of it add their weighed shading.
                    float w = sample_radial(s);
                    float z = q.inv2.w + uv.x * q.inv0.w + uv.y * q.inv1.w;
                    if (PROJECT == BLEND_SURFACE_DEPTH) {
                        if (w >= SURFACE_VISIBLE * radial[0].x) tile_acc[at].w = min(a.w, z);
                    } else if (w > 0.0 && abs(z - a.w) <= q.emit.a) {
                        tile_acc[at] = vec4(a.xy + q.emit.xy * w, a.z + w, a.w);
                    }
                } else if (live && PROJECT == BLEND_SUM) {
                    float d = q.emit.a * sample_radial(s);
                    tile_acc[at] = a + vec4(q.emit.r * d, d, 0.0, 0.0);
                } else if (live) {
                    // A tapered or teardrop blur averages the moving footprint's alpha over time.
                    float alpha = swept ? footprint_value(slices, false, uv, vec3(q.inv0.w, q.inv1.w, frame.sweep.y),
                                                          vec2(0.0), q.emit.a, true)
                                        : 1.0 - exp(-q.emit.a * sample_radial(s));
                    vec4 src = vec4(q.emit.rgb * alpha, alpha);
                    if (btf) {
                        a = src + (1.0 - alpha) * a;
                    } else {
                        a += (1.0 - a.a) * src;
                        if (terminate && 1.0 - a.a <= pc.occluded) {
#ifdef SHUFFLE
                            open -= 1;
#else
                            atomicAdd(tile_open, -1);
#endif
                        }
                    }
                    tile_acc[at] = a;
                }
                t += RASTER_LANES;
            } while (t < count);
            sync_lanes();
        } while (++j < n);
    }
    for (uint t = lane; t < TILE_PIXELS; t += RASTER_LANES) {
        ivec2 xy = tile_pixel(t0, t);
        if (all(lessThanEqual(xy, t1))) imageStore(accum, xy, tile_acc[t]);
    }
}
