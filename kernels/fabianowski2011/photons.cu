// Thesis 000 §5.1: photon tracing with photon differentials, one thread per photon.
//
// An isotropic point light emits n photons of equal flux (eq. 5.1, alpha = pi);
// each carries its position z, direction w and the four differentials
// dz/dp1, dz/dp2, dw/dp1, dw/dp2 (pre-scaled so that one global
// Delta p = sqrt(4 pi / n) applies, eqs. 5.9-5.11). At every surface hit the
// differentials are propagated (eqs. 3.7-3.9); interaction 2 and 3 on a diffuse
// surface are stored; Russian roulette with the mean reflectivity rho keeps the
// photon (flux scaled by rho_i / rho, differentials by rho^(-1/2), §5.1.4);
// a mirror reflects it (eqs. 3.10-3.11; where the scene has vertex normals
// about the interpolated normal with dn/dp from eqs. 5.12-5.21, otherwise
// flat: dn/dp = 0); a diffuse
// surface absorbs and re-emits it with cosine sampling and the virtual offset
// t_v (eqs. 5.25-5.29). Tracing ends at the 3rd interaction.
//
// Random numbers are counter based (hash of photon index and dimension), so
// a run is reproducible and src/repro/fabianowski2011/photons.rs replays each
// photon with the same float operations in the same order: the stored photons
// agree bit for bit. Keep the two in step.
//
// The kd-tree traversal is the stack-based one of raytrace.cu (no caches),
// with the same layout: 8-byte nodes, triangle references, Wald triangles.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

// Floats per stored photon slot (two slots per photon: interactions 2 and 3):
// [0,3) z, [3,6) flux, [6,9) dz/dp1, [9,12) dz/dp2, [12,15) dw/dp1,
// [15,18) dw/dp2, [18,21) normal (facing the incoming photon), 21 triangle
// (bits), 22 interaction (bits), 23 valid (1.0).
#define SLOT 24

struct Params {
  float light_pos[3], flux[3];
  float lo[3], hi[3];
  float eps;
  int num_photons;
  int has_normals;  // 0: no vertex normals (flat mirrors); 1: `nrm` holds them
};

struct V3 { float x, y, z; };
static __device__ __forceinline__ V3 v3(float x, float y, float z) { V3 r = {x, y, z}; return r; }
static __device__ __forceinline__ float comp(V3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
static __device__ __forceinline__ float dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static __device__ __forceinline__ V3 add3(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static __device__ __forceinline__ V3 scale3(V3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static __device__ __forceinline__ V3 cross3(V3 a, V3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static __device__ __forceinline__ float len3(V3 a) { return sqrtf(dot3(a, a)); }

struct Scene {
  const Params *p;
  const uint2 *nodes;      // 8-byte nodes: split bits, pair << 2 | axis (3 = leaf: first << 2 | 3, count)
  const unsigned *refs;    // triangle references
  const float4 *tris;      // 3 float4 per triangle: [n'i n'j n'd k], [e'1], [e'2]
  const unsigned *tri_mat; // material per triangle
  const float4 *mats;      // [r g b kind], kind: 0 diffuse, 1 mirror, 2 emitter; then [emission, 0]
  const float *nrm;        // 9 floats per triangle: n0, n'1 = n1 - n0, n'2 = n2 - n0 (L2247)
};

// The counter-based generator: a uniform float in [0, 1) with 24 random bits
// for photon `i`, dimension `d` (two rounds of a 32-bit integer hash).
static __device__ __forceinline__ float rng(unsigned i, unsigned d) {
  unsigned h = i * 0x9e3779b9u ^ (d + 1u) * 0x85ebca6bu;
  for (int r = 0; r < 2; r++) {
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
  }
  return (float)(h >> 8) * (1.0f / 16777216.0f);
}

// (cos, sin) of the azimuth 2 pi y for y in [0, 1): a quarter turn q = floor(4y),
// the rest x in [-pi/4, pi/4) by Taylor polynomials (error < 1e-8), rotated by
// pi/4 and q quarter turns.
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

// Alg. 3.3: Wald's test; updates t_hit and the barycentric weights (u, v) of
// vertices 1 and 2 and returns true on a hit.
static __device__ __forceinline__ bool wald(const Scene &s, unsigned t, V3 o, V3 d, float t_min, float *t_hit,
                                            float *u_hit, float *v_hit) {
  const float *w = (const float *)(s.tris + 3 * t);
  float n0 = __ldg(w), n1 = __ldg(w + 1), n2 = __ldg(w + 2);
  int k = __float_as_int(__ldg(w + 3));
  int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
  float num = n2 - comp(o, k) - n0 * comp(o, a) - n1 * comp(o, b);
  float tt = num / (comp(d, k) + n0 * comp(d, a) + n1 * comp(d, b));
  if (!(tt >= t_min && tt <= *t_hit)) return false;
  float hx = comp(o, a) + tt * comp(d, a);
  float hy = comp(o, b) + tt * comp(d, b);
  float u = __ldg(w + 8) * hx + __ldg(w + 9) * hy + __ldg(w + 10);
  float v = __ldg(w + 4) * hx + __ldg(w + 5) * hy + __ldg(w + 6);
  if (u < 0.0f || v < 0.0f || u + v > 1.0f) return false;
  *t_hit = tt;
  *u_hit = u;
  *v_hit = v;
  return true;
}

// The nearest hit in (t_min, inf) and its barycentric weights: the stack-based traversal of raytrace.cu.
static __device__ int trace(const Scene &s, V3 o, V3 d, float t_min, float *t_out, float *u_out, float *v_out) {
  V3 inv = v3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
  const Params *p = s.p;
  float t0x = (p->lo[0] - o.x) * inv.x, t1x = (p->hi[0] - o.x) * inv.x;
  float t0y = (p->lo[1] - o.y) * inv.y, t1y = (p->hi[1] - o.y) * inv.y;
  float t0z = (p->lo[2] - o.z) * inv.z, t1z = (p->hi[2] - o.z) * inv.z;
  float tn = fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fminf(t0z, t1z));
  float tf = fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
  float ta = fmaxf(t_min, tn), tb = tf;
  if (!(ta <= tb)) return -1;
  float t_hit = __int_as_float(0x7f800000);
  struct Entry { unsigned node; float tb; } stack[33];
  int size = 0;
  unsigned node = 0;
  for (;;) {
    const unsigned *w = (const unsigned *)(s.nodes + node);
    uint2 n = make_uint2(__ldg(w), __ldg(w + 1));
    while ((n.y & 3) != 3) {
      int k = n.y & 3;
      float ts = (__int_as_float(n.x) - comp(o, k)) * comp(inv, k);
      unsigned left = 2 * (n.y >> 2) + 1, right = left + 1;
      bool neg = __float_as_int(comp(d, k)) < 0;
      unsigned near = neg ? right : left, far = neg ? left : right;
      if (ts > tb || ts != ts) {
        node = near;
      } else if (ts < ta) {
        node = far;
      } else {
        stack[size].node = far;
        stack[size].tb = tb;
        size++;
        tb = ts;
        node = near;
      }
      w = (const unsigned *)(s.nodes + node);
      n = make_uint2(__ldg(w), __ldg(w + 1));
    }
    float lo = fmaxf(ta - p->eps, t_min);
    float saved = t_hit;
    t_hit = fminf(t_hit, tb + p->eps);
    int found = -1;
    for (unsigned r = 0; r < n.x; r++) {
      unsigned t = __ldg(s.refs + (n.y >> 2) + r);
      if (wald(s, t, o, d, lo, &t_hit, u_out, v_out)) found = (int)t;
    }
    if (found >= 0) {
      *t_out = t_hit;
      return found;
    }
    t_hit = saved;
    if (size == 0) return -1;
    size--;
    ta = tb;
    tb = stack[size].tb;
    node = stack[size].node;
  }
}

// The geometric normal of triangle t from the Wald form, facing against d.
static __device__ V3 normal_of(const Scene &s, unsigned t, V3 d) {
  const float *w = (const float *)(s.tris + 3 * t);
  int k = __float_as_int(__ldg(w + 3));
  float n[3];
  n[k] = 1.0f;
  n[k == 2 ? 0 : k + 1] = __ldg(w);
  n[k == 0 ? 2 : k - 1] = __ldg(w + 1);
  float inv = 1.0f / sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  V3 v = v3(n[0] * inv, n[1] * inv, n[2] * inv);
  if (v.x * d.x + v.y * d.y + v.z * d.z > 0.0f) v = v3(-v.x, -v.y, -v.z);
  return v;
}

// Component c of the row of dlambda/dz (eq. 5.21) whose values at the axes
// i = k + 1 and j = k + 2 (mod 3) are a and b: zero at axis k.
static __device__ __forceinline__ V3 place(int k, float a, float b) {
  return v3(k == 0 ? 0.0f : (k == 2 ? a : b), k == 1 ? 0.0f : (k == 0 ? a : b), k == 2 ? 0.0f : (k == 1 ? a : b));
}

static __device__ __forceinline__ bool finite3(V3 a) {
  const float inf = __int_as_float(0x7f800000);
  return fabsf(a.x) < inf && fabsf(a.y) < inf && fabsf(a.z) < inf;
}

// Mirror reflection at the barycentric weights (u, v) of triangle t about the
// interpolated normal n(lambda) = normalize(n0 + u n'1 + v n'2) (L2247), with
// dn/dp = (dn/dlambda)(dlambda/dz)(dz/dp) (eqs. 5.12, 5.13, 5.21) in eq. 3.11:
// dw' = dw - 2[(w.n) dn/dp + (dw.n + w.dn/dp) n]. Returns false (nothing
// changed) where ||n'(lambda)|| is 0 or a derivative is not finite: the
// caller reflects about the flat normal. photons.rs's shading_normal and
// reflect_curved perform the same operations in the same order.
static __device__ bool reflect_curved(const Scene &s, unsigned t, float u, float v, V3 *w, V3 *dz1, V3 *dz2,
                                      V3 *dw1, V3 *dw2) {
  const float *q = s.nrm + 9 * t;
  V3 n0 = v3(__ldg(q), __ldg(q + 1), __ldg(q + 2));
  V3 d1 = v3(__ldg(q + 3), __ldg(q + 4), __ldg(q + 5));
  V3 d2 = v3(__ldg(q + 6), __ldg(q + 7), __ldg(q + 8));
  V3 raw = add3(n0, add3(scale3(d1, u), scale3(d2, v)));
  float l = len3(raw);
  if (!(l > 0.0f && l < __int_as_float(0x7f800000))) return false;
  float il = 1.0f / l;
  V3 n = scale3(raw, il);
  V3 dnu = scale3(add3(d1, scale3(n, -dot3(d1, n))), il);
  V3 dnv = scale3(add3(d2, scale3(n, -dot3(d2, n))), il);
  const float *w4 = (const float *)(s.tris + 3 * t);
  int k = __float_as_int(__ldg(w4 + 3));
  V3 ru = place(k, __ldg(w4 + 8), __ldg(w4 + 9));  // du/dz from e'2
  V3 rv = place(k, __ldg(w4 + 4), __ldg(w4 + 5));  // dv/dz from e'1
  if (!(finite3(dnu) && finite3(dnv) && finite3(ru) && finite3(rv))) return false;
  float wn = dot3(*w, n);
  V3 dn1 = add3(scale3(dnu, dot3(ru, *dz1)), scale3(dnv, dot3(rv, *dz1)));
  float c1 = dot3(*dw1, n) + dot3(*w, dn1);
  *dw1 = add3(*dw1, scale3(add3(scale3(dn1, wn), scale3(n, c1)), -2.0f));
  V3 dn2 = add3(scale3(dnu, dot3(ru, *dz2)), scale3(dnv, dot3(rv, *dz2)));
  float c2 = dot3(*dw2, n) + dot3(*w, dn2);
  *dw2 = add3(*dw2, scale3(add3(scale3(dn2, wn), scale3(n, c2)), -2.0f));
  *w = add3(*w, scale3(n, -2.0f * wn));
  return true;
}

static __device__ __forceinline__ void put(float *o, int at, V3 v) {
  o[at] = v.x;
  o[at + 1] = v.y;
  o[at + 2] = v.z;
}

extern "C" __global__ void trace_photons(const Params *p, const uint2 *nodes, const unsigned *refs,
                                         const float4 *tris, const unsigned *tri_mat, const float4 *mats,
                                         const float *nrm, float *out) {
  Scene s = {p, nodes, refs, tris, tri_mat, mats, nrm};
  for (unsigned i = WL_TID; i < (unsigned)p->num_photons; i += blockDim.x * gridDim.x) {
    // emission (eqs. 5.1, 5.9-5.10 with alpha = pi, R = I): cos p1 = y1 in [-1, 1)
    float cp1 = rng(i, 0) * 2.0f - 1.0f;
    float sp1 = sqrtf(fmaxf(1.0f - cp1 * cp1, 0.0f));
    float cp2, sp2;
    azimuth(rng(i, 1), &cp2, &sp2);
    V3 z = v3(p->light_pos[0], p->light_pos[1], p->light_pos[2]);
    V3 w = v3(cp2 * sp1, sp2 * sp1, cp1);
    V3 dz1 = v3(0.0f, 0.0f, 0.0f), dz2 = v3(0.0f, 0.0f, 0.0f);
    V3 dw1 = v3(cp2 * cp1, sp2 * cp1, -sp1);
    V3 dw2 = v3(-sp2, cp2, 0.0f);
    V3 flux = v3(p->flux[0], p->flux[1], p->flux[2]);
    for (int k = 1; k <= 3; k++) {
      float t, hu = 0.0f, hv = 0.0f;
      int h = trace(s, z, w, p->eps, &t, &hu, &hv);
      if (h < 0) break;
      V3 n = normal_of(s, (unsigned)h, w);
      // propagation (eqs. 3.7-3.9)
      float wn = dot3(w, n);
      V3 a1 = add3(dz1, scale3(dw1, t)), a2 = add3(dz2, scale3(dw2, t));
      float dt1 = -dot3(a1, n) / wn, dt2 = -dot3(a2, n) / wn;
      dz1 = add3(a1, scale3(w, dt1));
      dz2 = add3(a2, scale3(w, dt2));
      z = v3(z.x + w.x * t, z.y + w.y * t, z.z + w.z * t);
      unsigned m = __ldg(tri_mat + h);
      const float *mat = (const float *)(mats + 2 * m);
      V3 col = v3(__ldg(mat), __ldg(mat + 1), __ldg(mat + 2));
      float kind = __ldg(mat + 3);
      if (kind == 2.0f) break;                                 // an emitter absorbs
      bool diffuse = kind == 0.0f;
      if (diffuse && k >= 2) {                                 // store interactions 2 and 3
        float *o = out + (2 * i + (k - 2)) * SLOT;
        put(o, 0, z);
        put(o, 3, flux);
        put(o, 6, dz1);
        put(o, 9, dz2);
        put(o, 12, dw1);
        put(o, 15, dw2);
        put(o, 18, n);
        o[21] = __uint_as_float((unsigned)h);
        o[22] = __uint_as_float((unsigned)k);
        o[23] = 1.0f;
      }
      if (k == 3) break;
      // Russian roulette (§5.1.4) with the mean reflectivity
      float rho = (col.x + col.y + col.z) / 3.0f;
      if (!(rng(i, 4 * k - 2) < rho)) break;
      flux = v3(flux.x * (col.x / rho), flux.y * (col.y / rho), flux.z * (col.z / rho));
      float g = 1.0f / sqrtf(rho);
      dz1 = scale3(dz1, g);
      dz2 = scale3(dz2, g);
      dw1 = scale3(dw1, g);
      dw2 = scale3(dw2, g);
      if (!diffuse) {
        // specular reflection about the interpolated normal (eqs. 3.10-3.11, 5.12-5.21)
        if (p->has_normals && reflect_curved(s, (unsigned)h, hu, hv, &w, &dz1, &dz2, &dw1, &dw2)) continue;
        // a flat mirror (eqs. 3.10-3.11 with dn/dp = 0)
        float s2 = 2.0f * wn;
        w = v3(w.x - s2 * n.x, w.y - s2 * n.y, w.z - s2 * n.z);
        float s1 = 2.0f * dot3(dw1, n), s3 = 2.0f * dot3(dw2, n);
        dw1 = v3(dw1.x - s1 * n.x, dw1.y - s1 * n.y, dw1.z - s1 * n.z);
        dw2 = v3(dw2.x - s3 * n.x, dw2.y - s3 * n.y, dw2.z - s3 * n.z);
        continue;
      }
      // diffuse absorption and re-emission (eqs. 5.22-5.29): the virtual offset first
      float tv = sqrtf(2.0f * len3(cross3(dz1, dz2)));
      float y1 = rng(i, 4 * k - 1);
      float c1 = sqrtf(1.0f - y1), s1 = sqrtf(y1);
      float c2, s2;
      azimuth(rng(i, 4 * k), &c2, &s2);
      // the local frame: tangent from the x axis (the y axis when n is near x), bitangent n x tangent
      V3 ax = fabsf(n.x) < 0.5f ? v3(1.0f, 0.0f, 0.0f) : v3(0.0f, 1.0f, 0.0f);
      V3 tg = add3(ax, scale3(n, -dot3(ax, n)));
      tg = scale3(tg, 1.0f / len3(tg));
      V3 bt = cross3(n, tg);
      float sc = sqrtf(1.0f / (4.0f * c1));
      w = add3(add3(scale3(tg, c2 * s1), scale3(bt, s2 * s1)), scale3(n, c1));
      dw1 = add3(add3(scale3(tg, c2 * c1 * sc), scale3(bt, s2 * c1 * sc)), scale3(n, -s1 * sc));
      dw2 = add3(scale3(tg, -s2 * sc), scale3(bt, c2 * sc));
      dz1 = scale3(dw1, tv);
      dz2 = scale3(dw2, tv);
    }
  }
}
