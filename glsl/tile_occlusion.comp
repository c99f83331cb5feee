#version 450
// Per composite tile, the largest transmittance left in the accumulation image: after a batch of a
// bricked volume drawn front to back, what brick_hidden tests the next batch's bricks against.
// Mirror: cpu::brick::tile_occlusion.
#include "types.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
layout(std430, binding = 0) readonly buffer FrameBlock { Frame frame; };
layout(binding = 1, rgba32f) uniform readonly image2D accum;
layout(std430, binding = 2) writeonly buffer Occlusion { float occlusion[]; };

void main() {
    uint t = linear_invocation();
    ivec2 size = ivec2(frame.blur.zw);
    int tiles_x = (size.x + int(COMPOSITE_TILE) - 1) / int(COMPOSITE_TILE);
    int tiles_y = (size.y + int(COMPOSITE_TILE) - 1) / int(COMPOSITE_TILE);
    if (t >= uint(tiles_x * tiles_y)) return;
    ivec2 p0 = ivec2(int(t) % tiles_x, int(t) / tiles_x) * int(COMPOSITE_TILE);
    ivec2 p1 = min(p0 + int(COMPOSITE_TILE), size);
    float most = 0.0;
    for (int y = p0.y; y < p1.y; ++y) {
        for (int x = p0.x; x < p1.x; ++x) most = max(most, 1.0 - imageLoad(accum, ivec2(x, y)).a);
    }
    occlusion[t] = most;
}
