#version 450
// Compute per-splat compositing: one workgroup per RASTER_TILE² screen tile and one invocation per
// tile row (llvmpipe runs the rows as the lanes of one SIMD group). Every row walks the tile's list
// in draw-list (PBTF) order; for each footprint it visits only the pixels of its row inside the
// footprint's box and composites them front to back (under) or back to front (over). Front to
// back, a pixel stops once its transmittance is at most pc.occluded and the row stops when all its
// pixels have (early termination): no pixel then differs by more than that threshold.
// Per-pixel tests of every entry (one invocation per pixel) cost llvmpipe ~5x more.
// Mirror: cpu::tile::tile_composite.
#extension GL_KHR_shader_subgroup_vote : require
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"

layout(local_size_x = RASTER_TILE) in;
layout(std430, binding = 10) readonly buffer TileStart { uint tile_start[]; };
layout(std430, binding = 11) readonly buffer TileEntries { uint tile_entries[]; };
layout(binding = 12, rgba32f) uniform writeonly image2D accum;
layout(std430, binding = 13) readonly buffer Quads { ScreenQuad quads[]; };

void main() {
    uvec2 size = uvec2(frame.blur.zw);
    int x0 = int(gl_WorkGroupID.x * RASTER_TILE);
    int y = int(gl_WorkGroupID.y * RASTER_TILE + gl_LocalInvocationID.x);
    int x_end = min(x0 + int(RASTER_TILE), int(size.x)) - 1;
    uint tiles_x = (size.x + RASTER_TILE - 1u) / RASTER_TILE;
    uint tile = gl_WorkGroupID.y * tiles_x + gl_WorkGroupID.x;
    uint end = tile_start[tile + 1u];
    bool btf = pc.back_to_front != 0u;
    bool terminate = !btf && pc.occluded > 0.0;
    vec4 acc[RASTER_TILE];
    for (uint i = 0u; i < RASTER_TILE; ++i) acc[i] = vec4(0.0);
    // Pixels of this row still open (all of them when not terminating early).
    int open = y < int(size.y) ? x_end - x0 + 1 : 0;
    // The loop stays uniform across the rows (no divergent continue or exit), so the compiler
    // loads each entry once for all of them instead of once per lane.
    for (uint k = tile_start[tile]; k < end; ++k) {
        if (terminate && subgroupAll(open == 0)) break;
        ScreenQuad q = quads[tile_entries[k]];
        bool row = y >= q.box.y && y <= q.box.w;
        // A fixed trip count unrolls, so acc[] stays in registers (an indexed private array costs
        // llvmpipe a gather and a scatter per access).
        for (int i = 0; i < int(RASTER_TILE); ++i) {
            int x = x0 + i;
            vec4 a = acc[i];
            vec3 p = vec3(float(x) + 0.5, float(y) + 0.5, 1.0);
            vec2 uv = vec2(dot(q.inv0.xyz, p), dot(q.inv1.xyz, p)) / dot(q.inv2.xyz, p);
            bool live = row && x >= q.box.x && x <= q.box.z && abs(uv.x) <= 1.0 && abs(uv.y) <= 1.0 &&
                        (!terminate || 1.0 - a.a > pc.occluded);
            if (live) {
                float tau = q.emit.a * footprint_weight(slices, false, uv, q.inv0.w, vec2(0.0));
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
        }
    }
    for (int i = 0; i < int(RASTER_TILE); ++i) {
        if (y < int(size.y) && x0 + i <= x_end) imageStore(accum, ivec2(x0 + i, y), acc[i]);
    }
}
