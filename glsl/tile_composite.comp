#version 450
// Compute per-splat compositing: one workgroup per RASTER_TILE² screen tile, one invocation per
// pixel, walks the tile's list in draw-list (PBTF) order in batches: the workgroup stages a batch's
// footprints (projective map, pixel box, colour, optical depth) in shared memory, then every pixel
// composites them front to back (under) or back to front (over). Front to back, a pixel stops once
// its transmittance is at most pc.occluded and the tile stops when all its pixels have (early
// termination); no pixel then differs by more than that threshold. Mirror: cpu::tile::tile_composite.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"

layout(local_size_x = RASTER_TILE, local_size_y = RASTER_TILE) in;
layout(std430, binding = 10) readonly buffer TileStart { uint tile_start[]; };
layout(std430, binding = 11) readonly buffer TileEntries { uint tile_entries[]; };
layout(binding = 12, rgba32f) uniform writeonly image2D accum;

const uint BATCH = RASTER_TILE * RASTER_TILE;
shared vec3 s_inv0[BATCH];
shared vec3 s_inv1[BATCH];
shared vec3 s_inv2[BATCH];
shared ivec4 s_box[BATCH];
shared vec4 s_emit[BATCH];    // rgb, optical depth scale (tau x energy)
shared float s_stretch[BATCH];
shared uint s_live;

void main() {
    uvec2 size = uvec2(frame.blur.zw);
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    bool inside = px.x < int(size.x) && px.y < int(size.y);
    uint tiles_x = (size.x + RASTER_TILE - 1u) / RASTER_TILE;
    uint tile = gl_WorkGroupID.y * tiles_x + gl_WorkGroupID.x;
    uint start = tile_start[tile];
    uint end = tile_start[tile + 1u];
    uint lid = gl_LocalInvocationIndex;
    bool btf = pc.back_to_front != 0u;
    bool terminate = !btf && pc.occluded > 0.0;
    vec4 acc = vec4(0.0);
    for (uint base = start; base < end; base += BATCH) {
        if (base + lid < end) {
            SplatParams p = params[tile_entries[base + lid]];
            mat3 inv;
            ivec4 box;
            screen_quad(p, inv, box);
            s_inv0[lid] = vec3(inv[0][0], inv[1][0], inv[2][0]);
            s_inv1[lid] = vec3(inv[0][1], inv[1][1], inv[2][1]);
            s_inv2[lid] = vec3(inv[0][2], inv[1][2], inv[2][2]);
            s_box[lid] = box;
            s_emit[lid] = vec4(p.emit.rgb, p.emit.a * p.axis_u.w);
            s_stretch[lid] = p.axis_v.w;
        }
        barrier();
        uint m = min(BATCH, end - base);
        bool live = inside && (!terminate || 1.0 - acc.a > pc.occluded);
        for (uint j = 0u; live && j < m; ++j) {
            ivec4 box = s_box[j];
            if (px.x < box.x || px.x > box.z || px.y < box.y || px.y > box.w) continue;
            vec3 q = vec3(vec2(px) + 0.5, 1.0);
            float h = dot(s_inv2[j], q);
            vec2 uv = vec2(dot(s_inv0[j], q), dot(s_inv1[j], q)) / h;
            if (abs(uv.x) > 1.0 || abs(uv.y) > 1.0) continue;
            float tau = s_emit[j].a * footprint_weight(table, slices, false, uv, s_stretch[j], vec2(0.0));
            if (tau <= 0.0) continue;
            float a = 1.0 - exp(-tau);
            vec4 src = vec4(s_emit[j].rgb * a, a);
            if (btf) {
                acc = src + (1.0 - a) * acc;
            } else {
                acc += (1.0 - acc.a) * src;
                live = !terminate || 1.0 - acc.a > pc.occluded;
            }
        }
        if (terminate) {
            // The whole tile stops once none of its pixels has transmittance left.
            if (lid == 0u) s_live = 0u;
            barrier();
            if (inside && 1.0 - acc.a > pc.occluded) atomicOr(s_live, 1u);
            barrier();
            if (s_live == 0u) break;
        }
        barrier();
    }
    if (inside) imageStore(accum, px, acc);
}
