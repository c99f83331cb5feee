// Shared by the tile binning stages (tile_count, tile_scatter): the screen tiles a draw-list
// entry's footprint box overlaps. Mirror: src/cpu/tile.rs (tile_range).
uvec2 tile_grid() {
    const uvec2 TILE = uvec2(RASTER_TILE_W, RASTER_TILE_H);
    return (uvec2(frame.blur.zw) + TILE - 1u) / TILE;
}

// The splat's footprint in screen space (an empty box when it covers no pixel).
ScreenQuad screen_record(SplatParams p) {
    mat3 inv;
    ivec4 box;
    ScreenQuad q;
    bool on = screen_quad(p, inv, box);
    q.inv0 = vec4(inv[0][0], inv[1][0], inv[2][0], p.axis_v.w);
    q.inv1 = vec4(inv[0][1], inv[1][1], inv[2][1], p.screen.y);
    q.inv2 = vec4(inv[0][2], inv[1][2], inv[2][2], p.screen.x);
    q.box = on ? box : ivec4(0, 0, -1, -1);
    q.emit = vec4(p.emit.rgb, p.emit.a * p.axis_u.w);
    return q;
}

// Inclusive tile range (x0, y0, x1, y1) of a footprint box; false when the box is empty.
bool tile_range(ivec4 box, out uvec4 tiles) {
    tiles = uvec4(max(box, ivec4(0))) / uvec4(RASTER_TILE_W, RASTER_TILE_H, RASTER_TILE_W, RASTER_TILE_H);
    return box.x <= box.z && box.y <= box.w;
}

// Entries [begin, end) of a binning chunk.
uvec2 chunk_entries(uint chunk) {
    uint size = (pc.count + pc.chunks - 1u) / pc.chunks;
    return uvec2(min(chunk * size, pc.count), min((chunk + 1u) * size, pc.count));
}
