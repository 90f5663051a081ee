// Thesis 000 §6.2.2 and Table 6.5: ray traversal of a BVH over the scene's
// triangles in the complete representation of [AL09] (B) and the compact one
// (C) with Algorithm 6.1 (L2724–2765, L2800, L2819–2825; extract §3.6, §3.7,
// §3.13).
//
// Both kernels: one thread per ray (origin, direction, [t_min, t_max], any-hit
// flag: shadow rays stop at the first hit); the ray is first clipped to the
// root's AABB (a kernel parameter), then the traversal starts at the pair of
// the root's children. A pair is loaded whole through the read-only path
// (__ldg) before any test; a hit leaf child is intersected at once (Wald's
// test, Alg. 3.3, on 12-word triangle records read with plain global loads,
// the leaf ending at the record whose end flag is set); when both children
// are inner and hit, the nearer one (by entry distance, the left on a tie) is
// visited and the other pushed onto a stack in local memory.
//
// trace_complete (B, [AL09]): 56-byte pairs lo[3] hi[3] of the left child, lo[3]
// hi[3] of the right, two words (bit 31 leaf; else the child's pair, if leaf
// its first triangle). Each child is slab-tested against the ray's [t_min,
// t_hit]; the stack holds the pair alone (4 bytes, Table 6.5 (b): "only node
// pairs are pushed onto the stack for it", no t_a > t_max check).
//
// trace_complete_ta (B of Table 6.5 (a), the older code base's baseline): as
// trace_complete, but a closest-hit ray pushes the far pair with its entry
// distance t_a (8 bytes) and skips a popped entry when t_a > t_max; a shadow
// ray pushes the pair alone (4 bytes), as in (a)'s "8 B (node + t_a) for
// primary rays, 4 B for shadow rays".
//
// trace_compact (C): 32-byte pairs m[3] M[3] w0 w1 as the photon map's
// (src/repro/fabianowski2011/pm_layout.rs: bits 0-27 the child, bit 28 leaf,
// bits 29-31 the masks l (w0) and L (w1), x highest); Algorithm 6.1 verbatim,
// the parent's interval [t_a, t_b] inherited, t_3 = ∞·ω_k⁻¹ for the planes a
// node inherits; the stack holds the pair and its interval (12 bytes), and a
// popped entry is skipped when t_a > t_max (L2765).
//
// Counts come from the emulator: a line ending in `@count NAME OPCODE`
// executes one OPCODE per event (src/repro/fabianowski2011/scene_bvh.rs sums
// the lanes). scene_bvh.rs repeats both traversals and every float operation
// in the same order; the hits agree bit for bit.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define RAY 12
#define HIT 4
#define TRI 12
#define STACK 64
#define LEAF_BIT 0x80000000u
#define REF_MASK 0x0fffffffu
#define REF_LEAF 0x10000000u
#define NONE 0xffffffffu
#if defined(__NVCC__)
#define LDG(p) __ldg(p)
#else
#define LDG(p) __nvvm_ldg_f(p)
#endif

struct TraceParams {
  float lo[3], hi[3];
  int count;
};

struct Ray {
  float o[3], d[3], inv[3];
  float tmin;
  int any;
};

struct Best {
  float t, u, v;
  unsigned tri;
};

static __device__ __forceinline__ float pick(float x, float y, float z, unsigned k) {
  return k == 0 ? x : (k == 1 ? y : z);
}

// Alg. 3.3 on the triangles of a leaf from `first` until the end flag; true
// when an any-hit ray has found its hit
static __device__ __forceinline__ bool leaf(const float *tris, unsigned first, const Ray &r, Best &best) {
  for (unsigned j = first;; j++) {
    const float *w = tris + TRI * j;
    unsigned k = __float_as_uint(w[0]); // @count tested ld.global.u32
    unsigned a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
    float ok = pick(r.o[0], r.o[1], r.o[2], k), oa = pick(r.o[0], r.o[1], r.o[2], a), ob = pick(r.o[0], r.o[1], r.o[2], b);
    float dk = pick(r.d[0], r.d[1], r.d[2], k), da = pick(r.d[0], r.d[1], r.d[2], a), db = pick(r.d[0], r.d[1], r.d[2], b);
    float t = (w[3] - ok - w[1] * oa - w[2] * ob) / (dk + w[1] * da + w[2] * db);
    if (t >= r.tmin && t <= best.t) {
      float hx = oa + t * da, hy = ob + t * db;
      float u = w[7] * hx + w[8] * hy + w[9];
      float v = w[4] * hx + w[5] * hy + w[6];
      if (!(u < 0.0f || v < 0.0f || u + v > 1.0f)) {
        best.t = t;
        best.u = u;
        best.v = v;
        best.tri = __float_as_uint(w[10]);
        if (r.any) return true;
      }
    }
    if (w[11] != 0.0f) return false;
  }
}

static __device__ __forceinline__ Ray load_ray(const float *q) {
  Ray r;
  for (int c = 0; c < 3; c++) {
    r.o[c] = q[c];
    r.d[c] = q[3 + c];
    r.inv[c] = 1.0f / r.d[c];
  }
  r.tmin = q[6];
  r.any = q[8] != 0.0f;
  return r;
}

// the slab test of one box against [ta, tb]
static __device__ __forceinline__ bool slab(float lx, float ly, float lz, float hx, float hy, float hz, const Ray &r,
                                            float &ta, float &tb) {
  float lo[3] = {lx, ly, lz}, hi[3] = {hx, hy, hz};
  for (int c = 0; c < 3; c++) {
    float t1 = (lo[c] - r.o[c]) * r.inv[c], t2 = (hi[c] - r.o[c]) * r.inv[c];
    ta = fmaxf(ta, fminf(t1, t2));
    tb = fminf(tb, fmaxf(t1, t2));
  }
  return ta <= tb;
}

static __device__ __forceinline__ void store(float *o, const Best &best) {
  o[0] = best.t;
  o[1] = best.u;
  o[2] = best.v;
  o[3] = __uint_as_float(best.tri);
}

extern "C" __global__ void trace_complete(const TraceParams *p, const float *pairs, const float *tris, const float *rays,
                                          float *out) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    Ray r = load_ray(rays + i * RAY);
    Best best = {rays[i * RAY + 7], 0.0f, 0.0f, NONE};
    float ta = r.tmin, tb = best.t;
    if (slab(p->lo[0], p->lo[1], p->lo[2], p->hi[0], p->hi[1], p->hi[2], r, ta, tb)) {
      unsigned stack[STACK];
      int size = 0;
      unsigned pair = 0;
      for (;;) {
        const float *pr = pairs + 14 * pair;
        float b0 = LDG(pr);            // @count pairs ld.global.nc.f32
        float b1 = LDG(pr + 1), b2 = LDG(pr + 2), b3 = LDG(pr + 3), b4 = LDG(pr + 4), b5 = LDG(pr + 5);
        float c0 = LDG(pr + 6), c1 = LDG(pr + 7), c2 = LDG(pr + 8), c3 = LDG(pr + 9), c4 = LDG(pr + 10), c5 = LDG(pr + 11);
        unsigned wl = __float_as_uint(LDG(pr + 12)), wr = __float_as_uint(LDG(pr + 13));
        asm volatile("" ::"f"(b0), "f"(b1), "f"(b2), "f"(b3), "f"(b4), "f"(b5), "r"(wl), "r"(wr));
        asm volatile("" ::"f"(c0), "f"(c1), "f"(c2), "f"(c3), "f"(c4), "f"(c5));
        float tal = r.tmin, tbl = best.t, tar = r.tmin, tbr = best.t;
        bool hl = slab(b0, b1, b2, b3, b4, b5, r, tal, tbl);
        bool hr = slab(c0, c1, c2, c3, c4, c5, r, tar, tbr);
        bool done = false;
        if (hl && (wl & LEAF_BIT)) done = leaf(tris, wl & ~LEAF_BIT, r, best);
        if (!done && hr && (wr & LEAF_BIT)) done = leaf(tris, wr & ~LEAF_BIT, r, best);
        if (done) break;
        bool il = hl && !(wl & LEAF_BIT), ir = hr && !(wr & LEAF_BIT);
        unsigned next = NONE;
        if (il && ir) {
          bool left_first = tal <= tar;
          unsigned far = left_first ? wr : wl;
          stack[size] = far;           // @count push st.local.u32
          size++;
          next = left_first ? wl : wr;
        } else if (il) {
          next = wl;
        } else if (ir) {
          next = wr;
        }
        if (next != NONE) {
          pair = next;
          continue;
        }
        if (size == 0) break;
        size--;
        pair = stack[size];            // @count pop ld.local.u32
      }
    }
    store(out + i * HIT, best);
  }
}

extern "C" __global__ void trace_compact(const TraceParams *p, const float *pairs, const float *tris, const float *rays,
                                         float *out) {
  const float inf = __int_as_float(0x7f800000);
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    Ray r = load_ray(rays + i * RAY);
    Best best = {rays[i * RAY + 7], 0.0f, 0.0f, NONE};
    float ta = r.tmin, tb = best.t;
    if (slab(p->lo[0], p->lo[1], p->lo[2], p->hi[0], p->hi[1], p->hi[2], r, ta, tb)) {
      unsigned stack_pair[STACK];
      float stack_a[STACK], stack_b[STACK];
      int size = 0;
      unsigned pair = 0;
      for (;;) {
        const float *pr = pairs + 8 * pair;
        float m0 = LDG(pr);            // @count pairs ld.global.nc.f32
        float m1 = LDG(pr + 1), m2 = LDG(pr + 2), M0 = LDG(pr + 3), M1 = LDG(pr + 4), M2 = LDG(pr + 5);
        unsigned w0 = __float_as_uint(LDG(pr + 6)), w1 = __float_as_uint(LDG(pr + 7));
        asm volatile("" ::"f"(m0), "f"(m1), "f"(m2), "f"(M0), "f"(M1), "f"(M2), "r"(w0), "r"(w1));
        float m[3] = {m0, m1, m2}, M[3] = {M0, M1, M2};
        // Algorithm 6.1
        float tal = ta, tar = ta;
        float tbl = fminf(tb, best.t), tbr = tbl;
        for (int k = 0; k < 3; k++) {
          float t1 = (m[k] - r.o[k]) * r.inv[k];
          float t2 = (M[k] - r.o[k]) * r.inv[k];
          float t3 = inf * r.inv[k];
          bool lk = (w0 >> (31 - k)) & 1, uk = (w1 >> (31 - k)) & 1;
          float t1l = lk ? t1 : -t3, t1r = lk ? -t3 : t1;
          float t2l = uk ? t2 : t3, t2r = uk ? t3 : t2;
          tal = fmaxf(tal, fminf(t1l, t2l));
          tbl = fminf(tbl, fmaxf(t1l, t2l));
          tar = fmaxf(tar, fminf(t1r, t2r));
          tbr = fminf(tbr, fmaxf(t1r, t2r));
        }
        bool hl = tal <= tbl, hr = tar <= tbr;
        bool done = false;
        if (hl && (w0 & REF_LEAF)) done = leaf(tris, w0 & REF_MASK, r, best);
        if (!done && hr && (w1 & REF_LEAF)) done = leaf(tris, w1 & REF_MASK, r, best);
        if (done) break;
        bool il = hl && !(w0 & REF_LEAF), ir = hr && !(w1 & REF_LEAF);
        bool go = true;
        if (il && ir) {
          bool left_first = tal <= tar;
          unsigned far = (left_first ? w1 : w0) & REF_MASK;
          stack_pair[size] = far;      // @count push st.local.u32
          stack_a[size] = left_first ? tar : tal;
          stack_b[size] = left_first ? tbr : tbl;
          size++;
          pair = (left_first ? w0 : w1) & REF_MASK;
          ta = left_first ? tal : tar;
          tb = left_first ? tbl : tbr;
        } else if (il) {
          pair = w0 & REF_MASK;
          ta = tal;
          tb = tbl;
        } else if (ir) {
          pair = w1 & REF_MASK;
          ta = tar;
          tb = tbr;
        } else {
          go = false;
        }
        if (go) continue;
        bool found = false;
        while (size > 0) {
          size--;
          unsigned e = stack_pair[size]; // @count pop ld.local.u32
          float ea = stack_a[size], eb = stack_b[size];
          asm volatile("" ::"r"(e), "f"(ea), "f"(eb)); // the whole 12-byte entry is read on every pop
          if (ea > best.t) continue;
          pair = e;
          ta = ea;
          tb = eb;
          found = true;
          break;
        }
        if (!found) break;
      }
    }
    store(out + i * HIT, best);
  }
}

extern "C" __global__ void trace_complete_ta(const TraceParams *p, const float *pairs, const float *tris,
                                             const float *rays, float *out) {
  for (unsigned i = WL_TID; i < (unsigned)p->count; i += blockDim.x * gridDim.x) {
    Ray r = load_ray(rays + i * RAY);
    Best best = {rays[i * RAY + 7], 0.0f, 0.0f, NONE};
    float ta = r.tmin, tb = best.t;
    if (slab(p->lo[0], p->lo[1], p->lo[2], p->hi[0], p->hi[1], p->hi[2], r, ta, tb)) {
      unsigned stack[STACK];
      float stack_a[STACK];
      int size = 0;
      unsigned pair = 0;
      for (;;) {
        const float *pr = pairs + 14 * pair;
        float b0 = LDG(pr);            // @count pairs ld.global.nc.f32
        float b1 = LDG(pr + 1), b2 = LDG(pr + 2), b3 = LDG(pr + 3), b4 = LDG(pr + 4), b5 = LDG(pr + 5);
        float c0 = LDG(pr + 6), c1 = LDG(pr + 7), c2 = LDG(pr + 8), c3 = LDG(pr + 9), c4 = LDG(pr + 10), c5 = LDG(pr + 11);
        unsigned wl = __float_as_uint(LDG(pr + 12)), wr = __float_as_uint(LDG(pr + 13));
        asm volatile("" ::"f"(b0), "f"(b1), "f"(b2), "f"(b3), "f"(b4), "f"(b5), "r"(wl), "r"(wr));
        asm volatile("" ::"f"(c0), "f"(c1), "f"(c2), "f"(c3), "f"(c4), "f"(c5));
        float tal = r.tmin, tbl = best.t, tar = r.tmin, tbr = best.t;
        bool hl = slab(b0, b1, b2, b3, b4, b5, r, tal, tbl);
        bool hr = slab(c0, c1, c2, c3, c4, c5, r, tar, tbr);
        bool done = false;
        if (hl && (wl & LEAF_BIT)) done = leaf(tris, wl & ~LEAF_BIT, r, best);
        if (!done && hr && (wr & LEAF_BIT)) done = leaf(tris, wr & ~LEAF_BIT, r, best);
        if (done) break;
        bool il = hl && !(wl & LEAF_BIT), ir = hr && !(wr & LEAF_BIT);
        unsigned next = NONE;
        if (il && ir) {
          bool left_first = tal <= tar;
          unsigned far = left_first ? wr : wl;
          float far_a = left_first ? tar : tal;
          stack[size] = far;           // @count push st.local.u32
          if (!r.any) {
            stack_a[size] = far_a;     // @count push_ta st.local.f32
          }
          size++;
          next = left_first ? wl : wr;
        } else if (il) {
          next = wl;
        } else if (ir) {
          next = wr;
        }
        if (next != NONE) {
          pair = next;
          continue;
        }
        bool found = false;
        while (size > 0) {
          size--;
          unsigned e = stack[size];    // @count pop ld.local.u32
          if (!r.any) {
            float ea = stack_a[size];  // @count pop_ta ld.local.f32
            if (ea > best.t) continue;
          }
          pair = e;
          found = true;
          break;
        }
        if (!found) break;
      }
    }
    store(out + i * HIT, best);
  }
}
