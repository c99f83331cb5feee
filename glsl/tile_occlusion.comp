#version 450
// The occlusion map (occlusion.glsl): per composite tile, the largest transmittance left in the
// accumulation image and the mask of its pixels still open (more transmittance left than the
// termination threshold). After a wave of a bricked volume drawn front to back, what brick_hidden
// tests the next wave's bricks and voxels against.
// Mirror: cpu::tile_occlusion.
#include "types.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(binding = 1, rgba32f) uniform readonly image2D accum;
layout(std430, binding = 2) writeonly buffer Occlusion { float occlusion[]; };

layout(push_constant) uniform Push {
    uint first;
    uint count;
    uint splats;
    float occluded;  // the early-termination threshold
} pc;

void main() {
    uint t = linear_invocation();
    ivec2 size = ivec2(frame.blur.zw);
    int tiles_x = (size.x + int(COMPOSITE_TILE) - 1) / int(COMPOSITE_TILE);
    int tiles_y = (size.y + int(COMPOSITE_TILE) - 1) / int(COMPOSITE_TILE);
    if (t >= uint(tiles_x * tiles_y)) return;
    ivec2 p0 = ivec2(int(t) % tiles_x, int(t) / tiles_x) * int(COMPOSITE_TILE);
    ivec2 p1 = min(p0 + int(COMPOSITE_TILE), size);
    uint tiles = uint(tiles_x * tiles_y);
    float most = 0.0;
    uvec2 open = uvec2(0u);
    for (int y = p0.y; y < p1.y; ++y) {
        for (int x = p0.x; x < p1.x; ++x) {
            float left = 1.0 - imageLoad(accum, ivec2(x, y)).a;
            most = max(most, left);
            uint bit = uint((y - p0.y) * int(COMPOSITE_TILE) + x - p0.x);
            if (left > pc.occluded) {
                if (bit < 32u) open.x |= 1u << bit;
                else open.y |= 1u << (bit - 32u);
            }
        }
    }
    occlusion[t] = most;
    occlusion[tiles + 2u * t] = uintBitsToFloat(open.x);
    occlusion[tiles + 2u * t + 1u] = uintBitsToFloat(open.y);
}
