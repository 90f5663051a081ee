// Thesis 003 (Lin 2017): the path tracer, one megakernel launch per frame.
//
// One thread per path: pixel (x, y), subpixel (sx, sy) of the 2 x 2 grid
// (§4.2, 003:L221-230), path index i = 4 * (y * width + x) + 2 * sy + sx.
// Each launch is one frame of the outer loop (003:L119): every thread traces
// one path with a tent-jittered camera ray (smallpt's warp), adds its
// radiance to its slot of the accumulation buffer (progressive refinement
// across launches) and stores it in `last` (the frame alone).
//
// Traversal: the thesis' flattened kd-tree (§6.1: 16-byte nodes, the word
// axis 2 bits | leaf count 6 bits | left child 24 bits, split, right child,
// triangle offset) walked with the 8-byte short stack of Santos et al.
// (§3.4: entries {node, tfar}; tnear is the previous tfar on a pop) and the
// branch-reduced step of Fig. 15 (003:L479-492, 24-bit mask, errata 3;
// non-strict comparisons, see trace_stack()); or, for the comparison of
// 003:L175, the standard stack whose 12-byte entries also hold tnear.
// Triangles: the affine test of §6.4 (three float4 rows of the inverse of
// [A-C, B-C, N] with the translation in w; N = (A-C) x (B-C), errata 4).
//
// Shading (§4.4-4.5, §5.1): Lambertian diffuse with cosine sampling, perfect
// mirror, a glass whose Fresnel switch (Schlick, (1 - c)^5 by repeated
// multiplication; per material the exact equations instead, fresnel_exact())
// picks reflection or refraction, a rough mirror
// (Cook-Torrance: Beckmann D, Walter et al.'s approximation of Smith's G,
// Schlick's F with R0 the colour; microfacet normals sampled from D cos) and
// rough glass (Walter et al. 2007: the same D and G, Schlick's F as the
// switch between the reflected and the refracted microfacet direction), and
// the thesis' coated diffuse (§4.5: Schlick's F at the viewer's cosine
// switches between a smooth coat's mirror reflection and Ashikhmin and
// Shirley's coupled diffuse, 003:L255-263);
// emitters are one-sided (front = the winding's normal) and black. A ray
// that misses every triangle sees the equirectangular environment map, if
// any (§5.4; env()), which no light sample covers.
// Integrators: pt (BSDF sampling only), nee (a light sample and shadow ray at
// diffuse, coated and rough-mirror hits, emission after such a bounce not counted,
// 003:L249), mis (both, balance or power heuristic, §4.6). Rough glass is
// sampled only (emission after it counts in full). Russian roulette on the
// per-bounce mask (003:L267-271): continue with q = max RGB of the bounce's
// f cos / p, then divide by q. bdpt (bdpt_frame) and Metropolis light
// transport over it (mlt_init, mlt_start, mlt_frame) are below. Every integrator draws
// its random numbers through rng(K key, d): K is a path's key or an MLT
// iteration's sampler (Mlt), whose numbers are its chain's mutated samples.
//
// Random numbers are counter based: dimension d of path i in frame f is a
// hash of (i, f, seed, d), so the native path tracer (src/host/path/) draws
// the same numbers. It performs the same float operations in the same order
// (no contraction), so both render the same image bit for bit.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#pragma clang diagnostic ignored "-Wc++17-extensions"   // step()'s if constexpr (nvcc: C++17)
#endif

#define INTEGRATOR_PT 0
#define INTEGRATOR_NEE 1
#define INTEGRATOR_MIS_BALANCE 2
#define INTEGRATOR_MIS_POWER 3
#define INTEGRATOR_BDPT 4   // bdpt_frame's, never path_frame's
#define KIND_DIFFUSE 0
#define KIND_MIRROR 1
#define KIND_GLASS 2
#define KIND_EMITTER 3
#define KIND_CONDUCTOR 4     // rough mirror: Cook-Torrance, Beckmann
#define KIND_ROUGH_GLASS 5   // rough glass: Walter et al. 2007, Beckmann
#define KIND_TRANSLUCENT 6   // subsurface scattering (§5.3): sss_frame only
#define KIND_TEXTURED 7      // texture maps, the metalness workflow: texture_frame alone (texture_hit())
#define KIND_COATED 8        // §4.5's dielectric over Ashikhmin-Shirley's diffuse: the Fresnel switch in scatter()
#define PI_F 3.14159265358979324f
#if defined(__NVCC__)
#define FLOORF floorf
#else
#define FLOORF __builtin_floorf   // cvt.rmi.f32.f32, as CUDA's floorf
#endif
#define TRAVERSAL_SHORT_STACK 0
#define TRAVERSAL_RESTART 1
#define TRAVERSAL_BACKTRACK 2
#define TRAVERSAL_FULL_STACK 3   // the standard 12-byte entries {node, tnear, tfar}
#define LEAF_AXIS 3u
#define STACK_ENTRIES 32
// random dimensions: 2 for the camera ray, then 8 per bounce
#define DIMS_CAMERA 2u
#define DIMS_PER_BOUNCE 8u
#define DIMS_LIGHT 0x10000u   // bdpt's light subpath: 5 at y0, then 8 per bounce
#define INV_PI 0.318309886183790672f

// Scene, camera and frame, laid out by src/host/path/kernel.rs.
struct Params {
  float cam_pos[3], cam_fwd[3], cam_right[3], cam_up[3];
  float lo[3], hi[3];
  float eps, tan_half, aspect, light_area;
  int width, height, num_paths, frame, integrator, max_bounces, num_lights, seed, traversal;
  int env_w, env_h;   // the environment map's texels across and down (0: none)
  float mlt_b;        // mlt_frame: the bootstrap's mean luminance b (003:L330)
  int strata;         // PATH_STRATIFIED's D x D strata of a subpixel: D row by row, -D progressive (the other builds read none)
};

struct V3 { float x, y, z; };
static __device__ __forceinline__ V3 v3(float x, float y, float z) { V3 r = {x, y, z}; return r; }
static __device__ __forceinline__ float comp(V3 v, unsigned k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
static __device__ __forceinline__ float dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static __device__ __forceinline__ V3 add3(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static __device__ __forceinline__ V3 sub3(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static __device__ __forceinline__ V3 mul3(V3 a, V3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static __device__ __forceinline__ V3 scale3(V3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static __device__ __forceinline__ V3 normalize3(V3 v) {
  float inv = 1.0f / sqrtf(v.x * v.x + v.y * v.y + v.z * v.z);
  return v3(v.x * inv, v.y * inv, v.z * inv);
}

struct Scene {
  const Params *p;
  const uint4 *nodes;      // 16-byte nodes (§6.1)
  const unsigned *refs;    // the concatenated leaf triangle lists
  const float4 *tris;      // 3 float4 per triangle: the affine rows (§6.4)
  const float4 *tri_data;  // per triangle: unit geometric normal, material index (int bits)
  const float4 *mats;      // per material: [r g b kind], [emission rgb, ior], [alpha, exact Fresnel (1) or Schlick's (0), an anisotropic mirror's or rough glass's alpha_y (0: isotropic), 0]
  const float4 *lights;    // per emitting triangle: [v0, cdf], [e1, triangle (int bits)], [e2, 0]
  const float4 *boxes;     // per node (kd-backtrack): [box lo, parent (int bits)], [box hi, 0]
  const float4 *env;       // the environment map (§5.4): env_w x env_h texels [r g b 0], row 0 the zenith
};

// The counter-based generator (two rounds of a 32-bit integer hash per draw).
static __device__ __forceinline__ unsigned mix(unsigned h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}
// The key of path i in frame f.
static __device__ __forceinline__ unsigned path_key(unsigned i, unsigned frame, unsigned seed) {
  return mix(i * 0x9e3779b9u ^ mix(frame * 0x632be5abu + seed));
}
// Dimension d of a path: a uniform float in [0, 1) with 24 random bits.
static __device__ __forceinline__ float rng(unsigned key, unsigned d) {
  unsigned h = mix(mix(key ^ (d + 1u) * 0x85ebca6bu));
  return (float)(h >> 8) * (1.0f / 16777216.0f);
}

// (cos, sin) of the azimuth 2 pi y for y in [0, 1): a quarter turn q = floor(4y),
// the rest x in [-pi/4, pi/4) by Taylor polynomials (error < 1e-8), rotated by
// pi/4 and q quarter turns (the photon kernel's; no sin/cos instruction).
static __device__ __forceinline__ void azimuth(float y, float *c, float *s) {
  float f4 = y * 4.0f;
  int q = (int)f4;
  float x = (f4 - (float)q) * 1.57079632679489662f - 0.785398163397448310f;
  float x2 = x * x;
  float sx = x * (1.0f - x2 / 6.0f * (1.0f - x2 / 20.0f * (1.0f - x2 / 42.0f * (1.0f - x2 / 72.0f))));
  float cx = 1.0f - x2 / 2.0f * (1.0f - x2 / 12.0f * (1.0f - x2 / 30.0f * (1.0f - x2 / 56.0f * (1.0f - x2 / 90.0f))));
  float h = 0.707106781186547524f;
  float cr = (cx - sx) * h, sr = (sx + cx) * h;
  if (q == 0) { *c = cr; *s = sr; }
  else if (q == 1) { *c = -sr; *s = cr; }
  else if (q == 2) { *c = -cr; *s = -sr; }
  else { *c = sr; *s = -cr; }
}

// ln x for a normal positive x: x = 2^e m with m in [sqrt(1/2), sqrt(2)),
// ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.172, by its series to
// s^11 (no lg2 instruction; the native mirror computes the same operations).
static __device__ __forceinline__ float ln(float x) {
  int bits = __float_as_int(x);
  int e = ((bits >> 23) & 255) - 127;
  float m = __int_as_float((bits & 0x7fffff) | 0x3f800000);
  if (m > 1.41421356237309505f) {   // sqrt 2
    m = m * 0.5f;
    e = e + 1;
  }
  float sv = (m - 1.0f) / (m + 1.0f);
  float s2 = sv * sv;
  float poly = 1.0f + s2 * (1.0f / 3.0f + s2 * (0.2f + s2 * (1.0f / 7.0f + s2 * (1.0f / 9.0f + s2 * (1.0f / 11.0f)))));
  return (float)e * 0.693147180559945309f + 2.0f * sv * poly;
}

// e^x for x <= 0 (0 below -87): x = n ln 2 + r (Cody-Waite, two parts of
// ln 2), |r| <= ln 2 / 2, e^r by its Taylor series to r^7 (no ex2 instruction).
static __device__ __forceinline__ float exp_neg(float x) {
  if (x < -87.0f) return 0.0f;
  float n = FLOORF(x * 1.44269504088896341f + 0.5f);
  float r = x - n * 0.693145751953125f - n * 1.42860682030941723e-6f;
  float poly = 1.0f + r * (1.0f + r * 0.5f * (1.0f + r / 3.0f * (1.0f + r * 0.25f * (1.0f + r * 0.2f * (1.0f + r / 6.0f * (1.0f + r / 7.0f))))));
  return poly * __int_as_float(((int)n + 127) << 23);
}

// ---- Metropolis light transport's samples (§4.8; the kernels: mlt_init, mlt_start, mlt_frame) ----
//
// Primary sample space (Kelemen et al. 2002; "store and mutate only the random
// numbers", 003:L316): a chain keeps the path's random numbers as floats in
// global memory, 10 a path segment (003:L328), k = max bounces + 1 segments.
// The integrators draw dimension d through rng(K key, d); with the sampler Mlt
// the value is the chain's slot mlt_slot(d) after the iteration's mutation.
#define MLT_SLOTS_PER_SEGMENT 10u
#define MLT_DIM_LARGE 0x30000u    // the iteration's large-or-small choice
#define MLT_DIM_ACCEPT 0x30001u   // the acceptance test (the host's start pick: its choice)
#define MLT_P_LARGE 0.25f         // 003:L318's example: 1 large per 3 small on average
#define MLT_S2 (1.0f / 64.0f)     // Kelemen's small step: s1 = 1/1024, s2 = 1/64 (not stated)
#define MLT_LN_S2_S1 2.77258872223978124f   // ln(s2 / s1) = ln 16

// The slot of dimension d for max bounces m: segment s holds in slots 0-6 the
// eye bounce's dimensions 2 + 8 s + j (j = 0-6: the light point, the
// direction, roulette, the Fresnel switch) and in slots 7-9 bdpt's light
// vertex s's (direction and roulette, j = 3-5); y0's point takes segment 0's
// 7-9 and its direction segment 1's 7-8 (vertex 1 draws none); the camera's 2
// take segment m's 0-1 (bounce m draws none). Dimensions no integrator draws
// may share a slot.
static __device__ __forceinline__ unsigned mlt_slot(unsigned d, unsigned m) {
  if (d < DIMS_CAMERA) return MLT_SLOTS_PER_SEGMENT * m + d;
  if (d < DIMS_LIGHT) {
    unsigned e = d - DIMS_CAMERA;
    return MLT_SLOTS_PER_SEGMENT * (e >> 3) + (e & 7u);
  }
  unsigned e = d - DIMS_LIGHT, c = e >> 3, j = e & 7u;
  if (c == 0u) return j < 3u ? 7u + j : 14u + j;
  return MLT_SLOTS_PER_SEGMENT * c + 4u + j;
}

// An MLT iteration's sampler: the chain's current samples u (slots floats), the
// iteration's key (the mutation's random numbers) and whether it is a large step.
struct Mlt {
  const float *u;
  unsigned key, slots, max_bounces;
  bool large;
};

// Slot `slot` of the proposal: a large step draws it afresh; a small step moves
// the current value by s2 e^(-ln(s2 / s1) v) (Kelemen's exponential
// perturbation, "sampled by an exponential distribution", 003:L318), up or down
// with equal probability, wrapped into [0, 1).
static __device__ __forceinline__ float mlt_value(const Mlt &m, unsigned slot) {
  float r = rng(m.key, slot);
  if (m.large) return r;
  float x = m.u[slot];
  float r2 = r * 2.0f;
  bool up = r2 < 1.0f;
  float v = up ? r2 : r2 - 1.0f;
  float dv = MLT_S2 * exp_neg(-MLT_LN_S2_S1 * v);
  x = up ? x + dv : x - dv;
  if (x >= 1.0f) x = x - 1.0f;
  if (x < 0.0f) x = x + 1.0f;
  if (!(x < 1.0f)) x = __int_as_float(0x3f7fffff);   // a tiny negative x + 1 rounds to 1
  return x;
}

// Dimension d drawn through an MLT sampler (a dimension beyond the slots,
// which no integrator draws, is fresh).
static __device__ __forceinline__ float rng(const Mlt &m, unsigned d) {
  unsigned slot = mlt_slot(d, m.max_bounces);
  return slot < m.slots ? mlt_value(m, slot) : rng(m.key, d);
}

// Beckmann's distribution (§5.1, 003:L344) of a microfacet normal whose cosine
// with the macro normal is cm, for a2 = alpha^2: e^(-tan^2 / a2) / (pi a2 cos^4).
static __device__ __forceinline__ float beckmann(float a2, float cm) {
  if (!(cm > 0.0f)) return 0.0f;
  float c2 = cm * cm;
  float tan2 = (1.0f - c2) / c2;
  return exp_neg(-tan2 / a2) / (PI_F * a2 * (c2 * c2));
}

// Smith's masking of direction v (cosine cv with the macro normal, cvm with the
// microfacet normal) by Walter et al. 2007's rational approximation for
// Beckmann ("a numerical approximation to Smith shadowing function", 003:L357);
// 0 when v sees the microfacet's back.
static __device__ __forceinline__ float smith_g1(float alpha, float cv, float cvm) {
  if (!(cvm * cv > 0.0f)) return 0.0f;
  float acv = fabsf(cv);
  float a = acv / (alpha * sqrtf(fmaxf(1.0f - acv * acv, 0.0f)));
  if (a >= 1.6f) return 1.0f;
  return (3.535f * a + 2.181f * (a * a)) / (1.0f + 2.276f * a + 2.577f * (a * a));
}

// Schlick's Fresnel term with reflectance r0 at normal incidence, c the cosine
// (§4.5, 003:L255-259; (1 - c)^5 by repeated multiplication).
static __device__ __forceinline__ float schlick(float r0, float c) {
  float x = 1.0f - c;
  float x2 = x * x;
  return r0 + (1.0f - r0) * (x2 * x2 * x);
}

// Ashikhmin and Shirley's (2000) transmission factor of the coupled diffuse
// lobe (§4.5, 003:L261-263): 1 - (1 - c/2)^5, the power by multiplication as
// Schlick's (003:L259).
static __device__ __forceinline__ float as_factor(float c) {
  float x = 1.0f - 0.5f * c;
  float x2 = x * x;
  return 1.0f - x2 * x2 * x;
}

// A coated material's (KIND_COATED) Schlick reflectance at normal incidence from its IOR (003:L255).
static __device__ __forceinline__ float coat_r0(float ior) {
  float r0 = (1.0f - ior) / (1.0f + ior);
  return r0 * r0;
}

// atan s for |s| <= tan(pi/8) by its series to s^15 (error < 2e-8).
static __device__ __forceinline__ float atan_series(float s) {
  float s2 = s * s;
  return s * (1.0f - s2 * (1.0f / 3.0f - s2 * (0.2f - s2 * (1.0f / 7.0f - s2 * (1.0f / 9.0f - s2 * (1.0f / 11.0f - s2 * (1.0f / 13.0f - s2 / 15.0f)))))));
}

// atan2(y, x) in [-pi, pi] with no SFU instruction: t = min / max of |x|, |y|
// in [0, 1]; above tan(pi/8), atan t = pi/4 + atan((t - 1) / (t + 1)); then
// the octant.
static __device__ __forceinline__ float atan2_series(float y, float x) {
  float ax = fabsf(x), ay = fabsf(y);
  float mx = fmaxf(ax, ay), mn = fminf(ax, ay);
  float t = mx > 0.0f ? mn / mx : 0.0f;
  float a = t > 0.414213562373095049f ? 0.785398163397448310f + atan_series((t - 1.0f) / (t + 1.0f)) : atan_series(t);
  if (ay > ax) a = 1.57079632679489662f - a;
  if (x < 0.0f) a = PI_F - a;
  return y < 0.0f ? -a : a;
}

// The exact Fresnel reflectance of a dielectric (unpolarised light: the mean
// of the s and p reflectances) for the incident cosine ci and the transmitted
// cosine ct, eta = n_i / n_t, no total internal reflection: r_s = (eta ci -
// ct) / (eta ci + ct), r_p = (ci - eta ct) / (ci + eta ct). A glass whose
// scene file says fresnel = "exact" switches on it instead of Schlick's.
static __device__ __forceinline__ float fresnel_exact(float eta, float ci, float ct) {
  float rs = (eta * ci - ct) / (eta * ci + ct);
  float rp = (ci - eta * ct) / (ci + eta * ct);
  return 0.5f * (rs * rs + rp * rp);
}

// The Fresnel term of a smooth dielectric surface: the exact equations, or
// Schlick's with R0 from the IOR and (1 - c)^5 by multiplication (003:L259),
// c the cosine on the outer side; eta = n_i / n_t. translucent()'s; the glass
// of scatter() computes the same inline (as written before SSS, so that the
// existing kernels' PTX stays as it was in both dialects).
static __device__ __forceinline__ float surface_fresnel(bool exact, float ior, bool into, float eta, float cos_i,
                                                        float cos_t) {
  if (exact) return fresnel_exact(eta, cos_i, cos_t);
  float r0 = (1.0f - ior) / (1.0f + ior);
  r0 = r0 * r0;
  float c = 1.0f - (into ? cos_i : cos_t);
  float c2 = c * c;
  return r0 + (1.0f - r0) * (c2 * c2 * c);
}

// smallpt's tent warp of a uniform y in [0, 1) to [-1, 1).
static __device__ __forceinline__ float tent(float y) {
  float r = 2.0f * y;
  return r < 1.0f ? sqrtf(r) - 1.0f : 1.0f - sqrtf(2.0f - r);
}

// §6.4: the affine test; updates *t_hit and returns true on a hit in [t_min, *t_hit].
static __device__ __forceinline__ bool affine(const Scene &s, unsigned t, V3 o, V3 d, float t_min, float *t_hit) {
  const float4 *m = s.tris + 3 * t;
  float4 r2 = m[2];
  float oz = r2.x * o.x + r2.y * o.y + r2.z * o.z + r2.w;
  float dz = r2.x * d.x + r2.y * d.y + r2.z * d.z;
  float tt = -oz / dz;                                   // @count tri_tests div.rn.f32
  if (!(tt >= t_min && tt <= *t_hit)) return false;
  float4 r0 = m[0];
  float u = r0.x * o.x + r0.y * o.y + r0.z * o.z + r0.w + tt * (r0.x * d.x + r0.y * d.y + r0.z * d.z);
  if (u < 0.0f) return false;
  float4 r1 = m[1];
  float v = r1.x * o.x + r1.y * o.y + r1.z * o.z + r1.w + tt * (r1.x * d.x + r1.y * d.y + r1.z * d.z);
  if (v < 0.0f || u + v > 1.0f) return false;
  *t_hit = tt;
  return true;
}

// The exit distance of the ray from box [lo, hi] (the scene clip's expression).
static __device__ __forceinline__ float box_exit(float4 lo, float4 hi, V3 o, V3 inv) {
  float t0x = (lo.x - o.x) * inv.x, t1x = (hi.x - o.x) * inv.x;
  float t0y = (lo.y - o.y) * inv.y, t1y = (hi.y - o.y) * inv.y;
  float t0z = (lo.z - o.z) * inv.z, t1z = (hi.z - o.z) * inv.z;
  return fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
}

// kd-restart and kd-backtrack (Foley and Sugerman 2005; §3.4, 003:L173): no
// stack. Each descent goes to the nearest leaf of [tnear, tfar] with Fig. 15's
// step as printed (f = int(floor(tnear - tsplit)) >> 31, strict, narrowing
// tfar when tsplit < tfar); a leaf without a hit moves tnear to its exit.
// kd-restart then descends again from the root with tfar the scene exit;
// kd-backtrack climbs the parent links until a node's box reaches past tnear
// and descends from there with tfar that box's exit. Both visit the same
// leaves; the trees put triangles lying in a split plane on both sides
// (003:L566; src/host/path/build.rs), so no zero-thickness leaf is skipped.
static __device__ int trace_stackless(const Scene &s, bool backtrack, V3 o, V3 d, V3 inv, float t_min, float t_max,
                                      float tnear, float t_exit, bool any, float *t_out) {
  const Params *p = s.p;
  float t_hit = t_max, tfar = t_exit;
  int found = -1;
  unsigned idx = 0;
  for (;;) {
    uint4 n = s.nodes[idx];
    while ((n.x >> 30) != LEAF_AXIS) {
      unsigned axis = n.x >> 30;
      float tsplit = (__uint_as_float(n.y) - comp(o, axis)) * comp(inv, axis);   // @count inner mul.rn.f32
      unsigned first = n.x & 0xffffffu, second = n.z;
      if (__float_as_int(comp(d, axis)) < 0) {
        unsigned t = first;
        first = second;
        second = t;
      }
      int f = (int)FLOORF(tnear - tsplit) >> 31;      // Fig. 15 as printed
      idx = (first & (unsigned)f) + (second & ~(unsigned)f);
      if (f < 0 && tsplit < tfar) tfar = tsplit;
      n = s.nodes[idx];
    }
    unsigned count = (n.x >> 24) & 63u, first = n.w;   // @count leaves bfe.u32
    float lo = fmaxf(tnear - p->eps, t_min);
    float hi = fminf(t_hit, tfar + p->eps);
    for (unsigned r = 0; r < count; r++) {
      unsigned t = s.refs[first + r];
      if (affine(s, t, o, d, lo, &hi)) {
        found = (int)t;
        if (any) break;
      }
    }
    if (found >= 0) {
      t_hit = hi;
      break;
    }
    if (!(tfar < t_exit)) break;
    tnear = tfar;
    if (backtrack) {
      for (;;) {
        idx = __float_as_uint(s.boxes[2 * idx].w);
        float4 blo = s.boxes[2 * idx], bhi = s.boxes[2 * idx + 1];   // @count ascents shl.b32
        tfar = fminf(t_max, box_exit(blo, bhi, o, inv));
        if (idx == 0 || tnear < tfar) break;
      }
    } else {
      idx = 0;
      tfar = t_exit;
    }
  }
  *t_out = t_hit;
  return found;
}

// A short-stack entry (Santos et al., 003:L175): the node and its tfar, 8
// bytes; tnear is the previous tfar on a pop. The standard entry (WIDE)
// also stores tnear: 12 bytes.
template <bool WIDE> struct Entry { unsigned node; float tfar; };
template <> struct Entry<true> { unsigned node; float tfar, tnear; };
static __device__ __forceinline__ void put_tnear(Entry<false> &, float) {}
static __device__ __forceinline__ void put_tnear(Entry<true> &e, float t) { e.tnear = t; }
static __device__ __forceinline__ float get_tnear(const Entry<false> &, float prev_tfar) { return prev_tfar; }
static __device__ __forceinline__ float get_tnear(const Entry<true> &e, float) { return e.tnear; }

// The stack traversal of [tnear, tfar] with WIDE's entries.
template <bool WIDE>
static __device__ __forceinline__ int trace_stack(const Scene &s, V3 o, V3 d, V3 inv, float t_min, float t_max,
                                                  float tnear, float tfar, bool any, float *t_out) {
  const Params *p = s.p;
  float t_hit = t_max;
  int found = -1;
  Entry<WIDE> stack[STACK_ENTRIES];
  int size = 0;
  unsigned idx = 0;
  for (;;) {
    uint4 n = s.nodes[idx];
    while ((n.x >> 30) != LEAF_AXIS) {                // Fig. 15: one branch-reduced step
      unsigned axis = n.x >> 30;
      float tsplit = (__uint_as_float(n.y) - comp(o, axis)) * comp(inv, axis);   // @count inner mul.rn.f32
      unsigned first = n.x & 0xffffffu, second = n.z;
      if (__float_as_int(comp(d, axis)) < 0) {
        unsigned t = first;
        first = second;
        second = t;
      }
      // Fig. 15 computes f = int(floor(tnear - tsplit)) >> 31, -1 iff tnear < tsplit,
      // and pushes when tsplit < tfar. Both comparisons are non-strict here:
      // the project's builder keeps a triangle lying in a split plane on one
      // side only (the thesis' builder puts it on both, 003:L566), so a ray
      // that meets the plane at tnear or tfar must visit both children.
      int f = -(int)(tnear <= tsplit);                 // mask and add, no branch
      idx = (first & (unsigned)f) + (second & ~(unsigned)f);
      if (f < 0 && tsplit <= tfar) {
        stack[size].node = second;                    // @count push st.local.u32
        stack[size].tfar = tfar;
        put_tnear(stack[size], tsplit);
        size++;
        tfar = tsplit;
      }
      n = s.nodes[idx];
    }
    unsigned count = (n.x >> 24) & 63u, first = n.w;   // @count leaves bfe.u32
    float lo = fmaxf(tnear - p->eps, t_min);
    float hi = fminf(t_hit, tfar + p->eps);
    for (unsigned r = 0; r < count; r++) {
      unsigned t = s.refs[first + r];
      if (affine(s, t, o, d, lo, &hi)) {
        found = (int)t;
        if (any) break;
      }
    }
    if (found >= 0) {
      t_hit = hi;
      break;
    }
    if (size == 0) break;
    size--;
    idx = stack[size].node;                            // @count pop ld.local.u32
    tnear = get_tnear(stack[size], tfar);
    tfar = stack[size].tfar;
  }
  *t_out = t_hit;
  return found;
}

// The nearest hit in [t_min, t_max] (with `any`, the first found); -1 for none.
static __device__ int trace(const Scene &s, V3 o, V3 d, float t_min, float t_max, bool any, float *t_out) {
  const Params *p = s.p;
  float inv_x = 1.0f / d.x;                          // @count rays rcp.rn.f32
  V3 inv = v3(inv_x, 1.0f / d.y, 1.0f / d.z);
  // clip to the scene box
  float t0x = (p->lo[0] - o.x) * inv.x, t1x = (p->hi[0] - o.x) * inv.x;
  float t0y = (p->lo[1] - o.y) * inv.y, t1y = (p->hi[1] - o.y) * inv.y;
  float t0z = (p->lo[2] - o.z) * inv.z, t1z = (p->hi[2] - o.z) * inv.z;
  float tn = fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fminf(t0z, t1z));
  float tf = fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
  float tnear = fmaxf(t_min, tn), tfar = fminf(t_max, tf);
  if (!(tnear <= tfar)) return -1;
  if (p->traversal == TRAVERSAL_SHORT_STACK)
    return trace_stack<false>(s, o, d, inv, t_min, t_max, tnear, tfar, any, t_out);
  if (p->traversal == TRAVERSAL_FULL_STACK)
    return trace_stack<true>(s, o, d, inv, t_min, t_max, tnear, tfar, any, t_out);
  return trace_stackless(s, p->traversal == TRAVERSAL_BACKTRACK, o, d, inv, t_min, t_max, tnear, tfar, any, t_out);
}

// A heuristic's weight of a strategy with pdf a against one with pdf b.
static __device__ __forceinline__ float mis_weight(int integrator, float a, float b) {
  if (integrator == INTEGRATOR_MIS_POWER) {
    a = a * a;
    b = b * b;
  }
  return a / (a + b);
}

// Duff et al.'s orthonormal basis around the unit n.
static __device__ __forceinline__ void basis(V3 n, V3 *b1, V3 *b2) {
  float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + n.z);
  float b = n.x * n.y * a;
  *b1 = v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  *b2 = v3(b, sign + n.y * n.y * a, -n.y);
}

// The thesis' anisotropic Beckmann lobe of a mirror ("Wald model (Ward, 1992)",
// §5.1, 003:L346-352): alpha_x along b1, alpha_y along b2 of Duff et al.'s
// basis around the face's winding normal n, whichever side is hit (the lobe
// is symmetric about both axes).
struct Aniso {
  V3 b1, b2;
  float ax, ay;
};

static __device__ __forceinline__ Aniso aniso(V3 n, float ax, float ay) {
  Aniso a;
  basis(n, &a.b1, &a.b2);
  a.ax = ax;
  a.ay = ay;
  return a;
}

// D_aniso (003:L346) of the unit microfacet normal m, cm its cosine with the
// macro normal: e^(-tan^2 (cos^2 phi / ax^2 + sin^2 phi / ay^2)) / (pi ax ay cos^4).
static __device__ __forceinline__ float beckmann_aniso(const Aniso &a, V3 m, float cm) {
  if (!(cm > 0.0f)) return 0.0f;
  float x = dot3(m, a.b1) / a.ax, y = dot3(m, a.b2) / a.ay;
  float c2 = cm * cm;
  return exp_neg(-(x * x + y * y) / c2) / (PI_F * a.ax * a.ay * (c2 * c2));
}

// The roughness Smith's G1 sees along the unit v: sqrt(cos^2 phi ax^2 + sin^2
// phi ay^2) of v's azimuth (the slopes' spread in v's plane; 003:L357 prints
// 1 / (cos^2 phi / ax^2 + sin^2 phi / ay^2) there, D's term: an erratum).
static __device__ __forceinline__ float alpha_along(const Aniso &a, V3 v) {
  float x = dot3(v, a.b1), y = dot3(v, a.b2);
  float r2 = x * x + y * y;
  if (!(r2 > 0.0f)) return a.ax;   // along the normal: G1 = 1 at any alpha
  return sqrtf((x * x * (a.ax * a.ax) + y * y * (a.ay * a.ay)) / r2);
}

// A microfacet normal from D_aniso cos on the side of ns (003:L350-352):
// phi = arctan(ay / ax tan(2 pi y2)) in 2 pi y2's quadrant (the seed omits
// the quadrant), taken as the direction of (ax cos 2 pi y2, ay sin 2 pi y2);
// tan^2 theta = -ln(1 - y1) / (cos^2 phi / ax^2 + sin^2 phi / ay^2); *cm its cosine.
static __device__ __forceinline__ V3 sample_aniso(const Aniso &a, V3 ns, float y1, float y2, float *cm) {
  float c, sn;
  azimuth(y2, &c, &sn);
  float ex = a.ax * c, ey = a.ay * sn;
  float r = 1.0f / sqrtf(ex * ex + ey * ey);
  float cp = ex * r, sp = ey * r;
  float tan2 = -ln(1.0f - y1) / (cp * cp / (a.ax * a.ax) + sp * sp / (a.ay * a.ay));
  *cm = 1.0f / sqrtf(1.0f + tan2);
  float sm = sqrtf(tan2) * *cm;
  return add3(add3(scale3(a.b1, sm * cp), scale3(a.b2, sm * sp)), scale3(ns, *cm));
}

// A cosine-weighted direction about the unit n from uniforms y1 (the radius
// sqrt y1 on the disc) and y2 (the azimuth); *lz its cosine with n.
static __device__ __forceinline__ V3 cosine_dir(V3 n, float y1, float y2, float *lz) {
  float r = sqrtf(y1), c, sn;
  azimuth(y2, &c, &sn);
  *lz = sqrtf(fmaxf(1.0f - y1, 0.0f));
  V3 b1, b2;
  basis(n, &b1, &b2);
  return add3(add3(scale3(b1, r * c), scale3(b2, r * sn)), scale3(n, *lz));
}

// The environment's radiance in the unit direction d (§5.4, 003:L411: the
// "spherical projection map" of an infinitely distant sphere), in Mitsuba 3's
// envmap conventions (tools/mitsuba/reference.py checks them against it): y
// up, u = atan2(x, -z) / 2 pi, v = acos(y) / pi; texel column c centred at
// u = (c + 1/2) / W, row r on v = r / (H - 1); bilinear, periodic in u.
static __device__ __forceinline__ V3 env(const Scene &s, V3 d) {
  const Params *p = s.p;
  int w = p->env_w, h = p->env_h;
  float u = atan2_series(d.x, -d.z) * (0.5f * INV_PI) - 0.5f / (float)w;
  float v = atan2_series(sqrtf(d.x * d.x + d.z * d.z), d.y) * INV_PI;
  u = u - FLOORF(u);
  v = v - FLOORF(v);
  float x = u * (float)w, y = v * (float)(h - 1);
  int px = (int)x, py = (int)y;
  if (px > w - 1) px = w - 1;
  if (py > h - 2) py = h - 2;
  float fx = x - (float)px, fy = y - (float)py;
  float gx = 1.0f - fx, gy = 1.0f - fy;
  int qx = px + 1 == w ? 0 : px + 1;
  const float4 *r0 = s.env + py * w, *r1 = r0 + w;
  float4 a = r0[px], b = r0[qx], c = r1[px], e = r1[qx];
  return v3(gy * (gx * a.x + fx * b.x) + fy * (gx * c.x + fx * e.x),
            gy * (gx * a.y + fx * b.y) + fy * (gx * c.y + fx * e.y),
            gy * (gx * a.z + fx * b.z) + fy * (gx * c.z + fx * e.z));
}

// One path's state between bounces (the per-path struct of 003:L534: next
// ray, mask, pixel, activeness, and what the estimators carry across a bounce).
struct Path {
  V3 o, d;                // the next ray
  V3 L, beta;             // radiance gathered, the mask (path throughput)
  int bounce;             // bounces taken
  bool count_emission;    // camera rays and specular bounces see emitters
  float bsdf_pdf;         // solid-angle pdf of the last diffuse bounce (mis)
};

// The camera ray through the image point (px, py), in pixels from the top left.
static __device__ __forceinline__ Path camera_through(const Params *p, float px, float py) {
  float cx = (px / (float)p->width * 2.0f - 1.0f) * p->tan_half * p->aspect;
  float cy = (1.0f - py / (float)p->height * 2.0f) * p->tan_half;
  V3 fwd = v3(p->cam_fwd[0], p->cam_fwd[1], p->cam_fwd[2]);
  V3 right = v3(p->cam_right[0], p->cam_right[1], p->cam_right[2]);
  V3 up = v3(p->cam_up[0], p->cam_up[1], p->cam_up[2]);
  Path P;
  P.o = v3(p->cam_pos[0], p->cam_pos[1], p->cam_pos[2]);
  P.d = normalize3(add3(add3(fwd, scale3(right, cx)), scale3(up, cy)));
  P.L = v3(0.0f, 0.0f, 0.0f);
  P.beta = v3(1.0f, 1.0f, 1.0f);
  P.bounce = 0;
  P.count_emission = true;
  P.bsdf_pdf = 0.0f;
  return P;
}

// Path i's camera ray: tent-jittered in subpixel (sub & 1, sub >> 1) of the 2 x 2
// grid by the tent filter's uniforms r0 (across) and r1 (down).
static __device__ __forceinline__ Path camera_ray(const Params *p, int i, float r0, float r1) {
  int pixel = i >> 2, sub = i & 3;
  int x = pixel % p->width, y = pixel / p->width;
  float px = (float)x + ((float)(sub & 1) + 0.5f + tent(r0)) * 0.5f;
  float py = (float)y + ((float)(sub >> 1) + 0.5f + tent(r1)) * 0.5f;
  return camera_through(p, px, py);
}

#if defined(PATH_STRATIFIED)
// The progressive order of the strata (Params::strata = -D, D a power of two):
// frame f's stratum of the D x D grid is read from k = f mod D^2 two bits at a
// time, the lowest pair choosing the quadrant of the subpixel, the next the
// quadrant of that, and so on; each pair is XORed with two bits hashed from
// the subpixel's key and the quadrants chosen so far (Owen's nested
// scrambling). So every 4^j aligned frames put one ray in each cell of a
// 2^j x 2^j grid, and, the scramble being uniform, each frame's ray is
// uniform over the subpixel: every frame count is a fair image (successive
// refinement) and every 4^j frames a stratified one. (sx, sy): the stratum.
static __device__ __forceinline__ void progressive_stratum(unsigned k, int d, unsigned key, int *sx, int *sy) {
  unsigned x = 0u, y = 0u, node = 1u;
  for (int b = 1; b < d; b <<= 1, k >>= 2) {
    unsigned q = (k & 3u) ^ (mix(key ^ node * 0x85ebca6bu) & 3u);
    x = x * 2u + (q & 1u);
    y = y * 2u + (q >> 1);
    node = node * 4u + q;
  }
  *sx = (int)x;
  *sy = (int)y;
}
// The key of subpixel path i's scramble under seed: the same in every frame.
static __device__ __forceinline__ unsigned scramble_key(unsigned i, unsigned seed) {
  return mix(i * 0x9e3779b9u ^ mix(seed + 0x68e31da4u));
}

// The stratified build's camera ray (§4.2's alternative, 003:L223): the
// subpixel (sub & 1, sub >> 1) is cut into a D x D grid (D = |p->strata|) and
// frame f takes stratum s = f mod D^2, row by row from the top left (s % D
// across, s / D down), the same in every pixel (strata = D), or in the
// progressive order above (strata = -D); r0 and r1 place the ray uniformly
// in it (a box filter). Row by row, only every D^2 frames cover the subpixel.
static __device__ __forceinline__ Path camera_stratified(const Params *p, int i, float r0, float r1) {
  int pixel = i >> 2, sub = i & 3;
  int x = pixel % p->width, y = pixel / p->width;
  int d = p->strata, sx, sy;
  if (d < 0) {
    d = -d;
    progressive_stratum((unsigned)(p->frame % (d * d)), d, scramble_key((unsigned)i, (unsigned)p->seed), &sx, &sy);
  } else {
    int s = p->frame % (d * d);
    sx = s % d;
    sy = s / d;
  }
  float px = (float)x + ((float)(sub & 1) + ((float)sx + r0) / (float)d) * 0.5f;
  float py = (float)y + ((float)(sub >> 1) + ((float)sy + r1) / (float)d) * 0.5f;
  return camera_through(p, px, py);
}
#endif

// Path i's camera ray from dimensions 0 and 1: the tent filter's uniforms
// (the stratified build: the place in the frame's stratum).
static __device__ __forceinline__ Path camera_path(const Params *p, int i, unsigned key) {
#if defined(PATH_STRATIFIED)
  return camera_stratified(p, i, rng(key, 0), rng(key, 1));
#else
  return camera_ray(p, i, rng(key, 0), rng(key, 1));
#endif
}

// The next direction at a hit (d in, the sampled direction out) and the
// bounce's mask f cos / p in wgt; false when the path ends there.
template <class K>
static __device__ __forceinline__ bool scatter(const Scene &s, Path &P, float4 td, int kind, V3 ns, V3 color,
                                               float cos_d, float cos_o, K key, unsigned dim, V3 &d, V3 &wgt) {
  wgt = color;
  if (kind == KIND_DIFFUSE) {
    float lz;
    d = cosine_dir(ns, rng(key, dim + 3), rng(key, dim + 4), &lz);
    P.bsdf_pdf = lz * INV_PI;
    P.count_emission = false;
  } else if (kind == KIND_CONDUCTOR || kind == KIND_ROUGH_GLASS) {
    // a microfacet normal from Beckmann's D cos: tan^2 = -a2 ln(1 - y), uniform azimuth (§5.1);
    // an anisotropic mirror's or rough glass's (alpha_y > 0) from D_aniso cos
    float4 r = s.mats[3 * __float_as_int(td.w) + 2];
    float alpha = r.x;
    float a2 = alpha * alpha;
    V3 mh;
    float cm;
    Aniso an;
    if (r.z > 0.0f) {
      an = aniso(cos_d < 0.0f ? ns : v3(-ns.x, -ns.y, -ns.z), alpha, r.z);
      mh = sample_aniso(an, ns, rng(key, dim + 3), rng(key, dim + 4), &cm);
    } else {
      float tan2 = a2 * -ln(1.0f - rng(key, dim + 3));
      cm = 1.0f / sqrtf(1.0f + tan2);
      float sm = sqrtf(tan2) * cm;
      float c, sn;
      azimuth(rng(key, dim + 4), &c, &sn);
      V3 b1, b2;
      basis(ns, &b1, &b2);
      mh = add3(add3(scale3(b1, sm * c), scale3(b2, sm * sn)), scale3(ns, cm));
    }
    float co = -dot3(d, mh);
    if (!(co > 0.0f)) return false;
    V3 next = add3(d, scale3(mh, 2.0f * co));   // reflected about the microfacet
    float scale = 1.0f;
    bool refracted = false;
    if (kind == KIND_CONDUCTOR) {
      wgt = v3(schlick(color.x, co), schlick(color.y, co), schlick(color.z, co));
      P.bsdf_pdf = (r.z > 0.0f ? beckmann_aniso(an, mh, cm) : beckmann(a2, cm)) * cm / (4.0f * co);
      P.count_emission = false;
    } else {
      // the Fresnel switch on the microfacet (Walter et al. 2007): reflect with
      // probability F, else refract through it; radiance scales by eta^2
      float ior = s.mats[3 * __float_as_int(td.w) + 1].w;
      bool into = cos_d < 0.0f;
      float eta = into ? 1.0f / ior : ior;
      float k = 1.0f - eta * eta * (1.0f - co * co);
      if (k > 0.0f) {   // else total internal reflection
        float cos_t = sqrtf(k);
        float r0 = (1.0f - ior) / (1.0f + ior);
        bool exact = s.mats[3 * __float_as_int(td.w) + 2].y > 0.0f;
        float fr = exact ? fresnel_exact(eta, co, cos_t) : schlick(r0 * r0, into ? co : cos_t);
        if (!(rng(key, dim + 6) < fr)) {
          next = add3(scale3(d, eta), scale3(mh, eta * co - cos_t));
          scale = eta * eta;
          refracted = true;
        }
      }
      P.count_emission = true;
    }
    float ci = dot3(next, ns);
    if (refracted ? !(ci < 0.0f) : !(ci > 0.0f)) return false;   // on the wrong side
    float g = r.z > 0.0f ? smith_g1(alpha_along(an, d), cos_o, co) * smith_g1(alpha_along(an, next), ci, dot3(next, mh))
                         : smith_g1(alpha, cos_o, co) * smith_g1(alpha, ci, dot3(next, mh));
    float f = g * co / (cos_o * cm) * scale;
    wgt = scale3(wgt, f);
    d = next;
  } else if (kind == KIND_COATED) {
    // §4.5's Fresnel switch (003:L259-263): the smooth coat reflects with
    // Schlick's R at the viewer's cosine (weight R / R = 1), else Ashikhmin and
    // Shirley's coupled diffuse, cosine-sampled: f cos / (p (1 - R)) =
    // 28/23 (1 - R0) g(cos_i) g(cos_o) / (1 - R) times the colour, up to
    // 28/23 (31/32)^2 = 1.14 at normal incidence (003:L267's "mask <= 1" fails)
    float r0 = coat_r0(s.mats[3 * __float_as_int(td.w) + 1].w);
    float fr = schlick(r0, cos_o);
    if (rng(key, dim + 6) < fr || !(fr < 1.0f)) {
      d = add3(d, scale3(ns, 2.0f * cos_o));
      wgt = v3(1.0f, 1.0f, 1.0f);
      P.count_emission = true;
    } else {
      float lz;
      d = cosine_dir(ns, rng(key, dim + 3), rng(key, dim + 4), &lz);
      float k = 28.0f / 23.0f * (1.0f - r0) * as_factor(lz) * as_factor(cos_o) / (1.0f - fr);
      wgt = scale3(color, k);
      P.bsdf_pdf = (1.0f - fr) * lz * INV_PI;
      P.count_emission = false;
    }
  } else {
    float cos_i = -dot3(d, ns);   // > 0: ns faces the ray
    V3 next = add3(d, scale3(ns, 2.0f * cos_i));
    if (kind == KIND_GLASS) {
      // the Fresnel switch (Schlick): reflect with probability R, else refract
      float ior = s.mats[3 * __float_as_int(td.w) + 1].w;
      bool into = cos_d < 0.0f;
      float eta = into ? 1.0f / ior : ior;
      float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
      if (k > 0.0f) {   // else total internal reflection
        float cos_t = sqrtf(k);
        V3 tdir = add3(scale3(d, eta), scale3(ns, eta * cos_i - cos_t));
        float fr;
        if (s.mats[3 * __float_as_int(td.w) + 2].y > 0.0f) {
          fr = fresnel_exact(eta, cos_i, cos_t);
        } else {
          float r0 = (1.0f - ior) / (1.0f + ior);
          r0 = r0 * r0;
          float c = 1.0f - (into ? cos_i : cos_t);
          float c2 = c * c;
          fr = r0 + (1.0f - r0) * (c2 * c2 * c);
        }
        if (!(rng(key, dim + 6) < fr)) next = tdir;
      }
    }
    d = next;
    P.count_emission = true;
  }
  return true;
}

// A point on the area lights, as next-event estimation and bdpt's light subpath
// both choose it: the light triangle by the cumulative areas from dimension
// dim, the point uniform on it from dim + 1 and dim + 2 (the light pdf is open,
// 003:L240); *tri the triangle. Needs a light.
template <class K>
static __device__ __forceinline__ V3 light_point(const Scene &s, K key, unsigned dim, int *tri) {
  const Params *p = s.p;
  float yl = rng(key, dim);
  int l = 0;
  while (l + 1 < p->num_lights && !(yl < s.lights[3 * l].w)) l++;
  float4 la = s.lights[3 * l], lb = s.lights[3 * l + 1], lc = s.lights[3 * l + 2];
  float su = sqrtf(rng(key, dim + 1));
  float yv = rng(key, dim + 2);
  float bu = su * (1.0f - yv), bv = su * yv;
  *tri = __float_as_int(lb.w);
  return add3(add3(v3(la.x, la.y, la.z), scale3(v3(lb.x, lb.y, lb.z), bu)), scale3(v3(lc.x, lc.y, lc.z), bv));
}

// Russian roulette on the bounce's mask wgt = f cos / p (003:L267-271): continue
// with q = its max RGB, then divide by q; false when the path ends.
// Compiled with PATH_FIXED_DEPTH (path_fixed_depth.cu) there is no roulette:
// every path goes on to max bounces, the alternative 003:L269 compares with.
// The thesis takes the mask to be at most 1 (003:L267-269); where it is not
// (q >= 1: the rough BSDFs' sampled weights), the path goes on undivided. The
// emulator counts both tests (`@count`; host/path/counts.rs, Roulettes).
template <class K>
static __device__ __forceinline__ bool roulette(V3 &beta, V3 wgt, K key, unsigned dim) {
#ifdef PATH_FIXED_DEPTH
  beta = mul3(beta, wgt);
#else
  float q = fmaxf(fmaxf(wgt.x, wgt.y), wgt.z);
  if (q < 1.0f) {   // @count roulettes setp.geu.f32
    if (!(rng(key, dim + 5) < q)) return false;   // @count roulettes_below_one setp.geu.f32
    beta = v3(beta.x * (wgt.x / q), beta.y * (wgt.y / q), beta.z * (wgt.z / q));
  } else {
    beta = mul3(beta, wgt);
  }
#endif
  return true;
}

// ---- Participating media (§5.2, 003:L359-386): the march of volume_frame ----
//
// One medium, in an axis-aligned box (the whole scene's box when the scene
// file gives none): absorption sigma_a and scattering sigma_s (grey, per unit
// length at unit density), the Henyey-Greenstein phase function with g
// (003:L365), emission L_ve (RGB, per unit length at unit density) and a
// density 1 or, with an exponential height falloff of scale height H,
// e^(-(y - lo.y) / H) ("exponentially attenuated density in vertical
// direction", 003:L385). The segment of each ray inside the box is marched
// with steps of dt (003:L367): sample k at t = t_enter + (k + u) dt while
// t < t_end, with u one offset for the whole ray (Pauly's stratified pattern)
// or, for the comparison of 003:L367, one offset per step ("randomly pick a
// point in each segment"). Each sample adds dt T(t) (rho L_ve + sigma_s rho
// p L_light T_shadow G / pdf): single scattering from direct light only, one
// light sample and shadow ray per march sample (003:L379). The transmittance
// T is Beer's law, evaluated analytically (003:L369-371): sigma_t times the
// density's integral, (1 - e^(-x)) / x in closed form for the exponential
// density. T of the whole segment multiplies the mask (003:L377). Light
// samples at surfaces are attenuated by T along the shadow ray. The medium's
// random numbers: dimension MEDIUM_DIMS + MEDIUM_DIMS_PER_BOUNCE bounce + j,
// j = 0 the ray's offset, 4 k + 1 step k's own offset, 4 k + 2..4 its light point.
#define MEDIUM_DIMS 0x100000u
#define MEDIUM_DIMS_PER_BOUNCE 0x1000u
#define MEDIUM_MAX_STEPS 1023   // per ray segment (the host refuses a step that needs more)

// The path tracer's kernels have no medium: every hook below compiles to nothing.
struct NoMedium {
  static const bool TRANSLUCENT = false;
};
// The medium as src/host/path/layout.rs lays it out: [lo, dt], [hi, g],
// [sigma_a, sigma_s, 1 / H (0: uniform density), 1: an offset per step (0: per ray)], [L_ve, 0].
struct Medium {
  static const bool TRANSLUCENT = false;
  float4 lo, hi, c, e;
};

template <class K>
static __device__ __forceinline__ void march(const Scene &, Path &, K, const NoMedium &, V3, V3, float) {}
static __device__ __forceinline__ float attenuate(const NoMedium &, float g, V3, V3, float) { return g; }

// The part [*ta, *tb] of the ray o + t d, t in [0, t_end], inside the medium's box.
static __device__ __forceinline__ void medium_span(const Medium &m, V3 o, V3 d, float t_end, float *ta, float *tb) {
  float ix = 1.0f / d.x, iy = 1.0f / d.y, iz = 1.0f / d.z;
  float t0x = (m.lo.x - o.x) * ix, t1x = (m.hi.x - o.x) * ix;
  float t0y = (m.lo.y - o.y) * iy, t1y = (m.hi.y - o.y) * iy;
  float t0z = (m.lo.z - o.z) * iz, t1z = (m.hi.z - o.z) * iz;
  *ta = fmaxf(fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fminf(t0z, t1z)), 0.0f);
  *tb = fminf(fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z)), t_end);
}

// The density at height y: 1, or e^(-(y - lo.y) / H).
static __device__ __forceinline__ float medium_density(const Medium &m, float y) {
  return m.c.z > 0.0f ? exp_neg(-fmaxf(y - m.lo.y, 0.0f) * m.c.z) : 1.0f;
}

// The density's integral along o + t d over [ta, tb] (inside the box): tb - ta,
// or for the exponential density rho_max len (1 - e^(-x)) / x with x = |d.y| len / H
// and rho_max the density at the lower end (a series below x = 1e-3).
static __device__ __forceinline__ float medium_depth(const Medium &m, V3 o, V3 d, float ta, float tb) {
  if (!(ta < tb)) return 0.0f;
  float len = tb - ta;
  if (!(m.c.z > 0.0f)) return len;
  float ya = o.y + ta * d.y, yb = o.y + tb * d.y;
  float rho = medium_density(m, fminf(ya, yb));
  float x = fabsf(d.y) * m.c.z * len;
  float f = x < 1e-3f ? 1.0f - x * (0.5f - x * (1.0f / 6.0f)) : (1.0f - exp_neg(-x)) / x;
  return rho * len * f;
}

// Beer's law along a shadow ray from x in unit direction w to distance dist.
static __device__ __forceinline__ float medium_transmittance(const Medium &m, V3 x, V3 w, float dist) {
  float ta, tb;
  medium_span(m, x, w, dist, &ta, &tb);
  return exp_neg(-(m.c.x + m.c.y) * medium_depth(m, x, w, ta, tb));
}

// Henyey-Greenstein (003:L365) for the cosine c between the light's and the
// viewer's direction of travel: (1 - g^2) / (4 pi (1 + g^2 - 2 g c)^(3/2)).
static __device__ __forceinline__ float hg(float g, float c) {
  float den = 1.0f + g * g - 2.0f * g * c;
  return (1.0f - g * g) * (0.25f * INV_PI) / (den * sqrtf(den));
}

// A surface's light sample g, attenuated along its shadow ray.
static __device__ __forceinline__ float attenuate(const Medium &m, float g, V3 x, V3 w, float dist) {
  return g * medium_transmittance(m, x, w, dist);
}

// The march of the segment o + t d, t in [0, t_end], of a path after P.bounce
// bounces: the in-scattered and emitted light (if P.bounce < max bounces) into
// P.L, the segment's transmittance into the mask.
template <class K>
static __device__ __forceinline__ void march(const Scene &s, Path &P, K key, const Medium &m, V3 o, V3 d,
                                             float t_end) {
  const Params *p = s.p;
  float ta, tb;
  medium_span(m, o, d, t_end, &ta, &tb);
  if (!(ta < tb)) return;
  float sigma_t = m.c.x + m.c.y, dt = m.lo.w;
  if (P.bounce < p->max_bounces) {
    unsigned dim = MEDIUM_DIMS + MEDIUM_DIMS_PER_BOUNCE * (unsigned)P.bounce;
    float u = rng(key, dim);
    V3 sum = v3(0.0f, 0.0f, 0.0f);
    for (int k = 0; k < MEDIUM_MAX_STEPS; k++) {
      unsigned dk = dim + 4u * (unsigned)k + 1u;
      float uk = m.c.w > 0.0f ? rng(key, dk) : u;
      float t = ta + ((float)k + uk) * dt;
      if (!(t < tb)) break;
      V3 x = add3(o, scale3(d, t));
      float rho = medium_density(m, x.y);
      V3 src = scale3(v3(m.e.x, m.e.y, m.e.z), rho);
      if (p->num_lights > 0) {
        int ltri;
        V3 q = light_point(s, key, dk + 1u, &ltri);
        V3 wl = sub3(q, x);
        float dist2 = dot3(wl, wl);
        float dist = sqrtf(dist2);
        wl = scale3(wl, 1.0f / dist);
        float4 ld = s.tri_data[ltri];
        float cos_l = -dot3(v3(ld.x, ld.y, ld.z), wl);
        float ts;
        if (cos_l > 0.0f && trace(s, x, wl, p->eps, dist - p->eps, true, &ts) < 0) {
          float4 le = s.mats[3 * __float_as_int(ld.w) + 1];
          float w = m.c.y * rho * hg(m.hi.w, dot3(wl, d)) * cos_l * p->light_area / dist2;
          w = w * medium_transmittance(m, x, wl, dist);
          src = add3(src, scale3(v3(le.x, le.y, le.z), w));
        }
      }
      sum = add3(sum, scale3(src, exp_neg(-sigma_t * medium_depth(m, o, d, ta, t))));
    }
    P.L = add3(P.L, mul3(P.beta, scale3(sum, dt)));
  }
  P.beta = scale3(P.beta, exp_neg(-sigma_t * medium_depth(m, o, d, ta, tb)));
}

// ---- Subsurface scattering (§5.3, 003:L388-403): sss_frame ----
//
// A translucent material (KIND_TRANSLUCENT) is a smooth dielectric boundary
// (IOR; Schlick's or the exact Fresnel term) around a homogeneous medium:
// scattering sigma_s (grey), absorption sigma_a (RGB), Henyey-Greenstein g.
// At the surface from outside, the thesis' 3-way Fresnel switch (003:L259-265):
// xi < F mirror reflection, else xi' < translucency refraction into the
// medium, else Lambertian reflection with the colour (no light sample at a
// translucent surface: emission after any of its branches counts in full).
// From inside: reflect with F, else refract out. Weights: 1 for reflection
// and refraction (no eta^2, as smooth glass: entering and leaving cancel),
// the colour for the diffuse branch.
// Inside, single scattering only (003:L396): on a leg from the entry (or an
// internal reflection) the distance d = -ln(1 - xi) / sigma_s' with
// sigma_s' = (1 - g) sigma_s, along the refracted ray. If d falls before the
// exit surface, the path scatters there: weight e^(-sigma_a d) (the
// absorption along d; d's pdf is sigma_s' e^(-sigma_s' d)), the next
// direction sampled from HG(g) (weight 1), no light sample (a shadow ray
// cannot pass the smooth boundary), one bounce. Else the leg reaches the
// exit surface with weight e^(-sigma_a t) (d >= t has probability
// e^(-sigma_s' t)). After the scattering no second one: the legs up to the
// exit take the transmittance e^(-(sigma_a + sigma_s') t). The estimand is
// thus the radiative transfer of a medium with sigma_s' and HG(g), each
// stay inside scattered at most once (tools/mitsuba/reference.py: volpath
// on such a medium at a depth limit that admits one scattering). Translucent
// meshes must be closed and hold nothing: a leg ending on a translucent
// surface's back side is taken to have run inside.
// Random numbers of bounce b (dim = 2 + 8 b): 3-4 the direction (diffuse or
// HG), 5 roulette, 6 the Fresnel switch, 7 the translucency test (from
// outside) or the leg's distance (from inside; a scattering point's own).
// Layout: [colour, kind] [sigma_a rgb, IOR] [sigma_s, exact Fresnel, g, translucency].

// The state of sss_frame's path: whether it has scattered since it entered.
struct Sss {
  static const bool TRANSLUCENT = true;
  mutable bool scattered;
};

template <class K>
static __device__ __forceinline__ void march(const Scene &, Path &, K, const Sss &, V3, V3, float) {}
static __device__ __forceinline__ float attenuate(const Sss &, float g, V3, V3, float) { return g; }

// A direction from Henyey-Greenstein about the unit direction of travel d
// (forward peak for g > 0, as hg()): cos = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g y1))^2) / (2 g),
// 1 - 2 y1 for |g| < 1e-3; the azimuth from y2.
static __device__ __forceinline__ V3 hg_dir(float g, V3 d, float y1, float y2) {
  float c;
  if (fabsf(g) < 1e-3f) {
    c = 1.0f - 2.0f * y1;
  } else {
    float q = (1.0f - g * g) / (1.0f - g + 2.0f * g * y1);
    c = (1.0f + g * g - q * q) / (2.0f * g);
  }
  c = fminf(fmaxf(c, -1.0f), 1.0f);
  float sn = sqrtf(fmaxf(1.0f - c * c, 0.0f)), ca, sa;
  azimuth(y2, &ca, &sa);
  V3 b1, b2;
  basis(d, &b1, &b2);
  return normalize3(add3(add3(scale3(b1, sn * ca), scale3(b2, sn * sa)), scale3(d, c)));
}

// Every kernel but sss_frame: no translucent material (-1: the surface as usual).
template <class K, class M>
static __device__ __forceinline__ int translucent(const Scene &, Path &, K, const M &, float4, int, float, V3, V3,
                                                  float) {
  return -1;
}

// sss_frame: the ray o + t' d hit triangle data td (kind, cos_d = d . n) at t.
// -1 when it is not translucent; else the leg inside (if the ray left from
// inside), then the surface's switch: 1 the path goes on (P the next ray),
// 0 it ends.
template <class K>
static __device__ __forceinline__ int translucent(const Scene &s, Path &P, K key, const Sss &ss, float4 td, int kind,
                                                  float cos_d, V3 o, V3 d, float t) {
  if (kind != KIND_TRANSLUCENT) return -1;
  const Params *p = s.p;
  int bounce = P.bounce;
  unsigned dim = DIMS_CAMERA + DIMS_PER_BOUNCE * (unsigned)bounce;
  const float4 *mt = s.mats + 3 * __float_as_int(td.w);
  float4 m0 = mt[0], m1 = mt[1], m2 = mt[2];
  bool into = cos_d < 0.0f;
  if (!into) {
    // the leg ran inside: sigma_s' = (1 - g) sigma_s (003:L396)
    float sigma_r = (1.0f - m2.z) * m2.x;
    float ext = 0.0f;
    if (!ss.scattered) {
      float dd = sigma_r > 0.0f ? -ln(1.0f - rng(key, dim + 7)) / sigma_r : __int_as_float(0x7f800000);
      if (dd < t) {
        // the single scattering point (003:L396): absorption along dd, the phase function's direction
        if (bounce == p->max_bounces) return 0;
        V3 wgt = v3(exp_neg(-m1.x * dd), exp_neg(-m1.y * dd), exp_neg(-m1.z * dd));
        V3 next = hg_dir(m2.z, d, rng(key, dim + 3), rng(key, dim + 4));
        if (!roulette(P.beta, wgt, key, dim)) return 0;
        ss.scattered = true;
        P.o = add3(o, scale3(d, dd));
        P.d = next;
        P.bounce = bounce + 1;
        P.count_emission = true;
        return 1;
      }
    } else {
      ext = sigma_r;   // scattered once: no second scattering, the leg's transmittance
    }
    P.beta = v3(P.beta.x * exp_neg(-(m1.x + ext) * t), P.beta.y * exp_neg(-(m1.y + ext) * t),
                P.beta.z * exp_neg(-(m1.z + ext) * t));
  }
  if (bounce == p->max_bounces) return 0;
  V3 n = v3(td.x, td.y, td.z);
  V3 ns = into ? n : v3(-n.x, -n.y, -n.z);   // faces the ray
  float cos_i = -dot3(d, ns);
  V3 next = add3(d, scale3(ns, 2.0f * cos_i));   // the mirror direction
  V3 wgt = v3(1.0f, 1.0f, 1.0f);
  float ior = m1.w;
  float eta = into ? 1.0f / ior : ior;
  float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
  if (k > 0.0f) {   // else total internal reflection
    float cos_t = sqrtf(k);
    float fr = surface_fresnel(m2.y > 0.0f, ior, into, eta, cos_i, cos_t);
    if (!(rng(key, dim + 6) < fr)) {
      if (!into || rng(key, dim + 7) < m2.w) {
        // refraction, into the medium (translucency) or out of it
        next = add3(scale3(d, eta), scale3(ns, eta * cos_i - cos_t));
        ss.scattered = false;
      } else {
        float lz;
        next = cosine_dir(ns, rng(key, dim + 3), rng(key, dim + 4), &lz);
        wgt = v3(m0.x, m0.y, m0.z);
      }
    }
  }
  if (!roulette(P.beta, wgt, key, dim)) return 0;
  P.o = add3(o, scale3(d, t));
  P.d = next;
  P.bounce = bounce + 1;
  P.count_emission = true;
  return 1;
}

// ---- Texture maps (§5.4, 003:L405-417): the hook of texture_frame ----
//
// A textured material (KIND_TEXTURED) has an albedo map (RGB, times its
// colour), a metalness map and a roughness map (grey, the first channel),
// 8-bit texels read through the read-only (texture) path, nearest texel,
// repeated outside [0, 1) (thesis 000's lookup; the thesis states neither
// resolution nor filtering). At each hit, the metalness workflow (003:L255-257,
// L409) picks the BSDF's lobe: with probability m (the metalness texel) the
// metal lobe, the rough conductor (Cook-Torrance, Schlick's F) whose specular
// colour is lerp(white, albedo, m) and whose Beckmann alpha is the roughness
// texel / 255 (at least 1e-4), else the Lambertian lobe with the albedo: the
// BSDF (1 - m) albedo / pi + m f_CT, each lobe estimated with its own light
// sample and sampling. The host lays out, per textured material, one
// conductor row of mats per roughness level (256 with a roughness map, else
// one with the material's alpha) from its first row on, so that the chosen
// lobe is an existing kind and the shading below is path_frame's.
struct NoTextures {
  static constexpr bool MAPS = false;
};
// A textured scene's maps: per material [albedo, roughness, metalness map
// (-1: none), first conductor row (-1: no metal lobe)]; per triangle its 3
// vertices' texture coordinates (u, v); per map [first texel, width, height,
// 0]; every map's texels, r | g << 8 | b << 16 | a << 24, rows top down.
struct Textures {
  static constexpr bool MAPS = true;
  const int4 *mats;
  const float *uvs;
  const uint4 *info;
  const unsigned *texels;
};

// The texel of map `map` at texture coordinates (tu, tv): nearest, repeated, v = 0 the bottom row.
static __device__ __forceinline__ unsigned texel_at(const Textures &x, int map, float tu, float tv) {
  const unsigned *ti = (const unsigned *)(x.info + map);
  unsigned first = __ldg(ti);
  int tw = (int)__ldg(ti + 1), th = (int)__ldg(ti + 2);
  int px = __float2int_rd(tu * (float)tw) % tw;
  int py = __float2int_rd((1.0f - tv) * (float)th) % th;
  if (px < 0) px += tw;
  if (py < 0) py += th;
  return __ldg(x.texels + first + (unsigned)(py * tw + px));
}

// A hit on triangle tri at distance t along (o, d): a textured material
// becomes the lobe the metalness picks (dimension dim + 6, the switch's),
// *kind KIND_DIFFUSE with the albedo or KIND_CONDUCTOR with the specular
// colour and td.w its roughness level's conductor row.
template <class K>
static __device__ __forceinline__ void texture_hit(const Textures &x, const Scene &s, int tri, V3 o, V3 d, float t,
                                                   K key, unsigned dim, float4 &td, int &kind, V3 &color) {
  if (kind != KIND_TEXTURED) return;
  const int *tm = (const int *)(x.mats + __float_as_int(td.w));
  int albedo = __ldg(tm), rough = __ldg(tm + 1), metal = __ldg(tm + 2), rows = __ldg(tm + 3);
  // the barycentric weights of vertices 0 and 1, as the affine test computed them
  const float4 *m = s.tris + 3 * tri;
  float4 r0 = m[0], r1 = m[1];
  float b0 = r0.x * o.x + r0.y * o.y + r0.z * o.z + r0.w + t * (r0.x * d.x + r0.y * d.y + r0.z * d.z);
  float b1 = r1.x * o.x + r1.y * o.y + r1.z * o.z + r1.w + t * (r1.x * d.x + r1.y * d.y + r1.z * d.z);
  float b2 = 1.0f - b0 - b1;
  const float *uv = x.uvs + 6 * tri;
  float tu = b0 * __ldg(uv) + b1 * __ldg(uv + 2) + b2 * __ldg(uv + 4);
  float tv = b0 * __ldg(uv + 1) + b1 * __ldg(uv + 3) + b2 * __ldg(uv + 5);
  if (albedo >= 0) {
    unsigned a = texel_at(x, albedo, tu, tv);
    color = v3(color.x * ((float)(a & 255u) / 255.0f), color.y * ((float)((a >> 8) & 255u) / 255.0f),
               color.z * ((float)((a >> 16) & 255u) / 255.0f));
  }
  float mv = metal >= 0 ? (float)(texel_at(x, metal, tu, tv) & 255u) / 255.0f : 0.0f;
  kind = KIND_DIFFUSE;
  if (rows >= 0 && rng(key, dim + 6) < mv) {
    int level = rough >= 0 ? (int)(texel_at(x, rough, tu, tv) & 255u) : 0;
    td.w = __int_as_float(rows + level);
    kind = KIND_CONDUCTOR;
    float w = 1.0f - mv;   // lerp(white, albedo, m)
    color = v3(w + mv * color.x, w + mv * color.y, w + mv * color.z);
  }
}

// The next ray's hit: the triangle (< 0: none) and its distance in *t.
static __device__ __forceinline__ int trace_next(const Scene &s, const Path &P, float *t) {
  return trace(s, P.o, P.d, s.p->eps, __int_as_float(0x7f800000), false, t);
}

// One bounce of path P: its next ray traced (Traced false: step()) or, for the
// regrouped wavefront (Traced true), already traced to hit_tri (< 0: none) at
// distance hit_t by trace_next(); then emission, the light sample, the next
// direction and Russian roulette; false when the path ends.
// M: NoMedium, the Medium of volume_frame (march(), attenuate()) or the Sss of
// sss_frame (translucent()); T: NoTextures, or the Textures of texture_frame.
template <bool Traced, class K, class M = NoMedium, class T = NoTextures>
static __device__ __forceinline__ bool step_at(const Scene &s, Path &P, K key, const M &med, const T &tex,
                                               int hit_tri, float hit_t) {
  const Params *p = s.p;
  int integrator = p->integrator;
  int bounce = P.bounce;
  V3 o = P.o, d = P.d;
  float t;
  int tri;
  if (Traced) {
    t = hit_t;
    tri = hit_tri;
  } else {
    tri = trace(s, o, d, p->eps, __int_as_float(0x7f800000), false, &t);
  }
  march(s, P, key, med, o, d, tri < 0 ? __int_as_float(0x7f800000) : t);
  if (tri < 0) {
    // the environment: not light-sampled, so its radiance counts in full after any bounce
    if (p->env_w > 0) P.L = add3(P.L, mul3(P.beta, env(s, d)));
    return false;
  }
  float4 td = s.tri_data[tri];
  V3 n = v3(td.x, td.y, td.z);
  float4 m0 = s.mats[3 * __float_as_int(td.w)];
  int kind = __float_as_int(m0.w);
  float cos_d = dot3(d, n);
  // a translucent surface and the leg inside it (sss_frame's Sss only; nothing for the others)
  if (M::TRANSLUCENT) {
    int sub = translucent(s, P, key, med, td, kind, cos_d, o, d, t);
    if (sub >= 0) return sub > 0;
  }
  if (kind == KIND_EMITTER) {
    if (cos_d < 0.0f) {   // the front face emits
      float4 m1 = s.mats[3 * __float_as_int(td.w) + 1];
      float w = 1.0f;
      if (!P.count_emission) {
        if (integrator == INTEGRATOR_NEE) {
          w = 0.0f;
        } else if (integrator != INTEGRATOR_PT) {
          float light_pdf = t * t / (-cos_d * p->light_area);
          w = mis_weight(integrator, P.bsdf_pdf, light_pdf);
        }
      }
      P.L = add3(P.L, scale3(mul3(P.beta, v3(m1.x, m1.y, m1.z)), w));
    }
    return false;
  }
  V3 hitp = add3(o, scale3(d, t));
  V3 ns = cos_d < 0.0f ? n : v3(-n.x, -n.y, -n.z);   // faces the ray
  V3 color = v3(m0.x, m0.y, m0.z);
  float cos_o = -dot3(d, ns);   // the viewer's side, > 0
  unsigned dim = DIMS_CAMERA + DIMS_PER_BOUNCE * (unsigned)bounce;
  if constexpr (T::MAPS) texture_hit(tex, s, tri, o, d, t, key, dim, td, kind, color);   // the lobe of a textured hit
  bool sampled_light = kind == KIND_DIFFUSE || kind == KIND_CONDUCTOR || kind == KIND_COATED;
  if (sampled_light && integrator != INTEGRATOR_PT && p->num_lights > 0 && bounce < p->max_bounces) {
    // next event estimation: a light triangle by area, a point on it uniformly
    int ltri;
    V3 q = light_point(s, key, dim, &ltri);
    V3 wl = sub3(q, hitp);
    float dist2 = dot3(wl, wl);
    float dist = sqrtf(dist2);
    wl = scale3(wl, 1.0f / dist);
    float4 ld = s.tri_data[ltri];
    float cos_s = dot3(ns, wl);
    float cos_l = -dot3(v3(ld.x, ld.y, ld.z), wl);
    if (cos_s > 0.0f && cos_l > 0.0f) {
      // the BSDF times the cosine, as a colour fc times a scalar fs, and its sampling pdf
      V3 fc = color;
      float fs = cos_s * INV_PI, bsdf_pdf = cos_s * INV_PI;
      if (kind == KIND_CONDUCTOR) {
        float4 r = s.mats[3 * __float_as_int(td.w) + 2];
        float alpha = r.x;
        float a2 = alpha * alpha;
        V3 h = normalize3(sub3(wl, d));
        float ch = dot3(h, ns), coh = -dot3(d, h);
        float dm, g;
        if (r.z > 0.0f) {   // the anisotropic mirror
          Aniso a = aniso(n, alpha, r.z);
          dm = beckmann_aniso(a, h, ch);
          g = smith_g1(alpha_along(a, d), cos_o, coh) * smith_g1(alpha_along(a, wl), cos_s, dot3(wl, h));
        } else {
          dm = beckmann(a2, ch);
          g = smith_g1(alpha, cos_o, coh) * smith_g1(alpha, cos_s, dot3(wl, h));
        }
        fc = v3(schlick(color.x, coh), schlick(color.y, coh), schlick(color.z, coh));
        fs = dm * g / (4.0f * cos_o);
        bsdf_pdf = dm * ch / (4.0f * coh);
      } else if (kind == KIND_COATED) {
        // the coupled diffuse (003:L263); the coat's mirror lobe has no light sample
        float r0 = coat_r0(s.mats[3 * __float_as_int(td.w) + 1].w);
        fs = 28.0f / 23.0f * (1.0f - r0) * as_factor(cos_s) * as_factor(cos_o) * cos_s * INV_PI;
        bsdf_pdf = (1.0f - schlick(r0, cos_o)) * cos_s * INV_PI;
      }
      float ts;
      if (fs > 0.0f && trace(s, hitp, wl, p->eps, dist - p->eps, true, &ts) < 0) {
        float4 le = s.mats[3 * __float_as_int(ld.w) + 1];
        float light_pdf = dist2 / (cos_l * p->light_area);
        float w = 1.0f;
        if (integrator != INTEGRATOR_NEE) w = mis_weight(integrator, light_pdf, bsdf_pdf);
        float g = attenuate(med, fs / light_pdf * w, hitp, wl, dist);
        P.L = add3(P.L, scale3(mul3(mul3(P.beta, fc), v3(le.x, le.y, le.z)), g));
      }
    }
  }
  if (bounce == p->max_bounces) return false;
  // the next direction, and the bounce's mask f cos / p
  V3 wgt;
  if (!scatter(s, P, td, kind, ns, color, cos_d, cos_o, key, dim, d, wgt)) return false;
  // Russian roulette on the bounce's mask f cos / p
  if (!roulette(P.beta, wgt, key, dim)) return false;
  P.o = hitp;
  P.d = d;
  P.bounce = bounce + 1;
  return true;
}

// One level of the inner loop (003:L119) for one path: trace its ray, gather
// emission and the light sample, pick the next direction, Russian roulette.
// False when the path ends (missed, hit an emitter, the longest path, or
// terminated); P then holds its final radiance.
template <class K, class M = NoMedium, class T = NoTextures>
static __device__ __forceinline__ bool step(const Scene &s, Path &P, K key, const M &med = M(),
                                            const T &tex = T()) {
  return step_at<false>(s, P, key, med, tex, 0, 0.0f);
}

// Adds path i's radiance to its slot of the accumulation buffer and stores it in `last`.
static __device__ __forceinline__ void finish(float *accum, float *last, int i, V3 L) {
  float *a = accum + 3 * i;
  a[0] += L.x;
  a[1] += L.y;
  a[2] += L.z;
  float *l = last + 3 * i;
  l[0] = L.x;
  l[1] = L.y;
  l[2] = L.z;
}

// One thread's path of a megakernel frame, run to the end with medium m (or none) and textures tex (or none).
template <class M, class T = NoTextures>
static __device__ __forceinline__ void frame_path(const Scene &s, float *accum, float *last, const M &m,
                                                  const T &tex = T()) {
  const Params *p = s.p;
  int i = (int)WL_TID;
  if (i >= p->num_paths) return;
  unsigned key = path_key((unsigned)i, (unsigned)p->frame, (unsigned)p->seed);
  Path P = camera_path(p, i, key);
  while (step(s, P, key, m, tex)) {
  }
  finish(accum, last, i, P.L);
}

// The megakernel: one launch per frame, each thread runs its path to the end.
extern "C" __global__ void path_frame(const Params *params, const uint4 *nodes, const unsigned *refs,
                                      const float4 *tris, const float4 *tri_data, const float4 *mats,
                                      const float4 *lights, const float4 *boxes, const float4 *env, float *accum,
                                      float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  frame_path(s, accum, last, NoMedium());
}

// The megakernel with a participating medium (§5.2): path_frame's paths, each
// ray segment marched through the medium (march()); medium[0..3] as Medium.
extern "C" __global__ void volume_frame(const Params *params, const uint4 *nodes, const unsigned *refs,
                                        const float4 *tris, const float4 *tri_data, const float4 *mats,
                                        const float4 *lights, const float4 *boxes, const float4 *env,
                                        const float4 *medium, float *accum, float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  Medium m = {medium[0], medium[1], medium[2], medium[3]};
  frame_path(s, accum, last, m);
}

// The megakernel with translucent materials (§5.3): path_frame's paths, each
// translucent surface and the legs inside it by translucent() (single scattering).
extern "C" __global__ void sss_frame(const Params *params, const uint4 *nodes, const unsigned *refs,
                                     const float4 *tris, const float4 *tri_data, const float4 *mats,
                                     const float4 *lights, const float4 *boxes, const float4 *env, float *accum,
                                     float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  Sss m = {false};
  frame_path(s, accum, last, m);
}

// The megakernel of a scene with texture maps (§5.4): path_frame's paths, each
// hit on a textured material shaded as the lobe its maps pick (texture_hit()).
extern "C" __global__ void texture_frame(const Params *params, const uint4 *nodes, const unsigned *refs,
                                         const float4 *tris, const float4 *tri_data, const float4 *mats,
                                         const float4 *lights, const float4 *boxes, const float4 *env,
                                         const int4 *tex_mats, const float *uvs, const uint4 *tex_info,
                                         const unsigned *texels, float *accum, float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  Textures x = {tex_mats, uvs, tex_info, texels};
  frame_path(s, accum, last, NoMedium(), x);
}

// ---- Bidirectional path tracing (§4.7, 003:L295-308): bdpt_frame ----
//
// Per path one light subpath and one eye subpath. The light subpath starts at
// a point y0 sampled on the area lights by area (the light sample of nee),
// leaves it cosine-weighted and continues only through Lambertian surfaces
// (a glossy, specular, coated or emitting hit ends it), y0 ... y_{n-1}, n <= min(max
// bounces, LIGHT_VERTICES), each vertex with its throughput alpha (Le A at y0).
// The eye subpath is the path tracer's (BSDF sampling, Russian roulette);
// at each Lambertian eye vertex x it connects to every light vertex y_k
// whose full path has at most max bounces: a shadow ray, the geometry term
// G = cos_x cos_y / |x - y|^2 (003:L301), both BSDFs (1 at y0); connection
// through a non-Lambertian vertex is never tried (zero probability, 003:L303).
// Emission the eye subpath hits counts too (s = 0). The weights are the
// thesis' uniform ones (003:L303: each contribution divided by the number of
// combinations that make the same path), with the count taken over the
// combinations that can make it (the light-side prefix up to the connection
// all Lambertian, at most LIGHT_VERTICES light vertices): c = 1 + min(m, nl)
// for m the Lambertian vertices in a row from the light's end. No light
// vertex is connected to the camera (t = 1: splats, not counted in c).
#define LIGHT_VERTICES 16

static __device__ __forceinline__ int imin(int a, int b) { return a < b ? a : b; }

struct LightVertex {
  V3 p, n;     // position; normal on the side the light came from (y0: the light's front)
  V3 alpha;    // throughput arriving at the vertex (y0: Le times the lights' area)
  V3 color;    // Lambertian albedo (y0: unused)
};

// Traces the light subpath of `key` into lv (at most nl vertices); returns its vertex count.
template <class K>
static __device__ int light_subpath(const Scene &s, K key, int nl, LightVertex *lv) {
  const Params *p = s.p;
  int ltri;
  V3 o = light_point(s, key, DIMS_LIGHT, &ltri);
  float4 ld = s.tri_data[ltri];
  float4 le = s.mats[3 * __float_as_int(ld.w) + 1];
  V3 alpha = scale3(v3(le.x, le.y, le.z), p->light_area);
  lv[0].p = o;
  lv[0].n = v3(ld.x, ld.y, ld.z);
  lv[0].alpha = alpha;
  lv[0].color = v3(0.0f, 0.0f, 0.0f);
  // the emitted direction, cosine-weighted: Le cos / (cos / pi) = pi Le
  float lz;
  V3 d = cosine_dir(lv[0].n, rng(key, DIMS_LIGHT + 3), rng(key, DIMS_LIGHT + 4), &lz);
  alpha = scale3(alpha, PI_F);
  int count = 1;
  while (count < nl) {
    float t;
    int tri = trace(s, o, d, p->eps, __int_as_float(0x7f800000), false, &t);
    if (tri < 0) break;
    float4 td = s.tri_data[tri];
    float4 m0 = s.mats[3 * __float_as_int(td.w)];
    if (__float_as_int(m0.w) != KIND_DIFFUSE) break;
    V3 n = v3(td.x, td.y, td.z);
    V3 hitp = add3(o, scale3(d, t));
    V3 ns = dot3(d, n) < 0.0f ? n : v3(-n.x, -n.y, -n.z);
    V3 color = v3(m0.x, m0.y, m0.z);
    lv[count].p = hitp;
    lv[count].n = ns;
    lv[count].alpha = alpha;
    lv[count].color = color;
    count++;
    if (count == nl) break;
    unsigned dim = DIMS_LIGHT + DIMS_PER_BOUNCE * (unsigned)count;
    d = cosine_dir(ns, rng(key, dim + 3), rng(key, dim + 4), &lz);
    if (!roulette(alpha, color, key, dim)) break;
    o = hitp;
  }
  return count;
}

// One eye vertex of bdpt: trace, count emission with its uniform weight, connect
// a Lambertian vertex to the light subpath, scatter. run: the Lambertian eye
// vertices in a row ending at the previous one. False when the path ends.
template <class K>
static __device__ __forceinline__ bool bdpt_step(const Scene &s, Path &P, K key, const LightVertex *lv, int nl,
                                                 int nl_max, int &run) {
  const Params *p = s.p;
  int bounce = P.bounce;
  V3 o = P.o, d = P.d;
  float t;
  int tri = trace(s, o, d, p->eps, __int_as_float(0x7f800000), false, &t);
  if (tri < 0) {
    if (p->env_w > 0) P.L = add3(P.L, mul3(P.beta, env(s, d)));   // only the eye subpath sees it
    return false;
  }
  float4 td = s.tri_data[tri];
  V3 n = v3(td.x, td.y, td.z);
  float4 m0 = s.mats[3 * __float_as_int(td.w)];
  int kind = __float_as_int(m0.w);
  float cos_d = dot3(d, n);
  if (kind == KIND_EMITTER) {
    if (cos_d < 0.0f) {
      float4 m1 = s.mats[3 * __float_as_int(td.w) + 1];
      int c = 1 + imin(run, nl_max);
      P.L = add3(P.L, scale3(mul3(P.beta, v3(m1.x, m1.y, m1.z)), 1.0f / (float)c));
    }
    return false;
  }
  V3 hitp = add3(o, scale3(d, t));
  V3 ns = cos_d < 0.0f ? n : v3(-n.x, -n.y, -n.z);
  V3 color = v3(m0.x, m0.y, m0.z);
  float cos_o = -dot3(d, ns);
  unsigned dim = DIMS_CAMERA + DIMS_PER_BOUNCE * (unsigned)bounce;
  if (kind == KIND_DIFFUSE) {
    int last = p->max_bounces - bounce - 1;   // light vertex k makes a path of k + bounce + 1 bounces
    if (last > nl - 1) last = nl - 1;
    for (int k = 0; k <= last; k++) {
      V3 w = sub3(lv[k].p, hitp);
      float dist2 = dot3(w, w);
      float dist = sqrtf(dist2);
      w = scale3(w, 1.0f / dist);
      float cos_x = dot3(ns, w), cos_y = -dot3(lv[k].n, w);
      float ts;
      if (cos_x > 0.0f && cos_y > 0.0f && trace(s, hitp, w, p->eps, dist - p->eps, true, &ts) < 0) {
        int c = 1 + imin(k + 1 + run, nl_max);
        float g = cos_x * cos_y / dist2 * INV_PI / (float)c;
        V3 f = k == 0 ? v3(1.0f, 1.0f, 1.0f) : scale3(lv[k].color, INV_PI);
        P.L = add3(P.L, scale3(mul3(mul3(mul3(P.beta, color), f), lv[k].alpha), g));
      }
    }
  }
  run = kind == KIND_DIFFUSE ? run + 1 : 0;
  if (bounce == p->max_bounces) return false;
  V3 wgt;
  if (!scatter(s, P, td, kind, ns, color, cos_d, cos_o, key, dim, d, wgt)) return false;
  if (!roulette(P.beta, wgt, key, dim)) return false;
  P.o = hitp;
  P.d = d;
  P.bounce = bounce + 1;
  return true;
}

// The bdpt megakernel: one launch per frame, each thread one light and one eye subpath.
extern "C" __global__ void bdpt_frame(const Params *params, const uint4 *nodes, const unsigned *refs,
                                      const float4 *tris, const float4 *tri_data, const float4 *mats,
                                      const float4 *lights, const float4 *boxes, const float4 *env, float *accum,
                                      float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  const Params *p = params;
  int i = (int)WL_TID;
  if (i >= p->num_paths) return;
  unsigned key = path_key((unsigned)i, (unsigned)p->frame, (unsigned)p->seed);
  LightVertex lv[LIGHT_VERTICES];
  int nl_max = p->num_lights > 0 ? imin(p->max_bounces, LIGHT_VERTICES) : 0;
  int nl = nl_max > 0 ? light_subpath(s, key, nl_max, lv) : 0;
  Path P = camera_path(p, i, key);
  int run = 0;
  while (bdpt_step(s, P, key, lv, nl, nl_max, run)) {
  }
  finish(accum, last, i, P.L);
}

// ---- The wavefront form (Fig. 1's inner loop, §6.3): one launch per level ----
//
// The per-path state lives in global memory between launches, 4 float4 (64
// bytes) per path: [o, path index], [d, bounce], [beta, bsdf_pdf],
// [L, flags] with flags bit 0 = count emission, bit 1 = active
// (PATH_ACTIVE; kernels/lin2017/compact.cu reads it). path_init writes every
// path's camera ray; path_level advances the first n states by one level. The
// host launches path_level over all paths each level ("normal") or compacts
// the active states between levels (kernels/lin2017/compact.cu) and
// launches over those alone. Path i's random numbers depend on i and its
// bounce only, so both forms trace exactly the megakernel's paths.
#define PATH_COUNT_EMISSION 1u
#define PATH_ACTIVE 2u

static __device__ __forceinline__ void store_path(float4 *st, int i, const Path &P, unsigned flags) {
  st[0] = make_float4(P.o.x, P.o.y, P.o.z, __int_as_float(i));
  st[1] = make_float4(P.d.x, P.d.y, P.d.z, __int_as_float(P.bounce));
  st[2] = make_float4(P.beta.x, P.beta.y, P.beta.z, P.bsdf_pdf);
  st[3] = make_float4(P.L.x, P.L.y, P.L.z, __uint_as_float(flags | (P.count_emission ? PATH_COUNT_EMISSION : 0u)));
}

extern "C" __global__ void path_init(const Params *params, float4 *states) {
  const Params *p = params;
  int i = (int)WL_TID;
  if (i >= p->num_paths) return;
  unsigned key = path_key((unsigned)i, (unsigned)p->frame, (unsigned)p->seed);
  store_path(states + 4 * i, i, camera_path(p, i, key), PATH_ACTIVE);
}

extern "C" __global__ void path_level(const Params *params, const uint4 *nodes, const unsigned *refs,
                                      const float4 *tris, const float4 *tri_data, const float4 *mats,
                                      const float4 *lights, const float4 *boxes, const float4 *env, float4 *states,
                                      unsigned n, float *accum, float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  const Params *p = params;
  unsigned j = WL_TID;
  if (j >= n) return;
  float4 *st = states + 4 * j;
  float4 e = st[3];
  unsigned flags = __float_as_uint(e.w);
  if (!(flags & PATH_ACTIVE)) return;
  float4 a = st[0];   // @count live ld.global.v4.u32
  float4 b = st[1], c = st[2];
  int i = __float_as_int(a.w);
  Path P;
  P.o = v3(a.x, a.y, a.z);
  P.d = v3(b.x, b.y, b.z);
  P.bounce = __float_as_int(b.w);
  P.beta = v3(c.x, c.y, c.z);
  P.bsdf_pdf = c.w;
  P.L = v3(e.x, e.y, e.z);
  P.count_emission = (flags & PATH_COUNT_EMISSION) != 0u;
  unsigned key = path_key((unsigned)i, (unsigned)p->frame, (unsigned)p->seed);
  if (step(s, P, key)) {
    store_path(st, i, P, PATH_ACTIVE);
  } else {
    finish(accum, last, i, P.L);
    st[3].w = __uint_as_float(0u);
  }
}

// ---- The 3-way Fresnel regroup (§6.3, 003:L536): regroup_init, regroup_trace, regroup_shade ----
//
// The wavefront form with trace and shade as separate launches, so that the
// branch a path's next shading takes is known before it runs: a level is
// regroup_trace (the next ray of every active state traced, its hit and that
// hit's branch stored) and then regroup_shade (the stored hit shaded: step()'s
// emission, light sample, next direction and roulette, step_at<true>). Between
// the two the host compacts the states three times (kernels/lin2017/compact.cu:
// regroup_flag, compact_scan, compact_scan_sums, regroup_scatter), once per
// branch, appending each into the second buffer, and swaps the buffers: the
// thesis' "3 stream compaction operations" into a double buffer (003:L536).
// Without regrouping the host compacts once (every active state) or not at all.
// The state is path_level's 4 float4 and a fifth [t, triangle, branch, 0]:
// 80 bytes. The branches are the Fresnel switch's three (003:L259-265):
// specular reflection (mirror, rough mirror, a coated material's coat),
// transmission (glass, rough glass: their reflect-or-refract choice is a
// select, not a branch, in scatter()) and diffuse reflection (a coated
// material's other side of the switch), with the paths that end at their next
// hit (an emitter or a miss) in the diffuse group. Path i's random numbers depend on i and its
// bounce only, so every order traces the megakernel's paths bit for bit.
#define REGROUP_STATE 5              // float4 per state
#define BRANCH_SPECULAR 0u
#define BRANCH_DIFFUSE 1u
#define BRANCH_TRANSMISSION 2u

// The Fresnel branch the shading of hit tri takes (tri < 0: a miss), for the
// ray's direction d at bounce `bounce` of the path with key `key`: a coated
// material's is its switch's own draw (scatter(): dimension dim + 6 against
// Schlick's R at the viewer's cosine), known before the shading runs.
static __device__ __forceinline__ unsigned next_branch(const Scene &s, int tri, V3 d, unsigned key, int bounce) {
  if (tri < 0) return BRANCH_DIFFUSE;
  float4 td = s.tri_data[tri];
  float4 m0 = s.mats[3 * __float_as_int(td.w)];
  int kind = __float_as_int(m0.w);
  if (kind == KIND_MIRROR || kind == KIND_CONDUCTOR) return BRANCH_SPECULAR;
  if (kind == KIND_GLASS || kind == KIND_ROUGH_GLASS) return BRANCH_TRANSMISSION;
  if (kind == KIND_COATED) {
    float fr = schlick(coat_r0(s.mats[3 * __float_as_int(td.w) + 1].w), fabsf(dot3(d, v3(td.x, td.y, td.z))));
    unsigned dim = DIMS_CAMERA + DIMS_PER_BOUNCE * (unsigned)bounce;
    if (rng(key, dim + 6) < fr || !(fr < 1.0f)) return BRANCH_SPECULAR;
  }
  return BRANCH_DIFFUSE;
}

extern "C" __global__ void regroup_init(const Params *params, float4 *states) {
  const Params *p = params;
  int i = (int)WL_TID;
  if (i >= p->num_paths) return;
  unsigned key = path_key((unsigned)i, (unsigned)p->frame, (unsigned)p->seed);
  store_path(states + REGROUP_STATE * i, i, camera_path(p, i, key), PATH_ACTIVE);
}

extern "C" __global__ void regroup_trace(const Params *params, const uint4 *nodes, const unsigned *refs,
                                         const float4 *tris, const float4 *tri_data, const float4 *mats,
                                         const float4 *lights, const float4 *boxes, const float4 *env,
                                         float4 *states, unsigned n) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  unsigned j = WL_TID;
  if (j >= n) return;
  float4 *st = states + REGROUP_STATE * j;
  if (!(__float_as_uint(st[3].w) & PATH_ACTIVE)) return;
  float4 a = st[0], b = st[1];
  Path P;
  P.o = v3(a.x, a.y, a.z);
  P.d = v3(b.x, b.y, b.z);
  float t;
  int tri = trace_next(s, P, &t);
  unsigned key = path_key((unsigned)__float_as_int(a.w), (unsigned)params->frame, (unsigned)params->seed);
  unsigned branch = next_branch(s, tri, P.d, key, __float_as_int(b.w));
  st[4] = make_float4(t, __int_as_float(tri), __uint_as_float(branch), 0.0f);
}

extern "C" __global__ void regroup_shade(const Params *params, const uint4 *nodes, const unsigned *refs,
                                         const float4 *tris, const float4 *tri_data, const float4 *mats,
                                         const float4 *lights, const float4 *boxes, const float4 *env,
                                         float4 *states, unsigned n, float *accum, float *last) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  const Params *p = params;
  unsigned j = WL_TID;
  if (j >= n) return;
  float4 *st = states + REGROUP_STATE * j;
  float4 e = st[3];
  unsigned flags = __float_as_uint(e.w);
  if (!(flags & PATH_ACTIVE)) return;
  float4 a = st[0], b = st[1], c = st[2], h = st[4];
  int i = __float_as_int(a.w);
  Path P;
  P.o = v3(a.x, a.y, a.z);
  P.d = v3(b.x, b.y, b.z);
  P.bounce = __float_as_int(b.w);
  P.beta = v3(c.x, c.y, c.z);
  P.bsdf_pdf = c.w;
  P.L = v3(e.x, e.y, e.z);
  P.count_emission = (flags & PATH_COUNT_EMISSION) != 0u;
  unsigned key = path_key((unsigned)i, (unsigned)p->frame, (unsigned)p->seed);
  if (step_at<true>(s, P, key, NoMedium(), NoTextures(), __float_as_int(h.y), h.x)) {
    store_path(st, i, P, PATH_ACTIVE);
  } else {
    finish(accum, last, i, P.L);
    st[3].w = __uint_as_float(0u);
  }
}

// ---- Metropolis light transport (§4.8, 003:L310-336): mlt_init, mlt_start, mlt_frame ----
//
// Primary-sample-space MLT over the path tracer named by p->integrator (pt,
// nee, mis or bdpt; the thesis runs it over bdpt, 003:L332): one Markov chain
// per pixel ("the number of threads is set to be equal to the number of screen
// pixels", 003:L328), its state the path's random numbers (mlt_slot(), 40 k
// bytes a chain) and its current radiance and pixel (a float4). A proposal's
// camera ray takes its subpixel and tent jitter from samples 0 and 1 over the
// whole image, so any chain splats anywhere. The scalar contribution is the
// luminance Y (003:L322); acceptance min(1, Y' / Y) (the mutations are
// symmetric, 003:L316); splats by expected values (the current sample weighted
// 1 - a, the proposal a), each b F / Y (003:L330) with b the bootstrap's mean
// luminance, added by 64-bit integer atomics in 32.32 fixed point: integer
// addition is associative, so the image does not depend on the order of the
// atomics and the native mirror (rayon) gets the same bits. Each chain starts
// at a bootstrap sample picked from all chains' in proportion to Y (the host's
// pick, mlt_start): the start is then distributed as the chains' stationary
// distribution. A pick among a chain's own 16 samples was not: most chains
// missed the light (1.2 % of primary sample space at 32 x 32, half of Y) and
// took hundreds of iterations to find it (the start-up bias that was issue 15's
// MLT bug).
#define MLT_BOOTSTRAP 16            // large-step samples per chain at start-up (not stated)
#define MLT_BOOTSTRAP_FRAME 0xffffffffu
#define MLT_STEPS 4                 // iterations per chain per frame (a frame's 4 samples a pixel)
#define MLT_FIXED 4294967296.0f     // 2^32: the splats' fixed point

typedef unsigned long long ull;
static __device__ __forceinline__ void add_u64(ull *a, ull v) {
#if defined(__NVCC__)
  atomicAdd(a, v);
#else
  __nvvm_atom_add_gen_ll((long long *)a, (long long)v);
#endif
}

// Y of an RGB radiance (003:L322).
static __device__ __forceinline__ float luminance(V3 c) {
  return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z;
}

// Adds the colour c times w to pixel `pixel` of the fixed-point image.
static __device__ __forceinline__ void splat(ull *image, int pixel, V3 c, float w) {
  ull *a = image + 3 * pixel;
  add_u64(a, (ull)(c.x * w * MLT_FIXED));
  add_u64(a + 1, (ull)(c.y * w * MLT_FIXED));
  add_u64(a + 2, (ull)(c.z * w * MLT_FIXED));
}

// The radiance the integrator p->integrator finds along camera path P with sampler key.
template <class K>
static __device__ __forceinline__ V3 radiance(const Scene &s, Path P, K key) {
  const Params *p = s.p;
  if (p->integrator == INTEGRATOR_BDPT) {
    LightVertex lv[LIGHT_VERTICES];
    int nl_max = p->num_lights > 0 ? imin(p->max_bounces, LIGHT_VERTICES) : 0;
    int nl = nl_max > 0 ? light_subpath(s, key, nl_max, lv) : 0;
    int run = 0;
    while (bdpt_step(s, P, key, lv, nl, nl_max, run)) {
    }
  } else {
    while (step(s, P, key)) {
    }
  }
  return P.L;
}

// A proposal's camera path: its subpixel of the 2W x 2H grid and its tent
// jitter from samples 0 and 1; *i the path index (4 pixel + subpixel).
static __device__ __forceinline__ Path mlt_camera(const Params *p, const Mlt &m, int *i) {
  float x = rng(m, 0) * (float)(2 * p->width), y = rng(m, 1) * (float)(2 * p->height);
  int sx = (int)x, sy = (int)y;
  if (sx > 2 * p->width - 1) sx = 2 * p->width - 1;
  if (sy > 2 * p->height - 1) sy = 2 * p->height - 1;
  *i = 4 * ((sy >> 1) * p->width + (sx >> 1)) + 2 * (sy & 1) + (sx & 1);
  return camera_ray(p, *i, x - (float)sx, y - (float)sy);
}

// The state floats of a chain: k = max bounces + 1 segments of MLT_SLOTS_PER_SEGMENT.
static __device__ __forceinline__ unsigned mlt_slots(const Params *p) {
  return MLT_SLOTS_PER_SEGMENT * (unsigned)(p->max_bounces + 1);
}

// The sample of sampler m (iteration `key` over chain samples u, a large step or
// a small one): its radiance F, *i its path index (the pixel is *i >> 2).
static __device__ __forceinline__ V3 mlt_sample(const Scene &s, const float *u, unsigned key, bool large, int *i) {
  const Params *p = s.p;
  Mlt m = {u, key, mlt_slots(p), (unsigned)p->max_bounces, large};
  Path P = mlt_camera(p, m, i);
  return radiance(s, P, m);
}

// The chain of this thread: its index *c and its samples *u (mlt_slots floats
// of state); false for a thread past the image's chains.
static __device__ __forceinline__ bool mlt_chain(const Params *p, float *state, int *c, float **u) {
  *c = (int)WL_TID;
  if (*c >= p->width * p->height) return false;
  *u = state + (ull)mlt_slots(p) * (ull)*c;
  return true;
}

// The key of bootstrap sample j (0 .. MLT_BOOTSTRAP W H - 1; chain c draws c MLT_BOOTSTRAP ...).
static __device__ __forceinline__ unsigned mlt_bootstrap_key(const Params *p, unsigned j) {
  return path_key(j, MLT_BOOTSTRAP_FRAME, (unsigned)p->seed);
}

// Start-up, 1: each chain draws MLT_BOOTSTRAP large-step samples and stores
// their luminances in boot (the host sums them to b, 003:L330, and picks each
// chain's start from all of them in proportion to Y: mlt_start).
extern "C" __global__ void mlt_init(const Params *params, const uint4 *nodes, const unsigned *refs,
                                    const float4 *tris, const float4 *tri_data, const float4 *mats,
                                    const float4 *lights, const float4 *boxes, const float4 *env, float *boot) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  const Params *p = params;
  int c = (int)WL_TID;
  if (c >= p->width * p->height) return;
  for (int j = 0; j < MLT_BOOTSTRAP; j++) {
    unsigned n = (unsigned)(MLT_BOOTSTRAP * c + j);
    int i;
    boot[n] = luminance(mlt_sample(s, nullptr, mlt_bootstrap_key(p, n), true, &i));
  }
}

// Start-up, 2: chain c starts at bootstrap sample start[c] (the host's pick):
// the sample is traced again (a large step is a function of its key) and its
// random numbers become the chain's state.
extern "C" __global__ void mlt_start(const Params *params, const uint4 *nodes, const unsigned *refs,
                                     const float4 *tris, const float4 *tri_data, const float4 *mats,
                                     const float4 *lights, const float4 *boxes, const float4 *env, float *state,
                                     float4 *chains, const unsigned *start) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  int c;
  float *u;
  if (!mlt_chain(params, state, &c, &u)) return;
  unsigned key = mlt_bootstrap_key(params, start[c]);
  int i;
  V3 L = mlt_sample(s, u, key, true, &i);
  for (unsigned k = 0; k < mlt_slots(params); k++) u[k] = rng(key, k);
  chains[c] = make_float4(L.x, L.y, L.z, __int_as_float(i >> 2));
}

// One frame: each chain takes MLT_STEPS iterations (a large step with
// probability MLT_P_LARGE), splatting both the current sample and the proposal.
extern "C" __global__ void mlt_frame(const Params *params, const uint4 *nodes, const unsigned *refs,
                                     const float4 *tris, const float4 *tri_data, const float4 *mats,
                                     const float4 *lights, const float4 *boxes, const float4 *env, float *state,
                                     float4 *chains, ull *image) {
  Scene s = {params, nodes, refs, tris, tri_data, mats, lights, boxes, env};
  const Params *p = params;
  int c;
  float *u;
  if (!mlt_chain(p, state, &c, &u)) return;
  unsigned slots = mlt_slots(p);
  float4 cur = chains[c];
  V3 fc = v3(cur.x, cur.y, cur.z);
  int pc = __float_as_int(cur.w);
  float yc = luminance(fc);
  float b = p->mlt_b;
  for (int t = 0; t < MLT_STEPS; t++) {
    unsigned key = path_key((unsigned)(MLT_STEPS * c + t), (unsigned)p->frame, (unsigned)p->seed);
    bool large = rng(key, MLT_DIM_LARGE) < MLT_P_LARGE;
    int i;
    V3 L = mlt_sample(s, u, key, large, &i);
    float y = luminance(L);
    float a = yc > 0.0f ? fminf(1.0f, y / yc) : 1.0f;
    if (yc > 0.0f) splat(image, pc, fc, (1.0f - a) * b / yc);
    if (y > 0.0f) splat(image, i >> 2, L, a * b / y);
    if (rng(key, MLT_DIM_ACCEPT) < a) {
      Mlt m = {u, key, slots, (unsigned)p->max_bounces, large};
      for (unsigned k = 0; k < slots; k++) u[k] = mlt_value(m, k);
      fc = L;
      pc = i >> 2;
      yc = y;
    }
  }
  chains[c] = make_float4(fc.x, fc.y, fc.z, __int_as_float(pc));
}
