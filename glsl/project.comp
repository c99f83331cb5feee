#version 450
// A projection mode's colours (options::Mode): the blended (key, weight) of each pixel, read from
// the tile compositor's image or the footprint draw's target, mapped through the colour map (the
// values 0 to 1 in COLOR_MAP_SIZE entries, linear between them) into the premultiplied frame.
// MIP: the largest weighed key over the coverage (the largest weight over a footprint's centre's),
// at that coverage; MinIP: one minus it; average: the weighed mean, at opacity the summed weight over one centre's
// (clamped to 1); X-ray: the map's top colour at opacity 1 - exp(-the summed optical depth);
// the isosurface: its colour at the iso value, shaded.
// Mirror: cpu::project.
#include "types.glsl"

layout(local_size_x = COMPOSITE_TILE, local_size_y = COMPOSITE_TILE) in;
layout(binding = 0, rgba32f) uniform image2D accum;
layout(binding = 1, rgba32f) uniform readonly image2D color;
layout(std430, binding = 2) readonly buffer ColorMap { vec4 color_map[]; };
layout(push_constant) uniform Push {
    uint mode;        // PROJECT_*
    uint width;
    uint height;
    uint source;      // 1: accum (the tile compositor), 2: the raster target (the footprint draw)
    float centre;     // the radial table's value at a footprint's centre (average's unit weight)
    float iso;        // the isosurface's value (its colour)
    uint pad1;
    uint pad2;
} pc;

// The isosurface's headlight (Shading::headlight's weights; the specular's exponent is
// surface.glsl's).
const float SURFACE_AMBIENT = 0.3;
const float SURFACE_DIFFUSE = 0.7;
const float SURFACE_SPECULAR = 0.25;

vec3 mapped(float v) {
    float t = clamp(v, 0.0, 1.0) * float(COLOR_MAP_SIZE - 1u);
    uint i = min(uint(t), COLOR_MAP_SIZE - 2u);
    return mix(color_map[i].rgb, color_map[i + 1u].rgb, t - float(i));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    vec4 acc = pc.source == 1u ? imageLoad(accum, p) : imageLoad(color, p);
    float v, a;
    // The isosurface: the colour map's colour at the iso value, lit by the weighed mean shading
    // (sum of w lambert, sum of w specular, sum of w); opaque where the discs' weights reach a
    // footprint's centre's.
    if (pc.mode == PROJECT_ISO) {
        vec3 lit = acc.z > 0.0 ? mapped(pc.iso) * (SURFACE_AMBIENT + SURFACE_DIFFUSE * acc.x / acc.z)
                                     + SURFACE_SPECULAR * acc.y / acc.z
                               : vec3(0.0);
        a = clamp(acc.z / pc.centre, 0.0, 1.0);
        imageStore(accum, p, vec4(lit * a, a));
        return;
    }
    // MIP and MinIP: the largest weighed key over the coverage, so a region of one value keeps
    // it between the voxels' centres (the weighed key alone ripples at the grid's pitch).
    if (pc.mode == PROJECT_MIP) {
        v = acc.y > 0.0 ? acc.x / acc.y : 0.0;
        a = acc.y;
    } else if (pc.mode == PROJECT_MINIP) {
        v = 1.0 - (acc.y > 0.0 ? acc.x / acc.y : 0.0);
        a = acc.y;
    } else if (pc.mode == PROJECT_AVERAGE) {
        v = acc.y > 0.0 ? acc.x / acc.y : 0.0;
        a = acc.y / pc.centre;
    } else {
        v = 1.0;
        a = 1.0 - exp(-acc.x);
    }
    a = clamp(a, 0.0, 1.0);
    imageStore(accum, p, vec4(mapped(v) * a, a));
}
