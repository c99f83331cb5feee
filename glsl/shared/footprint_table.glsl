// Bilinear lookup in the pre-integrated footprint table with explicit texel fetches, so the CPU
// mirror (src/cpu/footprint.rs, sample_table) computes the same weights as the GPU.
// uv in [-1, 1]^2 spans the kernel's radius.
float sample_table(sampler2D table, vec2 uv) {
    float n = float(FOOTPRINT_TABLE_SIZE);
    vec2 t = (uv * 0.5 + 0.5) * n - 0.5;
    vec2 f = floor(t);
    vec2 w = t - f;
    ivec2 i0 = clamp(ivec2(f), ivec2(0), ivec2(FOOTPRINT_TABLE_SIZE - 1));
    ivec2 i1 = clamp(ivec2(f) + 1, ivec2(0), ivec2(FOOTPRINT_TABLE_SIZE - 1));
    float a = texelFetch(table, ivec2(i0.x, i0.y), 0).r;
    float b = texelFetch(table, ivec2(i1.x, i0.y), 0).r;
    float c = texelFetch(table, ivec2(i0.x, i1.y), 0).r;
    float d = texelFetch(table, ivec2(i1.x, i1.y), 0).r;
    float top = a + (b - a) * w.x;
    float bottom = c + (d - c) * w.x;
    return top + (bottom - top) * w.y;
}

// Lookup in the kernel-slice table (image-aligned sheets): r in [0, 1] is the in-plane distance
// from the splat's centre and z in [-1, 1] the depth of a slab face relative to it, both in radius
// units; texel centres sit on r = x / (N-1) and z = 2y / (N-1) - 1 so both ends are exact.
// Mirror: sample_slice_table in src/cpu/footprint.rs.
float sample_slice_table(sampler2D slices, float r, float z) {
    float m = float(FOOTPRINT_TABLE_SIZE - 1);
    vec2 t = vec2(clamp(r, 0.0, 1.0), clamp(z, -1.0, 1.0) * 0.5 + 0.5) * m;
    ivec2 i0 = min(ivec2(floor(t)), ivec2(FOOTPRINT_TABLE_SIZE - 2));
    vec2 w = t - vec2(i0);
    float a = texelFetch(slices, ivec2(i0.x, i0.y), 0).r;
    float b = texelFetch(slices, ivec2(i0.x + 1, i0.y), 0).r;
    float c = texelFetch(slices, ivec2(i0.x, i0.y + 1), 0).r;
    float d = texelFetch(slices, ivec2(i0.x + 1, i0.y + 1), 0).r;
    float top = a + (b - a) * w.x;
    float bottom = c + (d - c) * w.x;
    return top + (bottom - top) * w.y;
}

// Lookup in the radial footprint table (Kernel::radial_pairs): s = r² in radius units, linear
// between RADIAL_TABLE_SIZE + 1 samples. The includer declares the `radial` buffer.
// Mirror: sample_radial in src/cpu/footprint.rs.
float sample_radial(float s) {
    float t = clamp(s, 0.0, 1.0) * float(RADIAL_TABLE_SIZE);
    uint i = min(uint(t), RADIAL_TABLE_SIZE - 1u);
    vec2 e = radial[i];  // (value, step to the next)
    return e.x + e.y * (t - float(i));
}

// MIP and MinIP: a footprint covers a pixel fully where it weighs this share of its centre's
// (params.glsl's PROJECT_SHRINK; mirror: cpu::footprint::PROJECT_FULL).
const float PROJECT_FULL = 0.7;

#include "sweep.glsl"

// Time samples of a tapered or teardrop footprint: a quarter radius apart along the path or
// closer, at most MAX_SWEEP_SAMPLES.
int sweep_samples(float stretch, float bend) {
    return clamp(1 + int(ceil(4.0 * (2.0 * stretch + 2.0 * abs(bend)))), 2, MAX_SWEEP_SAMPLES);
}

// The first and last of n time samples (t = (k + 0.5) / n) that can reach x: the path's u
// coordinate is linear in t, so only those within a radius of x along u, t in
// (x.x + stretch -+ 1) / (2 stretch). Mirror: sweep_window in src/cpu/footprint.rs.
ivec2 sweep_window(vec2 x, float stretch, int n) {
    float lo = (x.x + stretch - 1.0) / (2.0 * stretch), hi = (x.x + stretch + 1.0) / (2.0 * stretch);
    return ivec2(max(int(ceil(lo * float(n) - 0.5)), 0), min(int(floor(hi * float(n) - 0.5)), n - 1));
}

// Time sample k of n, t = (k + 0.5) / n, and r² from x to the path there. Mirror: sweep_sample in
// src/cpu/footprint.rs.
vec2 sweep_sample(vec2 x, float stretch, float bend, int k, int n) {
    float t = (float(k) + 0.5) / float(n);
    vec2 e = x - sweep_point(stretch, bend, t);
    return vec2(t, dot(e, e));
}

// The kernel's weight at r² s: the whole pre-integrated footprint or, for a slab, the kernel
// slice between its faces (radius units).
float kernel_at(sampler2D slices, bool slab, float s, vec2 faces) {
    if (slab) {
        float r = sqrt(s);
        return sample_slice_table(slices, r, faces.y) - sample_slice_table(slices, r, faces.x);
    }
    return sample_radial(s);
}

// What a footprint of optical depth scale tau deposits at quad coordinates uv: its optical depth
// (sheet modes: summed) or, with `opacity`, its alpha (per-splat compositing). `sweep` is the
// motion (stretch, bend, profile). The uniform profile weighs the distance to the path (the
// seed's footprint); the tapered and teardrop ones average the moving footprint over time
// samples, and per splat they average its alpha, as the accumulation buffer averages the frames
// of a lone splat. Mirror: footprint_value in src/cpu/footprint.rs.
float footprint_value(sampler2D slices, bool slab, vec2 uv, vec3 sweep, vec2 faces, float tau, bool opacity) {
    float stretch = sweep.x, bend = sweep.y;
    uint profile = uint(sweep.z);
    if (profile == SWEEP_UNIFORM || stretch == 0.0) {
        float d = tau * kernel_at(slices, slab, footprint_r2(uv, stretch, bend), faces);
        return opacity ? 1.0 - exp(-d) : d;
    }
    vec2 x = sweep_coords(uv, stretch, bend);
    int n = sweep_samples(stretch, bend);
    ivec2 ks = sweep_window(x, stretch, n);
    float sum = 0.0;
    for (int k = ks.x; k <= ks.y; ++k) {
        vec2 ts = sweep_sample(x, stretch, bend, k, n);
        float t = ts.x, s = ts.y;
        if (s >= 1.0) continue;
        float d = tau * kernel_at(slices, slab, s, faces);
        // Teardrop: weight 2t / n, rising to t_i (the weights sum to 1 either way).
        float w = profile == SWEEP_TEARDROP ? 2.0 * t / float(n) : 1.0 / float(n);
        sum += w * (opacity ? 1.0 - exp(-d) : d);
    }
    return sum;
}

// Two time slots (Pass::Slots): the alpha a footprint of scale tau deposits at uv in each half of
// the shutter, averaged over that half's samples (those of footprint_value, rounded up to an even
// count). Mirror: Weight::slots in src/cpu/footprint.rs.
vec2 footprint_slots(vec2 uv, vec3 sweep, float tau) {
    float stretch = sweep.x, bend = sweep.y;
    if (stretch == 0.0) {
        float a = 1.0 - exp(-tau * sample_radial(footprint_r2(uv, 0.0, 0.0)));
        return vec2(a);
    }
    vec2 x = sweep_coords(uv, stretch, bend);
    int n = 2 * ((sweep_samples(stretch, bend) + 1) / 2);
    ivec2 ks = sweep_window(x, stretch, n);
    vec2 sum = vec2(0.0);
    for (int k = ks.x; k <= ks.y; ++k) {
        vec2 ts = sweep_sample(x, stretch, bend, k, n);
        float s = ts.y;
        if (s >= 1.0) continue;
        float a = 1.0 - exp(-tau * sample_radial(s));
        if (2 * k < n) {
            sum.x += a;
        } else {
            sum.y += a;
        }
    }
    return sum * (2.0 / float(n));
}
