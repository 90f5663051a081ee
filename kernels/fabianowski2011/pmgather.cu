// Thesis 000 §6.2: VKDE through a BVH photon map in the complete (B) and the
// compact (C) representation (L2712–2798, extract §3.6–3.8).
//
// Both kernels: one thread per query point; the root's AABB (a kernel
// parameter) is tested first, then the traversal starts at the root's two
// children, so that n_T counts the same nodes in both: every child of an inner
// node that contains x. Nodes and pairs come through the read-only path
// (__ldg), 32 bytes each, loaded whole before any test; the kernels (16 floats:
// z, M, m', flux', n, end flag) through plain global loads; the stack (4-byte
// entries) lives in local memory.
//
// gather_complete (B): 32-byte nodes lo[3], hi[3], a, b (inner: children a, b
// adjacent; leaf: first a, count b & ~LEAF_BIT); Alg. 3.5's strict point test
// per node; inside an inner node: push the left child, continue with the right.
//
// gather_compact (C): 32-byte sibling pairs m[3], M[3] (the pair's new planes),
// w0, w1 (bits 0-27 the left/right child: a pair index or a first kernel;
// bit 28 leaf; bits 29-31 the masks l and L, x in bit 31); Alg. 6.2's bitmask
// test: miss = 6 plane tests, left = (l << 3) | L; a leaf is read until the
// kernel whose end flag is set; both children inner and inside: push the left
// child's pair, continue with the right's (L2792).
//
// Counts come from the emulator: a line ending in `@count NAME OPCODE`
// executes one OPCODE per event (src/repro/fabianowski2011/pm_layout.rs sums
// the lanes). src/repro/fabianowski2011/pm_layout.rs repeats both traversals
// and every float operation in the same order; the radiance agrees bit for bit.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define KERNEL 16
#define QUERY 12
#define ESTIMATE 4
#define STACK 64
#define LEAF_BIT 0x80000000u
#define REF_MASK 0x0fffffffu
#define REF_LEAF 0x10000000u
// a read-only load written on the line that uses it (the prelude's __ldg is an
// inline function, whose instruction `.loc` would place on the prelude's line)
#if defined(__NVCC__)
#define LDG(p) __ldg(p)
#else
#define LDG(p) __nvvm_ldg_f(p)
#endif

struct V3 { float x, y, z; };
static __device__ __forceinline__ V3 v3(float x, float y, float z) { V3 r = {x, y, z}; return r; }
static __device__ __forceinline__ float dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static __device__ __forceinline__ V3 sub3(V3 a, V3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static __device__ __forceinline__ V3 ld3(const float *p) { return v3(p[0], p[1], p[2]); }

struct GatherParams {
  float lo[3], hi[3];
  int count, shape;
};

// one kernel of a leaf: the back-face test, |d|^2 < 1, the weight
static __device__ __forceinline__ V3 evaluate(const float *k, V3 x, V3 nx, int shape, V3 sum) {
  float n0 = k[12];                    // @count retrieved ld.global.f32
  float n1 = k[13], n2 = k[14];
  if (!(dot3(v3(n0, n1, n2), nx) > 0.0f)) return sum;
  V3 z = ld3(k), major = ld3(k + 3), mp = ld3(k + 6);
  V3 d = sub3(x, z);
  float qq = dot3(mp, d) / dot3(mp, major);
  V3 r = v3(major.x * qq - d.x, major.y * qq - d.y, major.z * qq - d.z);
  float dd = qq * qq + dot3(r, r) / dot3(mp, mp);
  if (!(dd < 1.0f)) return sum;
  float w = shape == 0 ? 0.318309886183790672f : (1.0f - dd) * 0.636619772367581343f;
  float f0 = k[9];                     // @count contributed ld.global.f32
  V3 f = v3(f0, k[10], k[11]);
  return v3(sum.x + w * f.x, sum.y + w * f.y, sum.z + w * f.z);
}

static __device__ __forceinline__ bool in_root(const GatherParams *p, V3 x) {
  return p->lo[0] < x.x && p->lo[1] < x.y && p->lo[2] < x.z && p->hi[0] > x.x && p->hi[1] > x.y && p->hi[2] > x.z;
}

static __device__ __forceinline__ void finish(float *o, V3 rho, V3 sum) {
  const float inv_pi = 0.318309886183790672f;
  o[0] = rho.x * inv_pi * sum.x;
  o[1] = rho.y * inv_pi * sum.y;
  o[2] = rho.z * inv_pi * sum.z;
}

extern "C" __global__ void gather_complete(const GatherParams *p, const float *nodes, const float *kernels,
                                           const float *queries, float *out) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    const float *q = queries + i * QUERY;
    if (q[3] != 1.0f) continue;
    V3 x = ld3(q), nx = ld3(q + 4), rho = ld3(q + 8);
    V3 sum = v3(0.0f, 0.0f, 0.0f);
    if (in_root(p, x)) {
      unsigned stack[STACK];
      stack[0] = 1;                    // @count push st.local.u32
      int size = 1;
      unsigned node = 2;
      for (;;) {
        const float *nd = nodes + 8 * node;
        float lx = LDG(nd);            // @count nodes ld.global.nc.f32
        float ly = LDG(nd + 1), lz = LDG(nd + 2), hx = LDG(nd + 3), hy = LDG(nd + 4), hz = LDG(nd + 5);
        unsigned a = __float_as_uint(LDG(nd + 6)), b = __float_as_uint(LDG(nd + 7));
        asm volatile("" ::"f"(lx), "f"(ly), "f"(lz), "f"(hx), "f"(hy), "f"(hz), "r"(a), "r"(b));
        // Alg. 3.5
        if (lx < x.x && ly < x.y && lz < x.z && hx > x.x && hy > x.y && hz > x.z) {
          if ((b & LEAF_BIT) == 0) {
            stack[size] = a;           // @count push st.local.f32
            size++;
            node = b;
            continue;
          }
          unsigned end = a + (b & ~LEAF_BIT);
          for (unsigned j = a; j < end; j++) sum = evaluate(kernels + KERNEL * j, x, nx, p->shape, sum);
        }
        if (size == 0) break;
        size--;
        node = stack[size];            // @count pop ld.local.u32
      }
    }
    finish(out + i * ESTIMATE, rho, sum);
  }
}

// a leaf of the compact layout: from `first` until the kernel with the end flag
static __device__ __forceinline__ V3 leaf(const float *kernels, unsigned first, V3 x, V3 nx, int shape, V3 sum) {
  for (unsigned j = first;; j++) {
    const float *k = kernels + KERNEL * j;
    sum = evaluate(k, x, nx, shape, sum);
    if (k[15] != 0.0f) return sum;
  }
}

extern "C" __global__ void gather_compact(const GatherParams *p, const float *pairs, const float *kernels,
                                          const float *queries, float *out) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    const float *q = queries + i * QUERY;
    if (q[3] != 1.0f) continue;
    V3 x = ld3(q), nx = ld3(q + 4), rho = ld3(q + 8);
    V3 sum = v3(0.0f, 0.0f, 0.0f);
    if (in_root(p, x)) {
      unsigned stack[STACK];
      int size = 0;
      unsigned pair = 0;
      for (;;) {
        const float *pr = pairs + 8 * pair;
        float mx = LDG(pr);            // @count pairs ld.global.nc.f32
        float my = LDG(pr + 1), mz = LDG(pr + 2), Mx = LDG(pr + 3), My = LDG(pr + 4), Mz = LDG(pr + 5);
        unsigned w0 = __float_as_uint(LDG(pr + 6)), w1 = __float_as_uint(LDG(pr + 7));
        asm volatile("" ::"f"(mx), "f"(my), "f"(mz), "f"(Mx), "f"(My), "f"(Mz), "r"(w0), "r"(w1));
        // Alg. 6.2 (a point on a plane misses, as in Alg. 3.5)
        unsigned miss = ((unsigned)(mx >= x.x) << 5) | ((unsigned)(my >= x.y) << 4) | ((unsigned)(mz >= x.z) << 3) |
                        ((unsigned)(Mx <= x.x) << 2) | ((unsigned)(My <= x.y) << 1) | (unsigned)(Mz <= x.z);
        unsigned left = ((w0 >> 29) << 3) | (w1 >> 29);
        bool in_l = (left & miss) == 0, in_r = (~left & miss) == 0;
        unsigned next = 0xffffffffu;
        if (in_l) {
          if (w0 & REF_LEAF) sum = leaf(kernels, w0 & REF_MASK, x, nx, p->shape, sum);
          else next = w0 & REF_MASK;
        }
        if (in_r) {
          if (w1 & REF_LEAF) sum = leaf(kernels, w1 & REF_MASK, x, nx, p->shape, sum);
          else if (next != 0xffffffffu) {
            stack[size] = next;        // @count push st.local.u32
            size++;
            next = w1 & REF_MASK;
          } else next = w1 & REF_MASK;
        }
        if (next != 0xffffffffu) {
          pair = next;
          continue;
        }
        if (size == 0) break;
        size--;
        pair = stack[size];            // @count pop ld.local.u32
      }
    }
    finish(out + i * ESTIMATE, rho, sum);
  }
}
