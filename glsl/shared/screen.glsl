// A splat's footprint in screen space, without bindings (the includer declares `frame`): shared
// by the footprint stages (footprint.glsl) and the brick stages that write screen quads in their
// parameters' place (brick_quads, brick_lod_quads). Mirrors: src/cpu/footprint.rs, src/cpu/tile.rs.
#ifndef SCREEN_GLSL
#define SCREEN_GLSL

const vec2 CORNERS[4] = vec2[](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));

// The footprint quad in pixels: `inv` maps a pixel centre (x, y, 1) to homogeneous quad
// coordinates (u, v, 1) — the projective map that perspective-correct interpolation evaluates —
// and `box` is the inclusive pixel range (x0, y0, x1, y1) of the quad's bounding box, clipped to
// the image. False when the splat is culled, a corner lies behind the eye or the box is empty.
// Mirror: cpu::footprint::screen_quad.
bool screen_quad(SplatParams p, out mat3 inv, out ivec4 box) {
    inv = mat3(1.0);
    box = ivec4(0, 0, -1, -1);
    if (p.center.w == 0.0) return false;
    vec2 size = frame.blur.zw;
    vec4 c0 = frame.view_proj * vec4(p.center.xyz, 1.0);
    vec4 cu = frame.view_proj * vec4(p.axis_u.xyz, 0.0);
    vec4 cv = frame.view_proj * vec4(p.axis_v.xyz, 0.0);
    // Pixel = (X / W, Y / W) with X = (x + w) / 2 * width, Y = (y + w) / 2 * height.
    vec3 m0 = vec3((c0.xy + c0.w) * 0.5 * size, c0.w);
    vec3 mu = vec3((cu.xy + cu.w) * 0.5 * size, cu.w);
    vec3 mv = vec3((cv.xy + cv.w) * 0.5 * size, cv.w);
    vec2 lo = vec2(1e30), hi = vec2(-1e30);
    for (int k = 0; k < 4; ++k) {
        vec3 q = m0 + CORNERS[k].x * mu + CORNERS[k].y * mv;
        if (q.z <= 0.0) return false;
        vec2 s = q.xy / q.z;
        lo = min(lo, s);
        hi = max(hi, s);
    }
    box = ivec4(max(ceil(lo - 0.5), vec2(0.0)), min(floor(hi - 0.5), size - 1.0));
    if (box.x > box.z || box.y > box.w) return false;
    inv = inverse(mat3(mu, mv, m0));
    return true;
}

// The splat's footprint in screen space (an empty box when it covers no pixel).
ScreenQuad screen_record(SplatParams p) {
    mat3 inv;
    ivec4 box;
    ScreenQuad q;
    bool on = screen_quad(p, inv, box);
    q.inv0 = vec4(inv[0][0], inv[1][0], inv[2][0], p.axis_v.w);
    q.inv1 = vec4(inv[0][1], inv[1][1], inv[2][1], p.screen.y);
    q.inv2 = vec4(inv[0][2], inv[1][2], inv[2][2], p.screen.x);
    q.box = on ? box : ivec4(0, 0, -1, -1);
    q.emit = vec4(p.emit.rgb, p.emit.a * p.axis_u.w);
    return q;
}

#endif
