// Trilinear sample of the (colour * tau, tau) field with explicit texel fetches, zero outside the
// grid (a tent kernel around every voxel). Mirror: src/cpu/raycast.rs (trilinear).
vec4 fetch_or_zero(sampler3D field, ivec3 p, ivec3 dims) {
    if (any(lessThan(p, ivec3(0))) || any(greaterThanEqual(p, dims))) return vec4(0.0);
    return texelFetch(field, p, 0);
}

vec4 trilinear(sampler3D field, vec3 u, ivec3 dims) {
    vec3 b = floor(u);
    vec3 f = u - b;
    ivec3 i = ivec3(b);
    vec4 c000 = fetch_or_zero(field, i, dims);
    vec4 c100 = fetch_or_zero(field, i + ivec3(1, 0, 0), dims);
    vec4 c010 = fetch_or_zero(field, i + ivec3(0, 1, 0), dims);
    vec4 c110 = fetch_or_zero(field, i + ivec3(1, 1, 0), dims);
    vec4 c001 = fetch_or_zero(field, i + ivec3(0, 0, 1), dims);
    vec4 c101 = fetch_or_zero(field, i + ivec3(1, 0, 1), dims);
    vec4 c011 = fetch_or_zero(field, i + ivec3(0, 1, 1), dims);
    vec4 c111 = fetch_or_zero(field, i + ivec3(1, 1, 1), dims);
    vec4 x00 = c000 + (c100 - c000) * f.x;
    vec4 x10 = c010 + (c110 - c010) * f.x;
    vec4 x01 = c001 + (c101 - c001) * f.x;
    vec4 x11 = c011 + (c111 - c011) * f.x;
    vec4 y0 = x00 + (x10 - x00) * f.y;
    vec4 y1 = x01 + (x11 - x01) * f.y;
    return y0 + (y1 - y0) * f.z;
}
