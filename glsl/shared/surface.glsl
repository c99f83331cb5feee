// Surface splats (Mode::Iso; Zwicker et al. 2001, EWA surface splatting): a disc in the tangent
// plane of the isosurface, and its headlight shading, shared by iso_splats and the ray caster's
// first crossing. The includer declares `frame` (the ray caster: none; it uses surface_light and
// cell_gradient only). Mirror: cpu::iso_splats.

// Phong weights of the surface's headlight (Shading::headlight's); project.comp applies the
// ambient and diffuse ones to the surface colour.
const float SURFACE_SHININESS = 20.0;
// A surface splat's disc radius in voxel lengths (the footprint kernel spread over it).
const float ISO_DISC_VOXELS = 1.25;

// The corner values of a cell (corner c = dx + 2 dy + 4 dz) reconstructed at local point p.
float cell_value(float v[8], vec3 p) {
    float f = 0.0;
    for (int c = 0; c < 8; ++c) {
        vec3 w = mix(1.0 - p, p, vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1));
        f += v[c] * w.x * w.y * w.z;
    }
    return f;
}

// The gradient (index units) of that trilinear reconstruction at p: the surface's normal, the
// same for a splat and a ray that meet the surface in one cell.
vec3 cell_gradient(float v[8], vec3 p) {
    vec3 g = vec3(0.0);
    for (int c = 0; c < 8; ++c) {
        vec3 d = vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        vec3 w = mix(1.0 - p, p, d);
        vec3 s = 2.0 * d - 1.0;
        g += v[c] * s * vec3(w.y * w.z, w.x * w.z, w.x * w.y);
    }
    return g;
}

// (Lambert, Phong specular) of a surface of unit normal n lit by a headlight travelling along
// unit w; two-sided: the normal is turned toward the eye.
vec2 surface_light(vec3 n, vec3 w) {
    if (dot(n, w) > 0.0) n = -n;
    float lambert = max(dot(n, -w), 0.0);
    vec3 r = w - 2.0 * dot(w, n) * n;
    float spec = pow(max(dot(r, -w), 0.0), SURFACE_SHININESS);
    return vec2(lambert, spec);
}
