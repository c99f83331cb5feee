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
