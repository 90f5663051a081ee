// Thesis 000 §5.2.3: the k-th nearest neighbour density estimate, the
// baseline of VKDE, one thread per query point.
//
// The photon map is a left-balanced kd-tree in heap order, one interaction
// per node (§3.4.3.1, [Jen95]). The k nearest interactions facing the query's
// side are kept in a max-heap on distance^2 in local memory (the priority
// queue that, the thesis says, makes kNN expensive in CUDA, L2171); the radius
// starts at h_max and shrinks to the k-th distance once k are found (L1399).
// h = |x - x_k| (or h_max with fewer than k); L = (rho / pi) sum K(d / h) flux / h^2.
//
// src/repro/fabianowski2011/knn.rs repeats every float operation in the same
// order: estimates agree bit for bit. Keep the two in step.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define NODE 12
#define QUERY 12
#define ESTIMATE 8
#define STACK 64
#define K_MAX 512

struct Params {
  int count, shape, nodes, k;
  float h_max;
};

static __device__ __forceinline__ float node_f(const float *nodes, unsigned i, int c) { return __ldg(nodes + i * NODE + c); }

extern "C" __global__ void estimate_knn(const Params *p, const float *nodes, const float *queries, float *out) {
  float hd[K_MAX];
  unsigned hi[K_MAX];
  unsigned st_node[STACK];
  float st_plane[STACK];
  unsigned n = (unsigned)p->nodes, k = (unsigned)p->k;
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    const float *q = queries + i * QUERY;
    float *o = out + i * ESTIMATE;
    if (__ldg(q + 3) != 1.0f || n == 0) continue;
    float x[3] = {__ldg(q), __ldg(q + 1), __ldg(q + 2)};
    float nx = __ldg(q + 4), ny = __ldg(q + 5), nz = __ldg(q + 6);
    float hmax2 = p->h_max * p->h_max;
    float r2 = hmax2;
    unsigned count = 0, visited = 0, retrieved = 0;
    int size = 1;
    st_node[0] = 0;
    st_plane[0] = 0.0f;
    while (size > 0) {
      size--;
      unsigned j = st_node[size];
      if (!(st_plane[size] < r2)) continue;
      for (;;) {
        const float *pn = nodes + j * NODE;
        visited++;
        float px = __ldg(pn), py = __ldg(pn + 1), pz = __ldg(pn + 2);
        float dx = x[0] - px, dy = x[1] - py, dz = x[2] - pz;
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < r2 && __ldg(pn + 8) * nx + __ldg(pn + 9) * ny + __ldg(pn + 10) * nz > 0.0f) {
          retrieved++;
          if (count < k) {
            // push and sift up
            unsigned c = count;
            hd[c] = d2;
            hi[c] = j;
            while (c > 0) {
              unsigned par = (c - 1) / 2;
              if (!(hd[c] > hd[par])) break;
              float td = hd[c]; hd[c] = hd[par]; hd[par] = td;
              unsigned ti = hi[c]; hi[c] = hi[par]; hi[par] = ti;
              c = par;
            }
            count++;
            if (count == k) r2 = hd[0];
          } else {
            // replace the farthest and sift down
            hd[0] = d2;
            hi[0] = j;
            unsigned c = 0;
            for (;;) {
              unsigned l = 2 * c + 1;
              if (l >= k) break;
              unsigned r = l + 1;
              unsigned m = (r < k && hd[r] > hd[l]) ? r : l;
              if (!(hd[m] > hd[c])) break;
              float td = hd[c]; hd[c] = hd[m]; hd[m] = td;
              unsigned ti = hi[c]; hi[c] = hi[m]; hi[m] = ti;
              c = m;
            }
            r2 = hd[0];
          }
        }
        unsigned left = 2 * j + 1;
        if (left >= n) break;
        int axis = (int)__float_as_uint(__ldg(pn + 3));
        float dd = x[axis] - (axis == 0 ? px : (axis == 1 ? py : pz));
        unsigned near = dd < 0.0f ? left : left + 1, far = dd < 0.0f ? left + 1 : left;
        if (far < n) {
          st_node[size] = far;
          st_plane[size] = dd * dd;
          size++;
        }
        if (near >= n) break;
        j = near;
      }
    }
    float h2 = count == k ? hd[0] : hmax2;
    o[4] = __uint_as_float(visited);
    o[5] = __uint_as_float(retrieved);
    if (!(h2 > 0.0f)) continue;
    float sr = 0.0f, sg = 0.0f, sb = 0.0f;
    for (unsigned c = 0; c < count; c++) {
      float w = p->shape == 0 ? 0.318309886183790672f : (1.0f - hd[c] / h2) * 0.636619772367581343f;
      const float *pn = nodes + hi[c] * NODE;
      sr = sr + w * __ldg(pn + 4);
      sg = sg + w * __ldg(pn + 5);
      sb = sb + w * __ldg(pn + 6);
    }
    const float inv_pi = 0.318309886183790672f;
    o[0] = __ldg(q + 8) * inv_pi * (sr / h2);
    o[1] = __ldg(q + 9) * inv_pi * (sg / h2);
    o[2] = __ldg(q + 10) * inv_pi * (sb / h2);
    o[3] = __uint_as_float(count);
  }
}
