#version 450
// variants: PAGED_RECORDS STREAMED_STORE GRADIENTS
// Levels of detail, built when the classification changes: one workgroup per non-empty brick, a
// lane per level-1 cell reading its 8 voxels through the occupancy mask. Its voxels are classified
// (TF and gradient weighting; shading waits for the frame's light) and summed over 2x2x2 children
// into levels 1..3: optical depth, tau-weighted colour and gradient (sign-aligned). Each cell keeps
// its opacity along the three axes (brick.glsl): its children composited in pairs along the axis
// and averaged across it, so a coarse cell covers, seen along each axis, what its children cover.
// Its splat is 2^l times wider and carries the optical depth through the cell. Each cell's error is how far its children
// depart from it (Laur-Hanrahan): the largest over its children of their own error plus the
// difference of opacity over a brick's side, or of colour weighted by the child's opacity; and at
// least how far its face neighbours depart from what the coarse level predicts there (edge_errors:
// a coarse splat reaches past its cell, so it blurs the edges the fine level keeps). Writes
// the pyramid cells and each brick's summary (brick.glsl). A streamed store (STREAMED_STORE)
// builds the pyramids of one batch's bricks from its records, a workgroup per entry of
// brick_list from pc.first, into the entries' slots or, when the pyramid is resident, the bricks'
// own (pyramid_slot). Mirror: cpu::lod::brick_pyramid.
layout(local_size_x = BRICK_LANES) in;
#define MASK_SUMS
#include "brick.glsl"

layout(push_constant) uniform Push {
    uint first;      // the first brick to build (STREAMED_STORE: the batch's first entry of brick_list)
    uint count;      // and how many
    uint splats;     // not 0: into each brick's own slot (a resident pyramid), else the entry's
    float occluded;
} pc;

// Levels 1..3 at level_offset(l): sums over the cell's voxels (optical depth, tau-weighted colour,
// tau-weighted gradient sign-aligned), its error, and its opacity along x, y and z (at 3 i + axis).
shared float tau_l[LOD_CELLS];
shared vec3 col_l[LOD_CELLS];
shared vec3 grad_l[LOD_CELLS];
shared float err_l[LOD_CELLS];
shared float axis_l[3u * LOD_CELLS];
// Each cell's tau-weighted sum of its voxels' value codes (its value: the sum over tau_l).
shared float code_l[LOD_CELLS];
// The optical depth per cell length each cell stores along x (drawn when > 0).
shared float stored_l[LOD_CELLS];
// Drawn voxels per level-1 cell.
shared uint drawn_1[64];
// The voxel layer just outside each of the brick's 6 faces (face 2 axis + high side, 8 x 8 voxels
// each, the other two axes in order): 1 where nothing is drawn there (outside the grid, an empty
// brick or one the TF leaves empty, a voxel the store does not hold), 0 where a voxel may draw
// (read from resident words only, so a streamed store's build needs no neighbour's records).
shared uint empty_out[6u * 64u];
// The value range (low | high << 16, its header's) of the brick past each face, whose voxels the
// outside layer's drawn ones are: resident too.
shared uint range_out[6];
// The brick's occupancy mask and the stored voxels below each of its words.
shared uint mask_w[MASK_WORDS];
shared uint below_w[MASK_WORDS];

// Child d (0..7) of cell c (side n) of level l, as an index into level l - 1's sums.
uint child(uint l, uvec3 c, uint n, uint d) {
    uvec3 k = 2u * c + (uvec3(d, d >> 1u, d >> 2u) & 1u);
    uint m = 2u * n;
    uint i = k.x + m * (k.y + m * k.z);
    return l == 1u ? i : level_offset(l - 1u) + i;
}

// Cell c (side BRICK_SIDE >> l) of level l, as an index into the sums.
uint cell_at(uint l, uvec3 c) {
    uint n = BRICK_SIDE >> l;
    return level_offset(l) + c.x + n * (c.y + n * c.z);
}

// Whether the voxel at v (grid coordinates, possibly outside) draws nothing, from resident words.
uint empty_voxel(ivec3 v) {
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(frame.dims.xyz)))) return 1u;
    uvec3 c = uvec3(v);
    uint h = header_of(c);
    if (h == 0xffffffffu) return 1u;
    uint w = headers[h].w;
    if (tf_empty(w & 0xffffu, w >> 16u)) return 1u;
    uvec3 lc = c % BRICK_SIDE;
    uint l = lc.x + BRICK_SIDE * (lc.y + BRICK_SIDE * lc.z);
    return ((masks[h * MASK_STRIDE + l / 32u] >> (l % 32u)) & 1u) == 0u ? 1u : 0u;
}

// The value range of the brick holding voxel v (outside the grid or an empty brick: none drawn,
// the layer's voxels all empty; 0).
uint neighbour_range(ivec3 v) {
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(frame.dims.xyz)))) return 0u;
    uint h = header_of(uvec3(v));
    return h == 0xffffffffu ? 0u : headers[h].w;
}

// Level l's cells against their face neighbours (a coarse splat reaches past its cell: where a
// neighbour differs, the coarse picture blurs an edge the fine one keeps sharp, the halo of
// coarse cells on silhouettes), measured as a child's (child_error) but against what the coarse
// level predicts there: the cell's sums carried on linearly from the opposite neighbour (2 c - o,
// at least 0), or the cell's own where that one is outside the brick. Neighbouring coarse splats
// interpolate a linear ramp, so a ramp departs by nothing and an edge, a kink or a thin wall by
// its step. A neighbour inside the brick whose opposite one is outside is left to the
// neighbour's own comparisons and the level below's (no slope is known there). A neighbour
// outside the brick is the voxel layer past that face: its empty voxels draw nothing, the others
// are taken to be the prediction, unless the predicted value (the cell's, carried on likewise)
// lies outside the value range of the brick they are in (its header's, resident where its voxels
// are not): then they are at least as far as that range's nearest end, classified (an edge between
// two materials at a brick face; not with gradient-weighted opacity, which the range does not
// bound). Mirror:
// cpu::brick_pyramid::edge_errors.
void edge_errors(uint l, uint lane) {
    uint n = BRICK_SIDE >> l;
    uint side = 1u << l;
    float voxels = float(1u << (3u * l));
    float len = float(BRICK_SIDE);
    for (uint c = lane; c < n * n * n; c += BRICK_LANES) {
        uvec3 cc = uvec3(c % n, (c / n) % n, c / (n * n));
        uint i = level_offset(l) + c;
        float t = tau_l[i];
        float err = err_l[i];
        // The cell's value (its voxels' codes, tau-weighted).
        float q = t > 0.0 ? code_l[i] / t : 0.0;
        for (uint f = 0u; f < 6u; ++f) {
            uint ax = f / 2u;
            bool high = (f & 1u) != 0u;
            bool inside = high ? cc[ax] + 1u < n : cc[ax] > 0u;
            bool opposite = high ? cc[ax] > 0u : cc[ax] + 1u < n;
            // No slope is known here: left to the neighbour's own comparisons.
            if (inside && !opposite) continue;
            // The prediction on this side: linear from the opposite neighbour, or the cell's own.
            float pt = t;
            vec3 pc = col_l[i];
            // The cell's value, carried on likewise.
            float pq = q;
            if (opposite) {
                uvec3 oc = cc;
                oc[ax] = high ? cc[ax] - 1u : cc[ax] + 1u;
                uint o = cell_at(l, oc);
                pt = max(2.0 * t - tau_l[o], 0.0);
                pc = max(2.0 * col_l[i] - col_l[o], vec3(0.0));
                if (tau_l[o] > 0.0) pq = 2.0 * q - code_l[o] / tau_l[o];
            }
            float a = 1.0 - exp(-pt / voxels * len);
            vec3 straight = pt > 0.0 ? pc / pt : vec3(0.0);
            if (inside) {
                uvec3 nc = cc;
                nc[ax] = high ? cc[ax] + 1u : cc[ax] - 1u;
                uint k = cell_at(l, nc);
                err = max(err, child_error(a, straight, tau_l[k], col_l[k], 0.0, voxels, len));
            } else {
                // The face's outside layer under this cell: the fraction of it that draws nothing.
                uint u0 = cc[(ax + 1u) % 3u] * side;
                uint w0 = cc[(ax + 2u) % 3u] * side;
                uint empty = 0u;
                for (uint w = w0; w < w0 + side; ++w) {
                    for (uint u = u0; u < u0 + side; ++u) empty += empty_out[f * 64u + u + 8u * w];
                }
                float kept = 1.0 - float(empty) / float(side * side);
                err = max(err, child_error(a, straight, pt * kept, pc * kept, 0.0, voxels, len));
                // The predicted value against the range of the brick past the face, with half a
                // code's margin so that rounding never decides it (a ramp carries on into it).
                uint r = range_out[f];
                float lo = float(r & 0xffffu);
                float hi = float(r >> 16u);
                if (kept > 0.0 && t > 0.0 && bf.tf.w <= 0.0 && (pq < lo - 0.5 || pq > hi + 0.5)) {
                    vec4 cl = tf_color[pq < lo ? r & 0xffffu : r >> 16u];
                    float to = optical_depth(cl.a) * voxels * kept;
                    err = max(err, child_error(a, straight, to, cl.rgb * to, 0.0, voxels, len));
                }
            }
        }
        err_l[i] = err;
    }
}

// Cell i: its sums (t, col, g), error and axis opacities (for the level above), and its pyramid
// words at `slot`.
void put_cell(uint slot, uint h, uint i, float t, vec3 col, vec3 g, float err, vec3 axes) {
    tau_l[i] = t;
    col_l[i] = col;
    grad_l[i] = g;
    err_l[i] = err;
    uint codes[3];
    for (uint a = 0u; a < 3u; ++a) {
        axis_l[3u * i + a] = axes[a];
        codes[a] = tau_code(-log(1.0 - min(axes[a], 0.9999999)));
    }
    stored_l[i] = tau_decode(codes[0]);
    vec3 straight = t > 0.0 ? col / t : vec3(0.0);
    uint words[3] = uint[3](codes[0] | (codes[1] << 16u), codes[2] | (pack_normal(g) << 16u),
                            unorm10(straight.r) | (unorm10(straight.g) << 10u) | (unorm10(straight.b) << 20u));
    // Level 1 into the pyramid's slot, levels 2 and 3 into the brick's resident summary.
    for (uint k = 0u; k < 3u; ++k) {
        if (i < SLOT_CELLS) pyramid_put((slot * SLOT_CELLS + i) * CELL_WORDS + k, words[k]);
        else lod_words[h * SUMMARY_WORDS + 4u + (i - SLOT_CELLS) * CELL_WORDS + k] = words[k];
    }
    // The one level-3 cell's optical depth: the nodes above the brick sum it (brick_nodes).
    if (i == LOD_CELLS - 1u) lod_words[h * SUMMARY_WORDS + SUMMARY_WORDS - 1u] = floatBitsToUint(t);
}

void main() {
#ifdef STREAMED_STORE
    if (workgroup_item() >= pc.count) return;
    uint e = pc.first + workgroup_item();
    uint h = brick_list[e].x;
    uint first = brick_list[e].z;
    uint slot = pc.splats != 0u ? h : e;
#else
    // A resident store's bricks pc.first .. pc.first + pc.count (the build goes in parts, each
    // its own dispatch, so a host can show how far it has got).
    if (workgroup_item() >= pc.count) return;
    uint h = pc.first + workgroup_item();
    if (h >= bf.grid.w) return;
    uint slot = h;
    uint first = headers[h].y;
#endif
    uvec4 hd = headers[h];
    uvec3 b = brick_coords(hd.x);
    uint lane = gl_LocalInvocationID.x;
    // A brick whose value range the transfer function leaves empty: every cell of its pyramid and
    // its summary are zero, written without reading a voxel (the full pass writes the same words;
    // brick_cull never draws the brick, the nodes above sum its zeros). The whole workgroup leaves.
    if (tf_empty(hd.w & 0xffffu, hd.w >> 16u)) {
        for (uint i = lane; i < LOD_CELLS; i += BRICK_LANES) {
            put_cell(slot, h, i, 0.0, vec3(0.0), vec3(0.0), 0.0, vec3(0.0));
        }
        if (lane == 0u) {
            for (uint k = 0u; k < 4u; ++k) lod_words[h * SUMMARY_WORDS + k] = 0u;
#ifdef STREAMED_STORE
            pyramid_slot[h] = slot;
#endif
        }
        return;
    }
    if (lane < MASK_WORDS) mask_w[lane] = masks[h * MASK_STRIDE + lane];
    for (uint i = lane; i < 6u * 64u; i += BRICK_LANES) {
        uint f = i / 64u;
        uint ax = f / 2u;
        ivec3 v = ivec3(b * BRICK_SIDE);
        v[ax] += (f & 1u) != 0u ? int(BRICK_SIDE) : -1;
        v[(ax + 1u) % 3u] += int(i % 8u);
        v[(ax + 2u) % 3u] += int((i / 8u) % 8u);
        empty_out[i] = empty_voxel(v);
        // The brick past face f holds its whole outside layer.
        if (i % 64u == 0u) range_out[f] = neighbour_range(v);
    }
    barrier();
    if (lane == 0u) {
        uint below = 0u;
        for (uint w = 0u; w < MASK_WORDS; ++w) {
            below_w[w] = below;
            below += uint(bitCount(mask_w[w]));
        }
    }
    barrier();
    bool shaded = bf.light.w > 0.5;
    // Level 1: one lane per cell, its 8 voxels classified (TF, gradient weighting) in turn.
    for (uint c = lane; c < 64u; c += BRICK_LANES) {
        uvec3 cc = uvec3(c % 4u, (c / 4u) % 4u, c / 16u);
        float tk[8];
        vec3 ck[8];
        float ak[8];
        float t = 0.0;
        vec3 col = vec3(0.0);
        vec3 g = vec3(0.0);
        uint drawn = 0u;
        float code = 0.0;
        for (uint d = 0u; d < 8u; ++d) {
            uvec3 k = 2u * cc + (uvec3(d, d >> 1u, d >> 2u) & 1u);
            uint l = k.x + BRICK_SIDE * (k.y + BRICK_SIDE * k.z);
            tk[d] = 0.0;
            ck[d] = vec3(0.0);
            uint word = mask_w[l / 32u];
            if (((word >> (l % 32u)) & 1u) != 0u) {
                uint rank = below_w[l / 32u] + uint(bitCount(word & ((1u << (l % 32u)) - 1u)));
                uint q = record_at(first + rank) >> 16u;
                if (emits(q)) {
                    ivec3 v = ivec3(b * BRICK_SIDE + k);
                    vec4 cl = classify_voxel(v, q, false);
                    tk[d] = optical_depth(cl.a);
                    ck[d] = cl.rgb * tk[d];
                    code += tk[d] * float(q);
#ifdef GRADIENTS
                    // Each voxel's differences, made once (BrickStore::gradient_words): half the
                    // shaded pyramid's time read its neighbours through the store.
                    if (shaded) g += aligned(gradient_from(differences_at(h, rank)) * tk[d], g);
#else
                    if (shaded) g += aligned(gradient_at(v) * tk[d], g);
#endif
                    drawn += tk[d] > 0.0 ? 1u : 0u;
                }
            }
            ak[d] = 1.0 - exp(-tk[d]);
            t += tk[d];
            col += ck[d];
        }
        float a = 1.0 - exp(-t / 8.0 * float(BRICK_SIDE));
        vec3 straight = t > 0.0 ? col / t : vec3(0.0);
        float err = 0.0;
        for (uint d = 0u; d < 8u; ++d) err = max(err, child_error(a, straight, tk[d], ck[d], 0.0, 1.0, float(BRICK_SIDE)));
        vec3 axes = vec3(axis_opacity(ak, 0u), axis_opacity(ak, 1u), axis_opacity(ak, 2u));
        put_cell(slot, h, c, t, col, g, err, axes);
        code_l[c] = code;
        drawn_1[c] = drawn;
    }
    barrier();
    edge_errors(1u, lane);
    barrier();
    // Levels 2 and 3 from the level below.
    for (uint l = 2u; l <= 3u; ++l) {
        uint n = BRICK_SIDE >> l;
        float voxels = float(1u << (3u * l));
        for (uint c = lane; c < n * n * n; c += BRICK_LANES) {
            uvec3 cc = uvec3(c % n, (c / n) % n, c / (n * n));
            float t = 0.0;
            vec3 col = vec3(0.0);
            vec3 g = vec3(0.0);
            float code = 0.0;
            for (uint d = 0u; d < 8u; ++d) {
                uint k = child(l, cc, n, d);
                t += tau_l[k];
                col += col_l[k];
                code += code_l[k];
                g += aligned(grad_l[k], g);
            }
            float len = float(BRICK_SIDE);
            float a = 1.0 - exp(-t / voxels * len);
            vec3 straight = t > 0.0 ? col / t : vec3(0.0);
            float err = 0.0;
            for (uint d = 0u; d < 8u; ++d) {
                uint k = child(l, cc, n, d);
                err = max(err, child_error(a, straight, tau_l[k], col_l[k], err_l[k], voxels / 8.0, len));
            }
            vec3 axes;
            for (uint x = 0u; x < 3u; ++x) {
                float ak[8];
                for (uint d = 0u; d < 8u; ++d) ak[d] = axis_l[3u * child(l, cc, n, d) + x];
                axes[x] = axis_opacity(ak, x);
            }
            put_cell(slot, h, level_offset(l) + c, t, col, g, err, axes);
            code_l[level_offset(l) + c] = code;
        }
        barrier();
        edge_errors(l, lane);
        barrier();
    }
    if (lane == 0u) {
        uvec4 s = uvec4(0u);
        for (uint c = 0u; c < 64u; ++c) s.x += drawn_1[c] << 16u;
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
        for (uint k = 0u; k < 4u; ++k) lod_words[h * SUMMARY_WORDS + k] = s[k];
#ifdef STREAMED_STORE
        pyramid_slot[h] = slot;
#endif
    }
}
