// Shared by the tile binning stages (tile_count, tile_scatter): the screen tiles a draw-list
// entry's footprint box overlaps. Mirror: src/cpu/tile.rs (tile_range).
uvec2 tile_grid() {
    return (uvec2(frame.blur.zw) + uvec2(RASTER_TILE - 1u)) / uvec2(RASTER_TILE);
}

// Inclusive tile range (x0, y0, x1, y1) of the splat's footprint; false when it covers no pixel.
bool tile_range(SplatParams p, out uvec4 tiles) {
    mat3 inv;
    ivec4 box;
    tiles = uvec4(0u);
    if (!screen_quad(p, inv, box)) return false;
    tiles = uvec4(box) / uvec4(RASTER_TILE);
    return true;
}

// Entries [begin, end) of a binning chunk.
uvec2 chunk_entries(uint chunk) {
    return uvec2(chunk * TILE_CHUNK, min((chunk + 1u) * TILE_CHUNK, pc.count));
}
