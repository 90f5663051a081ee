// Lesson 6: stackless kd-tree traversal (kd-restart) of a fan of 2D rays.
//
// A ray walks down the tree to the leaf holding its current start point,
// tests that leaf's segments, and if it hits nothing there moves its start
// past the leaf and restarts from the root: no stack, at the price of
// descending again. Rays of one warp need different numbers of restarts, so
// the warp diverges in the outer loop and the SIMT stack holds the finished
// rays until the last one is done.
//
// Tree layout (int4 per node): x = axis (0, 1) or 2 for a leaf; inner nodes:
// y = left child (below the split), z = right child, split[node] = plane;
// leaves: y = first index into items, z = item count. Segments: float4
// (x0, y0, x1, y1).
#include "../prelude.h"

struct Ray { float ox, oy, dx, dy; };

// Nearest hit of the ray with segment s for t in [tlo, thi]; returns t or -1.
static __device__ __forceinline__ float hit_segment(Ray r, float4 s, float tlo, float thi) {
  float ex = s.z - s.x, ey = s.w - s.y;
  float den = r.dx * ey - r.dy * ex;
  if (den == 0.0f) return -1.0f;                            // parallel
  float qx = s.x - r.ox, qy = s.y - r.oy;
  float t = (qx * ey - qy * ex) / den;                      // along the ray
  float u = (qx * r.dy - qy * r.dx) / den;                  // along the segment
  return (u >= 0.0f && u <= 1.0f && t >= tlo && t <= thi) ? t : -1.0f;
}

extern "C" __global__ void stackless(const int4 *nodes, const float *split, const int *items, const float4 *segs,
                                     const Ray *rays, int *hit, float *thit, int *restarts, float tmax) {
  int i = WL_TID;
  Ray r = rays[i];
  float inv[2] = {1.0f / r.dx, 1.0f / r.dy};
  float o[2] = {r.ox, r.oy};
  float tmin = 0.0f;
  int best = -1, leaves = 0;
  float tbest = tmax;
  while (tmin < tmax) {                                     // one pass per leaf: restart from the root
    int node = 0;
    float tlo = tmin, thi = tmax;
    int4 n = nodes[node];
    while (n.x != 2) {                                      // descend to the leaf containing the ray at tlo
      float ts = (split[node] - o[n.x]) * inv[n.x];
      int near = o[n.x] < split[node] ? n.y : n.z;
      int far = o[n.x] < split[node] ? n.z : n.y;
      if (ts < 0.0f || ts >= thi) node = near;              // the ray meets the plane behind it or beyond thi
      else if (ts <= tlo) node = far;                       // it crossed the plane before tlo
      else { node = near; thi = ts; }                       // the plane splits [tlo, thi]: keep the near part
      n = nodes[node];
    }
    leaves++;
    for (int k = 0; k < n.z; k++) {                         // the leaf's segments
      int s = items[n.y + k];
      float t = hit_segment(r, segs[s], tlo, thi);
      if (t >= 0.0f && t < tbest) { tbest = t; best = s; }
    }
    if (best >= 0) break;                                   // a hit inside this leaf is the nearest
    tmin = thi;                                             // restart past this leaf
  }
  hit[i] = best;
  thit[i] = best >= 0 ? tbest : -1.0f;
  restarts[i] = leaves - 1;
}
