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

// r² (radius units) at quad coordinates uv of a footprint stretched along u across its motion
// segment (stretch, radius units; 0: round). Mirror: Weight::at in src/cpu/footprint.rs.
float footprint_r2(vec2 uv, float stretch) {
    float along = max(abs(uv.x) * (1.0 + stretch) - stretch, 0.0);
    return along * along + uv.y * uv.y;
}

// A footprint's weight at quad coordinates uv: the pre-integrated kernel across the motion segment
// (stretch, radius units along u) or, for a slab, the kernel slice between its faces (radius units).
// Mirror: Weight::at in src/cpu/footprint.rs.
float footprint_weight(sampler2D slices, bool slab, vec2 uv, float stretch, vec2 faces) {
    float s = footprint_r2(uv, stretch);
    if (slab) {
        float r = sqrt(s);
        return sample_slice_table(slices, r, faces.y) - sample_slice_table(slices, r, faces.x);
    }
    return sample_radial(s);
}
