// Thesis 000 §5.2: variable kernel density estimation with kernels built from
// photon differentials.
//
// construct_kernels: one thread per stored interaction (the photon kernel's
// 24-float slots). p is the parameter with the longer position differential;
// the interaction is discarded when the footprint height |D_p x D_p'| / |D_p|
// is below f |D_p| (eq. 5.33); both differentials are dampened by
// |D_p|^(1/4) / |D_p|; M = s dp g D_p, m1 = s dp g D_p', m2 = |m1| n with
// M, m1, m2 right-handed; axes longer than h_max are clamped; the flux is
// stored as flux / |M x m1|; m' = |m1| (m1 x m2) / |m1 x m2|; the AABB has the
// half-extents sqrt(M_i^2 + m1_i^2 + m2_i^2).
//
// estimate_vkde: one thread per query point; a stack traversal of the BVH
// photon map with Alg. 3.5's strict point test; per kernel the back-face test
// n_j . n_x > 0 and |d|^2 = q^2 + |q M - delta|^2 / |m'|^2 with
// q = (m' . delta) / (m' . M) (L2408, extract erratum 4); uniform (1/pi) or
// Epanechnikov ((1 - |d|^2) 2/pi) weights; L = (rho / pi) sum K flux'.
//
// src/repro/fabianowski2011/vkde.rs repeats every float operation in the same
// order: records and estimates agree bit for bit. Keep the two in step.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define SLOT 24
#define RECORD 24
#define KERNEL 16
#define QUERY 12
#define ESTIMATE 8
#define STACK 64
#define LEAF_BIT 0x80000000u

struct V3 { float x, y, z; };
static __device__ __forceinline__ V3 v3(float x, float y, float z) { V3 r = {x, y, z}; return r; }
static __device__ __forceinline__ float dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static __device__ __forceinline__ V3 sub3(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static __device__ __forceinline__ V3 scale3(V3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static __device__ __forceinline__ V3 cross3(V3 a, V3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static __device__ __forceinline__ float len3(V3 a) { return sqrtf(dot3(a, a)); }
static __device__ __forceinline__ V3 get3(const float *p) { return v3(__ldg(p), __ldg(p + 1), __ldg(p + 2)); }
static __device__ __forceinline__ void put3(float *o, V3 v) {
  o[0] = v.x;
  o[1] = v.y;
  o[2] = v.z;
}

struct ConstructParams {
  float dp, spread, h_max, f;
  int count;
};

extern "C" __global__ void construct_kernels(const ConstructParams *p, const float *slots, float *out) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    const float *s = slots + i * SLOT;
    float *o = out + i * RECORD;
    V3 z = get3(s), flux = get3(s + 3), d1 = get3(s + 6), d2 = get3(s + 9), n = get3(s + 18);
    float l1 = len3(d1), l2 = len3(d2);
    V3 a = d1, b = d2;
    float la = l1;
    if (l2 > l1) { a = d2; b = d1; la = l2; }
    // eq. 5.33: discard a degenerate footprint
    float height = len3(cross3(a, b)) / la;
    if (!(height >= p->f * la)) {
      o[21] = __uint_as_float(2u);
      continue;
    }
    // dampening (both differentials by the same factor), spread
    float g = sqrtf(sqrtf(la)) / la;
    float k = p->dp * g * p->spread;
    V3 major = scale3(a, k), minor = scale3(b, k);
    if (dot3(cross3(major, minor), n) < 0.0f) minor = scale3(minor, -1.0f);
    float lm = len3(major), l1m = len3(minor);
    float clamped = 0.0f;
    if (lm > p->h_max) {
      major = scale3(major, p->h_max / lm);
      clamped = 1.0f;
    }
    float r1 = l1m;
    if (l1m > p->h_max) {
      minor = scale3(minor, p->h_max / l1m);
      r1 = p->h_max;
      clamped = 1.0f;
    }
    V3 m2 = scale3(n, r1);
    float area = len3(cross3(major, minor));
    V3 m = cross3(minor, m2);
    V3 mp = scale3(m, r1 / len3(m));
    V3 e = v3(sqrtf(major.x * major.x + minor.x * minor.x + m2.x * m2.x),
              sqrtf(major.y * major.y + minor.y * minor.y + m2.y * m2.y),
              sqrtf(major.z * major.z + minor.z * minor.z + m2.z * m2.z));
    put3(o, z);
    put3(o + 3, major);
    put3(o + 6, mp);
    put3(o + 9, v3(flux.x / area, flux.y / area, flux.z / area));
    put3(o + 12, n);
    put3(o + 15, sub3(z, e));
    put3(o + 18, v3(z.x + e.x, z.y + e.y, z.z + e.z));
    o[21] = __uint_as_float(1u);
    o[22] = clamped;
    o[23] = area;
  }
}

struct EstimateParams {
  int count, shape, nodes, pad;
};

// 32-byte nodes: lo[3], hi[3], a, b (inner: children a, b; leaf: first a, count b & ~LEAF_BIT)
extern "C" __global__ void estimate_vkde(const EstimateParams *p, const float *nodes, const float *kernels,
                                         const float *queries, float *out) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    const float *q = queries + i * QUERY;
    float *o = out + i * ESTIMATE;
    if (__ldg(q + 3) != 1.0f || p->nodes == 0) continue;
    V3 x = get3(q), nx = get3(q + 4), rho = get3(q + 8);
    V3 sum = v3(0.0f, 0.0f, 0.0f);
    unsigned contributions = 0, visited = 0, retrieved = 0;
    unsigned stack[STACK];
    int size = 1;
    stack[0] = 0;
    while (size > 0) {
      size--;
      const float *nd = nodes + 8 * stack[size];
      visited++;
      // Alg. 3.5
      if (!(__ldg(nd) < x.x && __ldg(nd + 1) < x.y && __ldg(nd + 2) < x.z && __ldg(nd + 3) > x.x &&
            __ldg(nd + 4) > x.y && __ldg(nd + 5) > x.z))
        continue;
      unsigned a = __float_as_uint(__ldg(nd + 6)), b = __float_as_uint(__ldg(nd + 7));
      if ((b & LEAF_BIT) == 0) {
        stack[size] = b;
        stack[size + 1] = a;
        size += 2;
        continue;
      }
      unsigned end = a + (b & ~LEAF_BIT);
      for (unsigned j = a; j < end; j++) {
        const float *k = kernels + j * KERNEL;
        retrieved++;
        if (!(dot3(get3(k + 12), nx) > 0.0f)) continue;
        V3 z = get3(k), major = get3(k + 3), mp = get3(k + 6);
        V3 d = sub3(x, z);
        float qq = dot3(mp, d) / dot3(mp, major);
        V3 r = v3(major.x * qq - d.x, major.y * qq - d.y, major.z * qq - d.z);
        float dd = qq * qq + dot3(r, r) / dot3(mp, mp);
        if (!(dd < 1.0f)) continue;
        float w = p->shape == 0 ? 0.318309886183790672f : (1.0f - dd) * 0.636619772367581343f;
        V3 f = get3(k + 9);
        sum = v3(sum.x + w * f.x, sum.y + w * f.y, sum.z + w * f.z);
        contributions++;
      }
    }
    const float inv_pi = 0.318309886183790672f;
    o[0] = rho.x * inv_pi * sum.x;
    o[1] = rho.y * inv_pi * sum.y;
    o[2] = rho.z * inv_pi * sum.z;
    o[3] = __uint_as_float(contributions);
    o[4] = __uint_as_float(visited);
    o[5] = __uint_as_float(retrieved);
  }
}
