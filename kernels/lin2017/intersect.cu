// Thesis 003 (Lin 2017), §6.4 (003:L538-546): the affine test "reduces the
// 26 multiplications, 23 additions/subtractions required in the standard
// ray-triangle intersection algorithm to 20 multiplications and 13
// additions/subtractions". Both routines, one thread per (ray, triangle)
// pair, so that the emulator can count the floating-point instructions each
// executes (src/repro/lin2017/sec_6_4.rs, table lin:s6.4):
//
//   tri_standard  Moller & Trumbore (1997), the standard test the thesis
//                 does not name (our reading): edges from the three vertices,
//                 the determinant's reciprocal, u, v and t scaled by it
//   tri_affine    §6.4's test, the same expressions in the same order as
//                 affine() in kernels/lin2017/path.cu (a test holds the two
//                 compiled to the same floating-point instructions)
//
// rays: per pair [o, t_min], [d, t_max]. Triangles: tri_standard reads three
// float4 vertices (w unused), tri_affine the three affine rows of
// src/host/path/layout.rs. out[i]: the hit distance, or -1 on a miss.
// The contraction setting is path.cu's (off): clang's PTX counts every
// multiplication and addition on its own; nvcc's contracts pairs to fma.
#include "../prelude.h"

#pragma clang fp contract(off)

// Moller-Trumbore; true and *t on a hit in [t_min, t_max].
static __device__ __forceinline__ bool standard(float4 a, float4 b, float4 c, float4 o, float4 d, float *t) {
  float e1x = b.x - a.x, e1y = b.y - a.y, e1z = b.z - a.z;
  float e2x = c.x - a.x, e2y = c.y - a.y, e2z = c.z - a.z;
  float px = d.y * e2z - d.z * e2y, py = d.z * e2x - d.x * e2z, pz = d.x * e2y - d.y * e2x;
  float det = e1x * px + e1y * py + e1z * pz;
  if (det == 0.0f) return false;
  float inv = 1.0f / det;
  float sx = o.x - a.x, sy = o.y - a.y, sz = o.z - a.z;
  float u = (sx * px + sy * py + sz * pz) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  float qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
  float v = (d.x * qx + d.y * qy + d.z * qz) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  float tt = (e2x * qx + e2y * qy + e2z * qz) * inv;
  if (!(tt >= o.w && tt <= d.w)) return false;
  *t = tt;
  return true;
}

// §6.4's affine test over the rows m[0..3]; true and *t on a hit in [t_min, t_max].
static __device__ __forceinline__ bool affine(const float4 *m, float4 o, float4 d, float *t) {
  float4 r2 = m[2];
  float oz = r2.x * o.x + r2.y * o.y + r2.z * o.z + r2.w;
  float dz = r2.x * d.x + r2.y * d.y + r2.z * d.z;
  float tt = -oz / dz;
  if (!(tt >= o.w && tt <= d.w)) return false;
  float4 r0 = m[0];
  float u = r0.x * o.x + r0.y * o.y + r0.z * o.z + r0.w + tt * (r0.x * d.x + r0.y * d.y + r0.z * d.z);
  if (u < 0.0f) return false;
  float4 r1 = m[1];
  float v = r1.x * o.x + r1.y * o.y + r1.z * o.z + r1.w + tt * (r1.x * d.x + r1.y * d.y + r1.z * d.z);
  if (v < 0.0f || u + v > 1.0f) return false;
  *t = tt;
  return true;
}

extern "C" __global__ void tri_standard(const float4 *rays, const float4 *verts, unsigned n, float *out) {
  unsigned i = WL_TID;
  if (i >= n) return;
  float t = -1.0f;
  if (!standard(verts[3 * i], verts[3 * i + 1], verts[3 * i + 2], rays[2 * i], rays[2 * i + 1], &t)) t = -1.0f;
  out[i] = t;
}

extern "C" __global__ void tri_affine(const float4 *rays, const float4 *rows, unsigned n, float *out) {
  unsigned i = WL_TID;
  if (i >= n) return;
  float t = -1.0f;
  if (!affine(rows + 3 * i, rays[2 * i], rays[2 * i + 1], &t)) t = -1.0f;
  out[i] = t;
}
