#version 450
// Footprint stage in compute, sheet modes: one invocation per draw-list entry of the batch walks
// its quad's pixel box, evaluates the footprint where the perspective-correct quad coordinates
// fall inside the quad (the pixels the rasteriser would shade) and adds (rgb * tau, tau) to its
// summation layer with fixed-point atomics: order-independent, so the sums are bit-identical run to
// run (float atomics would round differently with every interleaving). composite.comp reads the
// fixed-point layers directly (its SUMS_FIXED variant). Mirror: cpu::footprint_sum.
// variants: SUM64
// SUM64 (devices with shaderBufferInt64Atomics): two channels per 64-bit atomic, (r, g) and
// (b, tau), the same memory layout; llvmpipe runs each atomic lane by lane, so halving them makes
// the stage ~1.3x faster. A channel's sum would carry into its neighbour where a 32-bit sum would
// wrap, past 4096 units of optical depth in one pixel of one sheet.
#ifdef SUM64
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_ARB_gpu_shader_int64 : require
#endif
#define FOOTPRINT_COMPUTE
#include "footprint.glsl"

layout(local_size_x = WORKGROUP_SIZE) in;
#include "linear.glsl"
#ifdef SUM64
layout(std430, binding = 8) buffer Sums { uint64_t sums[]; };
#else
layout(std430, binding = 8) buffer Sums { uint sums[]; };
#endif

// llvmpipe ends every loop of an invocation once it has made 65535 iterations in all: a footprint
// box whose loops would pass LOOP_BUDGET (about 240 x 240 pixels) is not drawn but flagged (bit 2)
// for the host to refuse the frame (recording.rs).
layout(std430, binding = 17) buffer Status { uint loop_budget_spent; };

// One contribution in fixed point; clamped so no single add can wrap a pixel's sum.
uint fixed_point(float v) {
    return uint(min(v, 64.0) * float(SUM_FIXED_SCALE) + 0.5);
}

void main() {
    uint i = linear_invocation();
    if (i >= pc.count) return;
    uint e = pc.first + i;
    uint splat = entry_splat(e);
    SplatParams p = params_at(splat);
    if (p.center.w == 0.0 || (pc.occluded > 0.0 && occluded(p))) return;
    vec2 faces;
    int layer = entry_layer(e, splat, p, faces);
    mat3 inv;
    ivec4 box;
    if (layer < 0 || !screen_quad(p, inv, box)) return;
    uint width = uint(frame.blur.z);
    uint base = uint(layer) * width * uint(frame.blur.w);
    float energy = p.emit.a * p.axis_u.w;
    bool slab = SHEET_MODE == SHEET_MODE_SLAB;
    // Top-tested loops run one more (masked) pass each: (rows + 1) * (cols + 2) bounds the count.
    if (box.x <= box.z && box.y <= box.w && uint(box.w - box.y + 2) * uint(box.z - box.x + 3) > LOOP_BUDGET) {
        atomicOr(loop_budget_spent, 2u);
        return;
    }
    for (int y = box.y; y <= box.w; ++y) {
        for (int x = box.x; x <= box.z; ++x) {
            vec2 uv = quad_uv(inv, ivec2(x, y));
            if (abs(uv.x) > 1.0 || abs(uv.y) > 1.0) continue;
            float tau = footprint_value(slices, slab, uv, vec3(p.axis_v.w, p.screen.y, frame.sweep.y), faces,
                                        energy, false);
            if (tau <= 0.0) continue;
            uvec4 add = uvec4(fixed_point(p.emit.r * tau), fixed_point(p.emit.g * tau),
                              fixed_point(p.emit.b * tau), fixed_point(tau));
#ifdef SUM64
            uint idx = 2u * (base + uint(y) * width + uint(x));
            if (idx + 1u >= uint(sums.length())) continue;
            atomicAdd(sums[idx], uint64_t(add.r) | (uint64_t(add.g) << 32));
            atomicAdd(sums[idx + 1u], uint64_t(add.b) | (uint64_t(add.a) << 32));
#else
            uint idx = 4u * (base + uint(y) * width + uint(x));
            if (idx + 3u >= uint(sums.length())) continue;
            atomicAdd(sums[idx], add.r);
            atomicAdd(sums[idx + 1u], add.g);
            atomicAdd(sums[idx + 2u], add.b);
            atomicAdd(sums[idx + 3u], add.a);
#endif
        }
    }
}
