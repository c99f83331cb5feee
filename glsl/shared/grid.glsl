// Where grid points lie: the includer declares `frame`.
#ifndef GRID_GLSL
#define GRID_GLSL

// The world position of grid point `at` (index units): origin + U at, U the cell matrix (spacing
// on its diagonal, a sheared grid's shear above it). Mirror: Grid::point.
vec3 grid_point(vec3 at) {
    vec3 s = frame.spacing.xyz;
    vec3 h = frame.shear.xyz;
    return frame.origin.xyz + vec3(at.x * s.x + at.y * h.x + at.z * h.y, at.y * s.y + at.z * h.z, at.z * s.z);
}

// World direction d in index units (U's inverse, by back substitution). Mirror: Grid::index_dir.
vec3 grid_direction(vec3 d) {
    vec3 s = frame.spacing.xyz;
    vec3 h = frame.shear.xyz;
    float z = d.z / s.z;
    float y = (d.y - h.z * z) / s.y;
    return vec3((d.x - h.x * y - h.y * z) / s.x, y, z);
}

#endif
