// GPU structs and constants shared by every stage.
// Keep in sync with src/gpu_types.rs (sizes are asserted there).
#ifndef VOXSPLAT_TYPES_GLSL
#define VOXSPLAT_TYPES_GLSL

// One extracted (non-empty) voxel; camera independent. 32 bytes.
struct Splat {
    uvec4 ijk;    // grid index i, j, k; w: the voxel's value in [0, 1] as float bits (projections)
    vec4 color;   // straight rgb; a: opacity of one voxel-length of material, in [0, 1)
};

// The per-splat record arrays are bound as two pages of SPLAT_PAGE records (src/constants.rs): one
// storage binding may not pass maxStorageBufferRange. PAGED_READER defines `T name(uint i)`, which
// reads record i of the pair lo, hi (a function: SPIR-V gives each block's struct its own type).
// Built with ONE_PAGE (for scenes of at most SPLAT_PAGE splats) it reads lo only: llvmpipe runs both
// sides of the branch, each load lane by lane, which cost the tile compositor ~5-10 %.
// PAGED_FIELD_READER defines `T name(uint i)` reading one field of record i (a whole record is
// loaded word by word, lane by lane on llvmpipe); PAGED_WRITER defines `void name(uint i, T v)`,
// which stores record i the same way.
#ifdef ONE_PAGE
#define PAGED_READER(T, name, lo, hi) \
    T name(uint i) { return lo[i]; }
#define PAGED_FIELD_READER(T, name, lo, hi, field) \
    T name(uint i) { return lo[i].field; }
#define PAGED_WRITER(T, name, lo, hi) \
    void name(uint i, T v) { lo[i] = v; }
#else
#define PAGED_READER(T, name, lo, hi) \
    T name(uint i) {                  \
        if (i < SPLAT_PAGE) return lo[i]; \
        return hi[i - SPLAT_PAGE];    \
    }
#define PAGED_FIELD_READER(T, name, lo, hi, field)       \
    T name(uint i) {                                     \
        if (i < SPLAT_PAGE) return lo[i].field;          \
        return hi[i - SPLAT_PAGE].field;                 \
    }
#define PAGED_WRITER(T, name, lo, hi)  \
    void name(uint i, T v) {           \
        if (i < SPLAT_PAGE) {          \
            lo[i] = v;                 \
        } else {                       \
            hi[i - SPLAT_PAGE] = v;    \
        }                              \
    }
#endif

// Output of splat_params, input of the footprint stage. 80 bytes.
struct SplatParams {
    vec4 center;  // world-space centre; w: 1 if drawn, 0 if culled
    vec4 axis_u;  // world-space half-extent vector of the footprint quad; w: energy scale
    vec4 axis_v;  // second half-extent vector, perpendicular to axis_u and to the eye ray;
                  // w: motion stretch (half the blur length over the radius; 0 = not blurred)
    vec4 emit;    // rgb colour; a: optical depth of the voxel (tau)
    vec4 screen;  // eye-space depth z_e (section 3.3.1, +z forward); the motion path's bend (its
                  // middle's offset across the chord along axis_v, radius units; 0 = straight);
                  // footprint radius in pixels; anti-aliasing radius scale
};

// A footprint in screen space, written by screen_quads for the tile stages. 80 bytes.
struct ScreenQuad {
    vec4 inv0;    // rows of the inverse projective map, pixel centre (x, y, 1) -> homogeneous
    vec4 inv1;    // quad coordinates (u, v, 1); inv0.w: motion stretch; inv1.w: motion bend
    vec4 inv2;    // w: the splat's eye-space depth (the host's depth test)
    ivec4 box;    // inclusive pixel box x0, y0, x1, y1 (empty when culled: x0 > x1)
    vec4 emit;    // rgb; a: optical depth scale (tau x energy)
};

// Per-frame constants (vec4-only, so std140 = std430 and the Rust mirror is plain repr(C)). 592 bytes.
// Bound as a readonly storage buffer, not a uniform buffer: Mesa 22.3's lavapipe inlines uniform
// values that steer branches and recompiles the shader for every dispatch, keeping each variant until
// the pipeline dies (+0.2-0.7 MB of host memory per frame; docs/RELIABILITY.md).
struct Frame {
    mat4 view_proj;   // world -> clip (Vulkan: y down, depth 0..1)
    vec4 eye;         // world eye position; w: 1 perspective, 0 orthographic
    vec4 forward;     // unit view direction; w: near distance
    vec4 right;       // unit camera right; w: far distance
    vec4 up;          // unit camera up; w: D/p, pixels per world unit at unit depth (ortho: per unit)
    vec4 origin;      // world position of voxel (0,0,0); w: footprint radius in voxels
    vec4 spacing;     // voxel spacing xyz (the cell matrix's diagonal); w: world footprint radius
    vec4 shear;       // a sheared grid's cell matrix above the diagonal: x per j, x per k, y per k
    uvec4 dims;       // nx, ny, nz; w: splat count
    uvec4 split;      // PBTF: voxels per axis on the low side of the eye; w: 1 = back-to-front
    vec4 aa;          // x: anti-aliasing mode (AA_*); y: footprint standard deviation in voxels;
                      // z: EWA low-pass standard deviation in pixels; w: unused
    mat4 motion;      // chapter 4: grid point -> where it was at t_{i-1}, relative to the eye at t_i
    vec4 blur;        // x: delta in pixels (0 = no motion blur); y: G, the footprint's across-line
                      // integral over its area (radius units); z, w: image width and height
    mat4 motion_mid;  // arc paths: grid point -> where it was halfway through the shutter
    vec4 sweep;       // x: 1 = arc path through motion_mid, 0 = straight; y: profile along the
                      // path (SWEEP_*); z, w: unused
    uvec4 rect;       // x: 1 = a rectilinear grid (voxel positions from splat_params' Coords
                      // buffer); y: clipping planes in use; z: the projection mode (PROJECT_*,
                      // 0: compositing); w: 1 = the host's depth (HostDepth, eye-space depth per
                      // pixel) hides the splats behind it
    vec4 clip[CLIP_SLOTS];  // clipping planes (n, d): drawn where n . centre + d >= 0 for all
};

// Profiles of a motion-blurred footprint along its path (glsl/shared/footprint_table.glsl).
const uint SWEEP_UNIFORM = 0u;   // the seed's: uniform weight over the swept capsule, Eq. 4.2
const uint SWEEP_TAPERED = 1u;   // the time average of the moving footprint (brightest mid-path)
const uint SWEEP_TEARDROP = 2u;  // weighted towards t_i, fading towards t_{i-1}
const uint SWEEP_SLOTTED = 3u;   // tapered, each half of the shutter composited apart (Pass::Slots)

// Projection modes (Frame::rect.z; options::Mode::code). A projection's splat_params writes emit =
// (key, 0, 0, tau): the key a maximum takes (MIP: the value, MinIP: 1 - the value) or a sum weighs
// (average: the value, its tau 1 so the sum weighs the footprint alone; X-ray: 1).
#define PROJECT_NONE 0u
#define PROJECT_MIP 1u
#define PROJECT_MINIP 2u
#define PROJECT_AVERAGE 3u
#define PROJECT_XRAY 4u
// The isosurface (not a projection: surface splats, iso_splats; the ray caster's first crossing).
#define PROJECT_ISO 5u
// How a projection's footprints blend (the PROJECT specialization constant of tile_composite and
// footprint.frag): 0 composite, 1 the maximum of (key, 1) x the footprint over its centre's, 2 the
// sum of (key, 1) x tau x the footprint.
#define BLEND_COMPOSITE 0u
#define BLEND_MAX 1u
#define BLEND_SUM 2u
// 3 and 4: the isosurface's two passes over the same lists (tile_composite): 4 finds each pixel's
// visible depth (w), the nearest plane depth of the discs that weigh at least SURFACE_VISIBLE of a
// centre's there; 3 sums the discs within the depth band of it into (sum of w lambert, sum of w
// specular, sum of w).
#define BLEND_SURFACE 3u
#define BLEND_SURFACE_DEPTH 4u

// present.comp's sources beyond its images: over the host's image, its texels' layout.
#define PRESENT_OVER 4u
#define PRESENT_HOST_BGRA 8u
#define PRESENT_HOST_HALF 16u

#define AA_NONE 0.0
#define AA_SWAN 1.0
#define AA_EWA 2.0

// Uniforms of the ray caster. 176 bytes before the clipping planes.
struct RaycastParams {
    mat4 inv_view_proj;  // clip -> world
    vec4 box_min;        // index box sampled (voxel centres widened by one voxel); w: step length
    vec4 box_max;        // w: transmittance below which a ray stops (early ray termination)
    vec4 origin;         // world position of voxel (0,0,0); w: 1 / kernel spacing (sigma = tau * w)
    vec4 inv_spacing;    // the inverse cell matrix's diagonal (1 / voxel spacing); w: the projection
                         // mode (PROJECT_*; its field holds (value, 1, 0, tau) per voxel)
    vec4 inv_shear;      // the inverse cell matrix above its diagonal (a sheared grid's); w: unused
    uvec4 dims;          // nx, ny, nz; w: most steps per ray
    uvec4 image;         // width, height, empty-space brick side, clipping planes in use
    vec4 clip[CLIP_SLOTS];  // clipping planes (n, d): each ray cut to where n . x + d >= 0 for all
};

#define SHEET_MODE_SPLAT 0u  // per-splat over / under compositing
#define SHEET_MODE_AXIS 1u   // axis-aligned sheet summation
#define SHEET_MODE_SLAB 2u   // image-aligned sheets (slabs)
#define SHEET_MODE_BINNED 3u // axis-aligned sheets binned on the device: (splat, sheet) pairs

// A bricked batch's voxel as brick_order writes it (i | node level << 13 | j << 16, k | level << 13
// | VOXEL_MORPHS | stored value or pyramid cell << 16): its grid index (a coarse cell's lowest
// voxel; 13 bits each). Mirror: cpu::brick::voxel_ijk.
uvec3 voxel_ijk(uvec2 v) {
    return uvec3(v.x & 0x1fffu, (v.x >> 16u) & 0x1fffu, v.y & 0x1fffu);
}

// Set in a bricked voxel of a brick that morphs toward its next level (levels of detail): its
// splat grows (splat_growth), and brick_params reads no brick state for the others.
const uint VOXEL_MORPHS = 0x8000u;

// Its level of detail (0: a voxel; l: a cell of 2^l voxels a side; a node k levels above the brick
// is level 3 + k, its k in the first word). Mirror: cpu::brick::voxel_level.
uint voxel_level(uvec2 v) {
    return ((v.y >> 13u) & 3u) + ((v.x >> 13u) & 7u);
}

#define KERNEL_GAUSSIAN 0u
#define KERNEL_CUBIC 1u

#endif
