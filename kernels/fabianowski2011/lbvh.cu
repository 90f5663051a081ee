// Thesis 000 §6.1.2–6.1.3: the linear BVH photon map built by kernels with the
// dual "merge" construction (L2581–2619, extract §3.3).
//
// lbvh_codes: one thread per interaction; the 30-bit Morton code of its
// kernel's centre quantised to 10 bits per axis within the centres' bounds.
// (The host sorts the references by code, as the thesis' CUDPP radix sort.)
//
// lbvh_runs: one thread per sorted reference; a reference that starts a run of
// identical codes [j, k] writes S[j] = S[k] = k - j + 1 and AABB[j] = the union
// of the run's AABBs (the thesis' segmented scan).
//
// lbvh_levels: one thread per neighbour pair i, i + 1 with different codes: the
// merge point's level, the number of leading bits the two codes share (0..29).
// (The host sorts the merge points by level, Fig. 6.1(b).)
//
// lbvh_merge: one launch per level, deepest first; one thread per merge point
// i of the level: left [a, i], right [i + 1, b] with a = i - S[i] + 1,
// b = i + S[i + 1]; if S[i] + S[i + 1] > n_auto an inner node is made whose
// children are N[a] and N[i + 1], or leaves over the intervals where those
// are null (L2607, L2611); S[a] = S[b] = S[i] + S[i + 1];
// AABB[a] = AABB[a] u AABB[i + 1]. Merge points of one level have disjoint
// intervals, so the threads do not race.
//
// src/repro/fabianowski2011/lbvh.rs repeats every operation: the nodes agree
// bit for bit. Keep the two in step.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define LEAF_REF 0x80000000u
#define NODE_WORDS 16

struct CodeParams {
  float lo[3], scale[3];
  int count;
};

static __device__ __forceinline__ unsigned expand10(unsigned v) {
  v = (v * 0x00010001u) & 0xFF0000FFu;
  v = (v * 0x00000101u) & 0x0F00F00Fu;
  v = (v * 0x00000011u) & 0xC30C30C3u;
  v = (v * 0x00000005u) & 0x49249249u;
  return v;
}

static __device__ __forceinline__ unsigned quantise(float z, float lo, float scale) {
  float t = (z - lo) * scale;
  int q = t > 0.0f ? (int)t : 0;
  return q > 1023 ? 1023u : (unsigned)q;
}

// centres: 3 floats a kernel; codes: one word a kernel
extern "C" __global__ void lbvh_codes(const CodeParams *p, const float *centres, unsigned *codes) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    const float *z = centres + 3 * i;
    unsigned x = quantise(z[0], p->lo[0], p->scale[0]);
    unsigned y = quantise(z[1], p->lo[1], p->scale[1]);
    unsigned w = quantise(z[2], p->lo[2], p->scale[2]);
    codes[i] = (expand10(x) << 2) | (expand10(y) << 1) | expand10(w);
  }
}

struct Params {
  int count;
  int n_auto;
  int merges;
  int first_node;
};

static __device__ __forceinline__ float lower(float a, float b) { return b < a ? b : a; }
static __device__ __forceinline__ float upper(float a, float b) { return b > a ? b : a; }

// codes: sorted; boxes: 6 floats (lo, hi) per sorted reference; size, box: the S and AABB arrays
extern "C" __global__ void lbvh_runs(const Params *p, const unsigned *codes, const float *boxes, unsigned *size,
                                     float *box) {
  unsigned n = (unsigned)p->count;
  for (unsigned i = WL_TID; i < n; i += blockDim.x * gridDim.x) {
    unsigned c = codes[i];
    if (i > 0 && codes[i - 1] == c) continue;
    float b[6];
    for (int k = 0; k < 6; k++) b[k] = boxes[6 * i + k];
    unsigned k = i;
    while (k + 1 < n && codes[k + 1] == c) {
      k++;
      for (int a = 0; a < 3; a++) {
        b[a] = lower(b[a], boxes[6 * k + a]);
        b[a + 3] = upper(b[a + 3], boxes[6 * k + a + 3]);
      }
    }
    size[i] = k - i + 1;
    size[k] = k - i + 1;
    for (int a = 0; a < 6; a++) box[6 * i + a] = b[a];
  }
}

// level[i] for i < n - 1: the codes' common leading bits (0..29), or 0xffffffff when equal
extern "C" __global__ void lbvh_levels(const Params *p, const unsigned *codes, unsigned *level) {
  unsigned n = (unsigned)p->count;
  for (unsigned i = WL_TID; i + 1 < n; i += blockDim.x * gridDim.x) {
    unsigned x = codes[i] ^ codes[i + 1];
    level[i] = x == 0 ? 0xffffffffu : (unsigned)__clz((int)x) - 2u;
  }
}

// points: the merge points of this level; node: 16 words per merge point
// [left ref, left count, right ref, right count, left lo, left hi, right lo, right hi];
// ref: an inner node's index, or LEAF_REF | first reference (count: the leaf's size)
extern "C" __global__ void lbvh_merge(const Params *p, const unsigned *points, unsigned *size, float *box,
                                      unsigned *node_of, unsigned *nodes) {
  for (unsigned t = WL_TID; t < (unsigned)p->merges; t += blockDim.x * gridDim.x) {
    unsigned i = points[t];
    unsigned sl = size[i], sr = size[i + 1];
    unsigned a = i - sl + 1, b = i + sr;
    if (sl + sr > (unsigned)p->n_auto) {
      unsigned id = (unsigned)p->first_node + t;
      unsigned nl = node_of[a], nr = node_of[i + 1];
      unsigned *o = nodes + NODE_WORDS * id;
      o[0] = nl != 0 ? nl - 1 : (LEAF_REF | a);
      o[1] = nl != 0 ? 0 : sl;
      o[2] = nr != 0 ? nr - 1 : (LEAF_REF | (i + 1));
      o[3] = nr != 0 ? 0 : sr;
      for (int k = 0; k < 6; k++) {
        o[4 + k] = __float_as_uint(box[6 * a + k]);
        o[10 + k] = __float_as_uint(box[6 * (i + 1) + k]);
      }
      node_of[a] = id + 1;
    }
    size[a] = sl + sr;
    size[b] = sl + sr;
    for (int k = 0; k < 3; k++) {
      box[6 * a + k] = lower(box[6 * a + k], box[6 * (i + 1) + k]);
      box[6 * a + k + 3] = upper(box[6 * a + k + 3], box[6 * (i + 1) + k + 3]);
    }
  }
}
