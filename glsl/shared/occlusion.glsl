// The occlusion map that tile_occlusion builds from the accumulation image after each wave of a
// bricked frame drawn front to back, a pyramid of two levels over the composite tiles (8 x 8
// pixels): entries 0..tiles hold each tile's largest transmittance left (a float), then two words
// per tile its open pixels, one bit each (row-major within the tile, rows 0-3 in the first word):
// those with more transmittance left than the termination threshold. The includer declares `frame`
// and `float occlusion[]`. Mirror: cpu::tile_occlusion::box_hidden.

// Most composite tiles a box may span and still be tested (larger ones are always drawn).
const int MAX_BOX_TILES = 256;

// Whether no pixel of the inclusive pixel box is open: the tile compositor, which stops a pixel
// once its transmittance falls to the threshold, would draw nothing in it.
bool box_hidden(ivec4 box) {
    ivec2 size = ivec2(frame.blur.zw);
    int side = int(COMPOSITE_TILE);
    int tiles_x = (size.x + side - 1) / side;
    int tiles = tiles_x * ((size.y + side - 1) / side);
    box = clamp(box, ivec4(0), ivec4(size - 1, size - 1));
    ivec2 t0 = box.xy / side;
    ivec2 t1 = box.zw / side;
    if ((t1.x - t0.x + 1) * (t1.y - t0.y + 1) > MAX_BOX_TILES) return false;
    for (int ty = t0.y; ty <= t1.y; ++ty) {
        for (int tx = t0.x; tx <= t1.x; ++tx) {
            uint t = uint(ty * tiles_x + tx);
            uvec2 open = uvec2(floatBitsToUint(occlusion[tiles + 2u * t]), floatBitsToUint(occlusion[tiles + 2u * t + 1u]));
            if ((open.x | open.y) == 0u) continue;
            // The box's part of the tile, as a mask of the same layout.
            ivec2 a = max(box.xy, ivec2(tx, ty) * side) - ivec2(tx, ty) * side;
            ivec2 b = min(box.zw, ivec2(tx, ty) * side + side - 1) - ivec2(tx, ty) * side;
            uint row = ((1u << uint(b.x - a.x + 1)) - 1u) << uint(a.x);
            uvec2 part = uvec2(0u);
            for (int y = a.y; y <= b.y; ++y) {
                if (y < 4) part.x |= row << uint(8 * y);
                else part.y |= row << uint(8 * (y - 4));
            }
            if (((open.x & part.x) | (open.y & part.y)) != 0u) return false;
        }
    }
    return true;
}
