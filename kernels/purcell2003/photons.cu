// Seed 004 (Purcell et al. 2003) §2.1: breadth-first photon tracing, one
// launch per pass, and the eye rays that give the radiance estimate its query
// points (§2.4). One thread per photon (per pixel); every pass reads the
// previous pass's "frame" of the photon arrays and writes its own
// (frame b of array X is X[b * n + i]), as the paper renders each bounce into
// a non-overlapping frame of a photon texture.
//
// Photon frame layout (float4 each, laid out by src/repro/purcell2003/photons.rs):
//   pos[f]  = (x, y, z, stored)   stored = 1: a photon of the map, 0: invalid
//   pow[f]  = (r, g, b, alive)    alive = 1: the photon travels on from here
//   dir[f]  = (incoming direction, 0)
//   out[f]  = (outgoing direction, 0)
// Frame 0 is the emission (positions on the light, first directions); it
// holds no stored photon. Photons that leave the scene are marked invalid
// (stored = 0, alive = 0): a 2003 fragment program cannot drop them.
//
// The paper's texture of random numbers is replaced by a counter-based
// generator: the random number of (seed, photon, pass, dimension) is a hash,
// the same on every schedule (rng_unit, mirrored by photons.rs).
//
// Scene: triangles as (v0, e1, e2) and a material index, intersected by brute
// force (the paper's scenes have no acceleration structure, 004:L150).
// Materials: (r, g, b, kind) and (ior, 0, 0, 0): kind 0 diffuse (photon
// stored, Russian roulette on the albedo, cosine-weighted bounce), 1 mirror,
// 2 glass (Schlick-Fresnel choice of reflection or refraction), 3 emitter
// (absorbs).
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

static __device__ __forceinline__ int imin(int a, int b) { return a < b ? a : b; }
static __device__ __forceinline__ int imax(int a, int b) { return a > b ? a : b; }
static __device__ __forceinline__ unsigned umin(unsigned a, unsigned b) { return a < b ? a : b; }
static __device__ __forceinline__ unsigned umax(unsigned a, unsigned b) { return a > b ? a : b; }

struct V3 { float x, y, z; };
static __device__ __forceinline__ V3 v3(float x, float y, float z) { V3 r = {x, y, z}; return r; }
static __device__ __forceinline__ V3 add(V3 a, V3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static __device__ __forceinline__ V3 sub(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static __device__ __forceinline__ V3 mul(V3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static __device__ __forceinline__ float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static __device__ __forceinline__ V3 cross(V3 a, V3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static __device__ __forceinline__ V3 normalize(V3 v) { return mul(v, 1.0f / sqrtf(dot(v, v))); }

// Counter-based random numbers: lowbias32 (Chris Wellons' integer hash).
static __device__ __forceinline__ unsigned hash32(unsigned x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
// A number in [0, 1) for (seed, item, pass, dimension).
static __device__ __forceinline__ float rng_unit(unsigned seed, unsigned item, unsigned pass, unsigned dim) {
  unsigned h = hash32(seed ^ hash32(item ^ hash32(pass * 8u + dim)));
  return (float)(h >> 8) * (1.0f / 16777216.0f);
}

// Scene constants passed by value.
struct Scene {
  int num_tris;      // triangles
  int num_lights;    // emissive triangles (area light), 0: point light
  float eps;         // ray offset
  float pad;
  float light[4];    // point light position (num_lights == 0)
  float power[4];    // power per emitted photon (rgb)
  float cone[4];     // point light: axis and cosine of the half-angle of the emission cone
  float radiance[4]; // area light: emitted radiance (rgb); point light: intensity (rgb)
};

struct Hit { float t; int tri; };

// Nearest hit along o + t d, t in (eps, inf): every triangle (Moller-Trumbore).
static __device__ Hit intersect(const float *tris, int n, V3 o, V3 d, float eps) {
  Hit h = {3.0e38f, -1};
  for (int i = 0; i < n; ++i) {
    const float *t = tris + 12 * i;
    V3 v0 = v3(t[0], t[1], t[2]), e1 = v3(t[3], t[4], t[5]), e2 = v3(t[6], t[7], t[8]);
    V3 p = cross(d, e2);
    float det = dot(e1, p);
    if (fabsf(det) < 1e-12f) continue;
    float inv = 1.0f / det;
    V3 s = sub(o, v0);
    float u = dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) continue;
    V3 q = cross(s, e1);
    float v = dot(d, q) * inv;
    if (v < 0.0f || u + v > 1.0f) continue;
    float tt = dot(e2, q) * inv;
    if (tt > eps && tt < h.t) { h.t = tt; h.tri = i; }
  }
  return h;
}

static __device__ __forceinline__ V3 tri_normal(const float *tris, int i) {
  const float *t = tris + 12 * i;
  return normalize(cross(v3(t[3], t[4], t[5]), v3(t[6], t[7], t[8])));
}

// A cosine-weighted direction about n from two uniform numbers.
static __device__ __forceinline__ V3 cosine_dir(V3 n, float u1, float u2) {
  V3 a = fabsf(n.x) > 0.5f ? v3(0.0f, 1.0f, 0.0f) : v3(1.0f, 0.0f, 0.0f);
  V3 t = normalize(cross(a, n));
  V3 b = cross(n, t);
  float r = sqrtf(u1), phi = 6.28318530718f * u2;
  float x = r * __cosf(phi), y = r * __sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
  return add(add(mul(t, x), mul(b, y)), mul(n, z));
}

static __device__ __forceinline__ V3 reflect(V3 d, V3 n) { return sub(d, mul(n, 2.0f * dot(d, n))); }

// The specular continuation at a mirror or glass hit: the new direction.
// Glass: Schlick's Fresnel term picks reflection with its probability.
static __device__ __forceinline__ V3 specular(V3 d, V3 n, int kind, float ior, float u) {
  if (kind == 1) return reflect(d, n);
  float c = dot(d, n);
  float eta = 1.0f / ior;
  V3 nn = n;
  if (c > 0.0f) { eta = ior; nn = mul(n, -1.0f); } else { c = -c; }
  float k = 1.0f - eta * eta * (1.0f - c * c);
  float r0 = (1.0f - ior) / (1.0f + ior);
  r0 = r0 * r0;
  float m = 1.0f - c;
  float fr = r0 + (1.0f - r0) * m * m * m * m * m;
  if (k < 0.0f || u < fr) return reflect(d, nn);
  return normalize(add(mul(d, eta), mul(nn, eta * c - sqrtf(k))));
}

// Pass 0: emission. Photon i starts on the light: a point light emits
// uniformly into the cone of directions about sc.cone's axis that holds the
// scene (a projection map; cos = -1 and axis +z: the whole sphere); an area light (emissive triangles lights[]) from
// a uniformly chosen triangle, uniformly on it, cosine-weighted about its
// normal turned towards `toward`.
extern "C" __global__ void emit(Scene sc, const float *tris, const int *lights, float4 *pos, float4 *pw,
                                float4 *dir, float4 *out, int n, unsigned seed, float tx, float ty, float tz) {
  int i = WL_TID;
  if (i >= n) return;
  float u0 = rng_unit(seed, i, 0, 0), u1 = rng_unit(seed, i, 0, 1), u2 = rng_unit(seed, i, 0, 2),
        u3 = rng_unit(seed, i, 0, 3), u4 = rng_unit(seed, i, 0, 4);
  V3 p, d;
  if (sc.num_lights == 0) {
    p = v3(sc.light[0], sc.light[1], sc.light[2]);
    float z = 1.0f - u0 * (1.0f - sc.cone[3]), r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 6.28318530718f * u1;
    V3 a = v3(sc.cone[0], sc.cone[1], sc.cone[2]), t = v3(1.0f, 0.0f, 0.0f), b = v3(0.0f, 1.0f, 0.0f);
    if (a.z < 0.999999f) {
      t = normalize(cross(v3(0.0f, 0.0f, 1.0f), a));
      b = cross(a, t);
    }
    d = add(add(mul(t, r * __cosf(phi)), mul(b, r * __sinf(phi))), mul(a, z));
  } else {
    int l = imin((int)(u0 * sc.num_lights), sc.num_lights - 1);
    int ti = lights[l];
    const float *t = tris + 12 * ti;
    float a = u1, b = u2;
    if (a + b > 1.0f) { a = 1.0f - a; b = 1.0f - b; }
    p = add(v3(t[0], t[1], t[2]), add(mul(v3(t[3], t[4], t[5]), a), mul(v3(t[6], t[7], t[8]), b)));
    V3 nrm = tri_normal(tris, ti);
    if (dot(nrm, sub(v3(tx, ty, tz), p)) < 0.0f) nrm = mul(nrm, -1.0f);
    d = cosine_dir(nrm, u3, u4);
  }
  pos[i] = make_float4(p.x, p.y, p.z, 0.0f);
  pw[i] = make_float4(sc.power[0], sc.power[1], sc.power[2], 1.0f);
  dir[i] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  out[i] = make_float4(d.x, d.y, d.z, 0.0f);
}

// Pass b >= 1: one bounce. Reads frame b - 1, writes frame b. A photon that
// lands on a diffuse surface is stored, except, when `direct` is 0, one that
// comes straight from the light (b == 1): the shadow rays give direct light
// (004:L140), so the map holds indirect light and caustics only.
extern "C" __global__ void bounce(Scene sc, const float *tris, const float4 *mats, float4 *pos, float4 *pw,
                                  float4 *dir, float4 *out, int n, int b, unsigned seed, int direct) {
  int i = WL_TID;
  if (i >= n) return;
  int prev = (b - 1) * n + i, cur = b * n + i;
  float4 p4 = pos[prev], w4 = pw[prev], o4 = out[prev];
  float4 np = make_float4(p4.x, p4.y, p4.z, 0.0f);
  float4 nw = make_float4(w4.x, w4.y, w4.z, 0.0f);
  float4 nd = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  float4 no = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  if (w4.w != 0.0f) {
    V3 o = v3(p4.x, p4.y, p4.z), d = v3(o4.x, o4.y, o4.z);
    Hit h = intersect(tris, sc.num_tris, o, d, sc.eps);
    if (h.tri >= 0) {
      V3 x = add(o, mul(d, h.t));
      int m = __float_as_int(tris[12 * h.tri + 9]);
      float4 c = mats[2 * m], e = mats[2 * m + 1];
      int kind = (int)c.w;
      V3 nrm = tri_normal(tris, h.tri);
      np = make_float4(x.x, x.y, x.z, 0.0f);
      nd = make_float4(d.x, d.y, d.z, 0.0f);
      if (kind == 0) {
        np.w = (direct != 0 || b > 1) ? 1.0f : 0.0f;  // stored at a diffuse surface
        float q = fmaxf(c.x, fmaxf(c.y, c.z));
        if (rng_unit(seed, i, b, 0) < q) {
          if (dot(nrm, d) > 0.0f) nrm = mul(nrm, -1.0f);
          V3 nd2 = cosine_dir(nrm, rng_unit(seed, i, b, 1), rng_unit(seed, i, b, 2));
          nw = make_float4(w4.x * c.x / q, w4.y * c.y / q, w4.z * c.z / q, 1.0f);
          no = make_float4(nd2.x, nd2.y, nd2.z, 0.0f);
        }
      } else if (kind == 1 || kind == 2) {
        V3 s = specular(d, nrm, kind, e.x, rng_unit(seed, i, b, 3));
        nw = make_float4(w4.x * c.x, w4.y * c.y, w4.z * c.z, 1.0f);
        no = make_float4(s.x, s.y, s.z, 0.0f);
      }
    }
  }
  pos[cur] = np;
  pw[cur] = nw;
  dir[cur] = nd;
  out[cur] = no;
}

// Eye rays (one per pixel, through the pixel centre), followed through up to
// `depth` specular hits (glass: refraction unless totally reflected, mirror:
// reflection) to the first diffuse hit: the query point of the radiance
// estimate. query[p] = (x, y, z, 1) with the surface normal facing the eye in
// normal[p] and the diffuse albedo in albedo[p], or
// w = 0 where the ray leaves the scene or ends on the light.
extern "C" __global__ void eye_rays(Scene sc, const float *tris, const float4 *mats, const float *cam, int w,
                                    int h, int depth, float4 *query, float4 *normal, float4 *albedo) {
  int i = WL_TID;
  if (i >= w * h) return;
  int px = i % w, py = i / w;
  float sx = (2.0f * (px + 0.5f) / w - 1.0f) * cam[12] * cam[13];
  float sy = (1.0f - 2.0f * (py + 0.5f) / h) * cam[12];
  V3 o = v3(cam[0], cam[1], cam[2]);
  V3 d = normalize(add(v3(cam[3], cam[4], cam[5]), add(mul(v3(cam[6], cam[7], cam[8]), sx),
                                                        mul(v3(cam[9], cam[10], cam[11]), sy))));
  float4 q = make_float4(0.0f, 0.0f, 0.0f, 0.0f), a = q, nq = q;
  for (int k = 0; k <= depth; ++k) {
    Hit hh = intersect(tris, sc.num_tris, o, d, sc.eps);
    if (hh.tri < 0) break;
    V3 x = add(o, mul(d, hh.t));
    int m = __float_as_int(tris[12 * hh.tri + 9]);
    float4 c = mats[2 * m], e = mats[2 * m + 1];
    int kind = (int)c.w;
    if (kind == 0) {
      V3 nrm = tri_normal(tris, hh.tri);
      if (dot(nrm, d) > 0.0f) nrm = mul(nrm, -1.0f);
      q = make_float4(x.x, x.y, x.z, 1.0f);
      nq = make_float4(nrm.x, nrm.y, nrm.z, 0.0f);
      a = make_float4(c.x, c.y, c.z, 0.0f);
      break;
    }
    if (kind == 3) break;
    d = specular(d, tri_normal(tris, hh.tri), kind, e.x, 1.0f);
    o = x;
  }
  query[i] = q;
  normal[i] = nq;
  albedo[i] = a;
}

// Direct illumination (004:L140, L174-176): `samples` shadow rays per pixel
// from its query point (query, normal, albedo as eye_rays writes them) to the
// light. An area light (emissive triangles lights[]) is sampled as emit
// samples it (a uniformly chosen triangle, a uniform point on it); a point
// light is its position. Sample s of pixel i uses the random numbers of pass
// 16 + s. direct[i] = albedo / pi * the mean over the samples of the light's
// contribution: area light, radiance * cos_x * cos_l / d^2 * (lights *
// triangle area) when nothing lies between; point light, intensity * cos_x /
// d^2. Pixels without a query point get 0.
extern "C" __global__ void shadow_rays(Scene sc, const float *tris, const int *lights, const float4 *query,
                                       const float4 *normal, const float4 *albedo, int npix, int samples,
                                       unsigned seed, float4 *direct) {
  int i = WL_TID;
  if (i >= npix) return;
  float4 q4 = query[i];
  V3 acc = v3(0.0f, 0.0f, 0.0f);
  if (q4.w != 0.0f) {
    float4 n4 = normal[i];
    V3 x = v3(q4.x, q4.y, q4.z), n = v3(n4.x, n4.y, n4.z);
    for (int s = 0; s < samples; ++s) {
      unsigned pass = 16u + (unsigned)s;
      V3 l = v3(sc.light[0], sc.light[1], sc.light[2]);
      float weight = 1.0f;  // point light: intensity / d^2
      V3 nl = v3(0.0f, 0.0f, 0.0f);
      if (sc.num_lights > 0) {
        int k = imin((int)(rng_unit(seed, i, pass, 0) * sc.num_lights), sc.num_lights - 1);
        int ti = lights[k];
        const float *t = tris + 12 * ti;
        float a = rng_unit(seed, i, pass, 1), bb = rng_unit(seed, i, pass, 2);
        if (a + bb > 1.0f) { a = 1.0f - a; bb = 1.0f - bb; }
        V3 e1 = v3(t[3], t[4], t[5]), e2 = v3(t[6], t[7], t[8]);
        l = add(v3(t[0], t[1], t[2]), add(mul(e1, a), mul(e2, bb)));
        V3 c = cross(e1, e2);
        float len = sqrtf(dot(c, c));
        nl = mul(c, 1.0f / len);
        weight = 0.5f * len * (float)sc.num_lights;
      }
      V3 to = sub(l, x);
      float d2 = dot(to, to), dist = sqrtf(d2);
      V3 wi = mul(to, 1.0f / dist);
      float cx = dot(n, wi);
      if (cx <= 0.0f) continue;
      float cl = 1.0f;
      if (sc.num_lights > 0) {
        cl = fabsf(dot(nl, wi));
      }
      Hit h = intersect(tris, sc.num_tris, x, wi, sc.eps);
      if (h.tri >= 0 && h.t < dist - sc.eps) continue;  // occluded (the light itself lies at dist)
      float g = cx * cl * weight / d2;
      acc.x += sc.radiance[0] * g;
      acc.y += sc.radiance[1] * g;
      acc.z += sc.radiance[2] * g;
    }
    float4 a4 = albedo[i];
    float f = 1.0f / (3.14159265358979f * (float)samples);
    acc = v3(acc.x * a4.x * f, acc.y * a4.y * f, acc.z * a4.z * f);
  }
  direct[i] = make_float4(acc.x, acc.y, acc.z, 0.0f);
}
