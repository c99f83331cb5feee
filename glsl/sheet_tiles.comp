#version 450
// Sheet modes: for each composite tile, the range of sheets (global ranks; slab mode: slabs) whose
// footprints may reach it, so composite.comp visits only those layers of each batch instead of
// every layer at every pixel. One invocation per entry of the frame's whole sheet list (all
// batches), run once per frame. Each footprint's pixel box is grown by a pixel, so no rounding
// in the rasteriser can put a fragment on a tile the range leaves out.
// Mirror: cpu::sheet_tiles.
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
// 1: the raster draws point sprites (screen-aligned squares 2r wide), 0: quads or compute sums.
layout(constant_id = 1) const uint POINTS = 0u;
// [0, tiles): lowest sheet reaching the tile (~0u: none); [tiles, 2 tiles): highest sheet + 1.
layout(std430, binding = 14) buffer SheetTiles { uint sheet_tiles[]; };

void main() {
    uint e = linear_invocation();
    if (e >= pc.count) return;
    uint splat = entry_splat(e);
    SplatParams p = params_at(splat);
    vec2 faces;
    // The push constant's rank_base = 0 and rank_dir = +1 make this the sheet's global rank.
    int sheet = entry_layer(e, splat, p, faces);
    if (p.center.w == 0.0 || sheet < 0) return;
    vec2 size = frame.blur.zw;
    ivec4 box;
    if (POINTS != 0u) {
        vec4 c = frame.view_proj * vec4(p.center.xyz, 1.0);
        if (c.w <= 0.0) return;
        vec2 s = clamp((c.xy / c.w * 0.5 + 0.5) * size, vec2(-1e6), vec2(1e6));
        float half_size = max(p.screen.z, 0.5);
        box = ivec4(floor(s - half_size), floor(s + half_size));
    } else {
        mat3 inv;
        if (!screen_quad(p, inv, box)) return;
    }
    ivec2 last = ivec2(size) - 1;
    if (box.x > last.x + 1 || box.y > last.y + 1 || box.z < -1 || box.w < -1) return;
    ivec2 lo = clamp(box.xy - 1, ivec2(0), last);
    ivec2 hi = clamp(box.zw + 1, ivec2(0), last);
    uvec2 t0 = uvec2(lo) / COMPOSITE_TILE, t1 = uvec2(hi) / COMPOSITE_TILE;
    uint tiles_x = (uint(size.x) + COMPOSITE_TILE - 1u) / COMPOSITE_TILE;
    uint tiles = tiles_x * ((uint(size.y) + COMPOSITE_TILE - 1u) / COMPOSITE_TILE);
    for (uint y = t0.y; y <= t1.y; ++y) {
        for (uint x = t0.x; x <= t1.x; ++x) {
            uint t = y * tiles_x + x;
            atomicMin(sheet_tiles[t], uint(sheet));
            atomicMax(sheet_tiles[tiles + t], uint(sheet) + 1u);
        }
    }
}
