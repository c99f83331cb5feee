// Shared by the tile binning stages (tile_count, tile_scatter): the screen tiles a draw-list
// entry's footprint box overlaps. Mirror: src/cpu/tile.rs (tile_range).
uvec2 tile_grid() {
    const uvec2 TILE = uvec2(RASTER_TILE_W, RASTER_TILE_H);
    return (uvec2(frame.blur.zw) + TILE - 1u) / TILE;
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
