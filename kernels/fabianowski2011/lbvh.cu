// Thesis 000 §6.1.2–6.1.3: the linear BVH photon map built by kernels with the
// dual "merge" construction (L2581–2619, extract §3.3).
//
// lbvh_codes: one thread per interaction; the 30-bit Morton code of its
// kernel's centre quantised to 10 bits per axis within the centres' bounds.
// The references are then radix-sorted by code (radix_*, below; L2589) and
// lbvh_gather puts their AABBs in the sorted order.
//
// lbvh_runs: one thread per sorted reference; a reference that starts a run of
// identical codes [j, k] writes S[j] = S[k] = k - j + 1 and AABB[j] = the union
// of the run's AABBs (the thesis' segmented scan).
//
// lbvh_levels: one thread per neighbour pair i, i + 1 with different codes: the
// merge point's level, the number of leading bits the two codes share (0..29).
// lbvh_level_keys makes each merge point's sort key, 29 - level (deepest
// first), 31 where the codes are equal; the merge points are radix-sorted by
// it (Fig. 6.1(b)), so the points of one level are contiguous, ascending.
//
// lbvh_merge: one launch per level, deepest first; one thread per merge point
// i of the level (points[first_node + t]: the sorted merge points, deeper
// levels first, so a point's place in them is its node id): left [a, i], right [i + 1, b] with a = i - S[i] + 1,
// b = i + S[i + 1]; if S[i] + S[i + 1] > n_auto an inner node is made whose
// children are N[a] and N[i + 1], or leaves over the intervals where those
// are null (L2607, L2611); S[a] = S[b] = S[i] + S[i + 1];
// AABB[a] = AABB[a] u AABB[i + 1]. Merge points of one level have disjoint
// intervals, so the threads do not race.
//
// radix_count, radix_scan, radix_scatter: a stable LSD radix sort of 32-bit
// keys with 32-bit values, 4 bits a pass (the host launches the three per
// pass, ping-ponging two buffers). Tiles of SORT_THREADS elements; a tile's
// per-digit counts come from warp ballots (no atomics, so the order is
// deterministic and stable): radix_count writes counts[d * tiles + t],
// radix_scan (one CTA) scans them exclusively in place, radix_scatter puts
// each element at its digit-and-tile offset plus its rank among the tile's
// equal digits before it.
//
// src/repro/fabianowski2011/lbvh.rs repeats every operation: the nodes agree
// bit for bit. Keep the two in step.
#include "../prelude.h"
#include "cta_scan.h"

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
    unsigned i = points[(unsigned)p->first_node + t];
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

// sorted boxes: boxes[i] = kernel_boxes[order[i]] (6 floats, lo then hi)
extern "C" __global__ void lbvh_gather(const Params *p, const unsigned *order, const float *kernel_boxes,
                                       float *boxes) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    unsigned j = order[i];
    for (int k = 0; k < 6; k++) boxes[6 * i + k] = kernel_boxes[6 * j + k];
  }
}

// the merge points' sort keys: 29 - level (the deepest level first), 31 for equal codes (last)
extern "C" __global__ void lbvh_level_keys(const Params *p, const unsigned *level, unsigned *keys) {
  for (unsigned i = WL_TID; i + 1 < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    unsigned l = level[i];
    keys[i] = l == 0xffffffffu ? 31u : 29u - l;
  }
}

#define SORT_THREADS 256
#define SORT_WARPS (SORT_THREADS / 32)
#define RADIX_BITS 4
#define RADIX (1u << RADIX_BITS)

struct SortParams {
  int count;  // elements
  int tiles;  // ceil(count / SORT_THREADS)
  int shift;  // the pass' digit: bits shift .. shift + RADIX_BITS - 1
  int iota;   // 1: the values are the indices 0..count-1 (values_in unused)
};

// The digit of element i of the tile, RADIX when past the end.
static __device__ __forceinline__ unsigned digit_of(const SortParams *p, const unsigned *keys, unsigned i) {
  return i < (unsigned)p->count ? (keys[i] >> p->shift) & (RADIX - 1u) : RADIX;
}

// Within the warp: the rank of this lane's digit d among the lower lanes of
// the same digit; the lowest lane of each digit writes the warp's count of it
// to wc[warp * RADIX + d]. All 32 lanes take part.
static __device__ __forceinline__ unsigned warp_rank(unsigned d, unsigned *wc) {
  unsigned lane = threadIdx.x & 31u;
  unsigned same = __ballot_sync(0xffffffffu, d < RADIX);
  for (unsigned b = 0; b < RADIX_BITS; b++) {
    unsigned bit = (d >> b) & 1u;
    unsigned set = __ballot_sync(0xffffffffu, bit);
    same &= bit ? set : ~set;
  }
  unsigned below = same & ((1u << lane) - 1u);
  if (d < RADIX && below == 0u) wc[(threadIdx.x >> 5) * RADIX + d] = __popc(same);
  return __popc(below);
}

// counts[d * tiles + t]: the elements of tile t whose digit is d
extern "C" __global__ void radix_count(const SortParams *p, const unsigned *keys, unsigned *counts) {
  __shared__ unsigned wc[SORT_WARPS * RADIX];
  unsigned tiles = (unsigned)p->tiles;
  for (unsigned t = blockIdx.x; t < tiles; t += gridDim.x) {
    if (threadIdx.x < SORT_WARPS * RADIX) wc[threadIdx.x] = 0u;
    __syncthreads();
    warp_rank(digit_of(p, keys, t * SORT_THREADS + threadIdx.x), wc);
    __syncthreads();
    if (threadIdx.x < RADIX) {
      unsigned c = 0;
      for (unsigned w = 0; w < SORT_WARPS; w++) c += wc[w * RADIX + threadIdx.x];
      counts[threadIdx.x * tiles + t] = c;
    }
    __syncthreads();
  }
}

// one CTA: the exclusive scan of counts[0 .. RADIX * tiles), in place
extern "C" __global__ void radix_scan(const SortParams *p, unsigned *counts) {
  __shared__ unsigned buf[SORT_THREADS];
  unsigned m = RADIX * (unsigned)p->tiles, t = threadIdx.x, carry = 0;
  for (unsigned base = 0; base < m; base += SORT_THREADS) {
    unsigned v = base + t < m ? counts[base + t] : 0u;
    unsigned total;
    unsigned ex = cta_scan<SORT_THREADS>(buf, v, &total);
    if (base + t < m) counts[base + t] = carry + ex;
    carry += total;
  }
}

// every element to offsets[d * tiles + t] + its rank among the tile's equal digits
extern "C" __global__ void radix_scatter(const SortParams *p, const unsigned *offsets, const unsigned *keys,
                                         const unsigned *values, unsigned *keys_out, unsigned *values_out) {
  __shared__ unsigned wc[SORT_WARPS * RADIX];
  unsigned tiles = (unsigned)p->tiles;
  for (unsigned t = blockIdx.x; t < tiles; t += gridDim.x) {
    if (threadIdx.x < SORT_WARPS * RADIX) wc[threadIdx.x] = 0u;
    __syncthreads();
    unsigned i = t * SORT_THREADS + threadIdx.x;
    unsigned d = digit_of(p, keys, i);
    unsigned r = warp_rank(d, wc);
    __syncthreads();
    if (d < RADIX) {
      for (unsigned w = 0; w < (threadIdx.x >> 5); w++) r += wc[w * RADIX + d];
      unsigned dst = offsets[d * tiles + t] + r;
      keys_out[dst] = keys[i];
      values_out[dst] = p->iota ? i : values[i];
    }
    __syncthreads();
  }
}
