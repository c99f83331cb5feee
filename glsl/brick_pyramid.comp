#version 450
// variants: PAGED_RECORDS
// Levels of detail (issue 24), built when the classification changes: one workgroup per
// non-empty brick. Its voxels are classified (TF and gradient weighting; shading waits for the
// frame's light) into optical depth per voxel length tau, tau-weighted colour and tau-weighted
// gradient; levels 1..3 sum them over 2x2x2 children, so a coarse cell holds its children's
// extinction and extinction-weighted colour (Swan's energy argument, at build time: its splat is
// 2^l times wider and carries 2^l times the mean optical depth per voxel). Each cell's error is
// how far its children depart from it (Laur-Hanrahan): the largest over its children of their own
// error plus the difference of opacity per voxel length, or of colour weighted by the child's
// opacity. Writes the pyramid cells and each brick's summary (brick.glsl). Mirror:
// cpu::lod::brick_pyramid.
layout(local_size_x = BRICK_LANES) in;
#include "brick.glsl"

const uint FINE = BRICK_SIDE * BRICK_SIDE * BRICK_SIDE;
// Level 0: per voxel; levels 1..3 at level_offset(l): sums over the cell's voxels.
shared float tau0[FINE];
shared vec3 col0[FINE];
shared vec3 grad0[FINE];
shared float tau_l[LOD_CELLS];
shared vec3 col_l[LOD_CELLS];
shared vec3 grad_l[LOD_CELLS];
shared float err_l[LOD_CELLS];
// The optical depth per cell length each cell stores (drawn when > 0).
shared float stored_l[LOD_CELLS];

// Octahedral bytes (snorm 8 + 8) of gradient g, NO_NORMAL when it is zero.
uint pack_normal(vec3 g) {
    float len = abs(g.x) + abs(g.y) + abs(g.z);
    if (!(len > 0.0)) return NO_NORMAL;
    vec3 n = g / len;
    vec2 o = n.xy;
    if (n.z < 0.0) o = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return packSnorm4x8(vec4(o, 0.0, 0.0)) & 0xffffu;
}

// Child d (0..7) of cell c (side n) of level l, as an index into level l - 1's sums.
uint child(uint l, uvec3 c, uint n, uint d) {
    uvec3 k = 2u * c + (uvec3(d, d >> 1u, d >> 2u) & 1u);
    uint m = 2u * n;
    uint i = k.x + m * (k.y + m * k.z);
    return l == 1u ? i : level_offset(l - 1u) + i;
}

void main() {
    uint h = workgroup_item();
    if (h >= bf.grid.w) return;
    uvec4 hd = headers[h];
    uvec3 b = brick_coords(hd.x);
    uint lane = gl_LocalInvocationID.x;
    for (uint c = lane; c < FINE; c += BRICK_LANES) {
        tau0[c] = 0.0;
        col0[c] = vec3(0.0);
        grad0[c] = vec3(0.0);
    }
    barrier();
    bool shaded = bf.light.w > 0.5;
    for (uint r = lane; r < hd.z; r += BRICK_LANES) {
        uint rec = record_at(hd.y + r);
        if (!emits(rec >> 16u)) continue;
        uint l = rec & 511u;
        ivec3 v = ivec3(b * BRICK_SIDE + local_cell(l));
        vec4 c = classify_voxel(v, rec >> 16u, false);
        float t = -log(1.0 - clamp(c.a, 0.0, MAX_OPACITY));
        tau0[l] = t;
        col0[l] = c.rgb * t;
        grad0[l] = shaded ? gradient_at(v) * t : vec3(0.0);
    }
    barrier();
    for (uint l = 1u; l <= 3u; ++l) {
        uint n = BRICK_SIDE >> l;
        float voxels = float(1u << (3u * l));
        for (uint c = lane; c < n * n * n; c += BRICK_LANES) {
            uvec3 cc = uvec3(c % n, (c / n) % n, c / (n * n));
            float t = 0.0;
            vec3 col = vec3(0.0);
            vec3 g = vec3(0.0);
            for (uint d = 0u; d < 8u; ++d) {
                uint k = child(l, cc, n, d);
                t += l == 1u ? tau0[k] : tau_l[k];
                col += l == 1u ? col0[k] : col_l[k];
                g += l == 1u ? grad0[k] : grad_l[k];
            }
            float a = 1.0 - exp(-t / voxels);
            vec3 straight = t > 0.0 ? col / t : vec3(0.0);
            float err = 0.0;
            for (uint d = 0u; d < 8u; ++d) {
                uint k = child(l, cc, n, d);
                float tk = l == 1u ? tau0[k] : tau_l[k];
                vec3 ck = l == 1u ? col0[k] : col_l[k];
                float ek = l == 1u ? 0.0 : err_l[k];
                float ak = 1.0 - exp(-tk * 8.0 / voxels);
                vec3 sk = tk > 0.0 ? ck / tk : vec3(0.0);
                vec3 dc = abs(sk - straight);
                err = max(err, ek + max(abs(ak - a), ak * max(dc.x, max(dc.y, dc.z))));
            }
            uint i = level_offset(l) + c;
            tau_l[i] = t;
            col_l[i] = col;
            grad_l[i] = g;
            err_l[i] = err;
            uint base = (h * LOD_CELLS + i) * CELL_WORDS;
            // Optical depth per cell length: 2^l voxel lengths of the mean per voxel.
            stored_l[i] = t / voxels * float(1u << l);
            pyramid[base] = floatBitsToUint(stored_l[i]);
            pyramid[base + 1u] = packUnorm2x16(straight.rg);
            pyramid[base + 2u] = (packUnorm2x16(vec2(straight.b, 0.0)) & 0xffffu) | (pack_normal(g) << 16u);
        }
        barrier();
    }
    if (lane == 0u) {
        uvec4 s = uvec4(0u);
        for (uint l = 1u; l <= 3u; ++l) {
            uint n = BRICK_SIDE >> l;
            uint drawn = 0u;
            float most = 0.0;
            for (uint c = 0u; c < n * n * n; ++c) {
                uint i = level_offset(l) + c;
                if (stored_l[i] > 0.0) drawn++;
                most = max(most, err_l[i]);
            }
            s.x |= drawn << (l == 1u ? 0u : (l == 2u ? 8u : 12u));
            s[l] = floatBitsToUint(most);
        }
        lod_summary[h] = s;
    }
}
