// Chapter 4's blurred footprint: the geometry of its path, shared by the stage that places it
// (params.glsl) and the ones that weigh it (footprint_table.glsl). Mirror: src/cpu/footprint.rs.
#ifndef SWEEP_GLSL
#define SWEEP_GLSL

// Chapter 4's blurred footprint, in radius units about the quad's centre: the path runs from
// t_{i-1} at (-stretch, 0) to t_i at (stretch, 0) through (0, bend) halfway (a parabola: the
// seed's future work fits the path with one; bend 0 is its straight segment), and the quad
// spans (1 + stretch, 1 + |bend|) radii along u and v.
const int ARC_SEGMENTS = 8;
const int MAX_SWEEP_SAMPLES = 64;

// The path's point at time t in [0, 1]. Mirror: sweep_point in src/cpu/footprint.rs.
vec2 sweep_point(float stretch, float bend, float t) {
    return vec2(stretch * (2.0 * t - 1.0), 4.0 * bend * t * (1.0 - t));
}

// Quad coordinates -> radius units.
vec2 sweep_coords(vec2 uv, float stretch, float bend) {
    return vec2(uv.x * (1.0 + stretch), uv.y * (1.0 + abs(bend)));
}

// Length of the path in radius units (the bent one as ARC_SEGMENTS chords).
float sweep_length(float stretch, float bend) {
    if (bend == 0.0) return 2.0 * stretch;
    float l = 0.0;
    vec2 a = sweep_point(stretch, bend, 0.0);
    for (int k = 1; k <= ARC_SEGMENTS; ++k) {
        vec2 b = sweep_point(stretch, bend, float(k) / float(ARC_SEGMENTS));
        l += length(b - a);
        a = b;
    }
    return l;
}

// r² (radius units) at quad coordinates uv: the squared distance to the path (0: a round
// footprint). Mirror: sweep_r2 in src/cpu/footprint.rs.
float footprint_r2(vec2 uv, float stretch, float bend) {
    vec2 x = sweep_coords(uv, stretch, bend);
    if (bend == 0.0) {
        float along = max(abs(x.x) - stretch, 0.0);
        return along * along + x.y * x.y;
    }
    float best = 1e30;
    vec2 a = sweep_point(stretch, bend, 0.0);
    for (int k = 1; k <= ARC_SEGMENTS; ++k) {
        vec2 b = sweep_point(stretch, bend, float(k) / float(ARC_SEGMENTS));
        vec2 ab = b - a;
        float h = clamp(dot(x - a, ab) / max(dot(ab, ab), 1e-12), 0.0, 1.0);
        vec2 d = x - a - h * ab;
        best = min(best, dot(d, d));
        a = b;
    }
    return best;
}

#endif
