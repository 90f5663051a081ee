// Thesis 000 chapter 4: the GTX 280 kd-tree ray tracer, one kernel family.
//
// Persistent threads: each warp takes blocks of 32 consecutive pixels from a
// global job queue (atomicAdd) until the image is done. Per pixel up to four
// rays: primary, shadow, mirror reflection and its shadow ray (Whitted). A
// reflection ray is traced where the surface seen is specular: a mirror, or a
// diffuse material with a specular part (the MTL's Ks), whose reflection is
// added to its diffuse shading. Diffuse colours are the material's times the
// texel of its texture map, where it has one: all maps lie in one texel array
// read through the texture path (the thesis stacks them in one 3-D texture,
// seed extract L3431), nearest texel, repeated outside [0, 1).
// kd-tree nodes (8 bytes), triangle references and triangles are read through
// the read-only (texture) path (__ldg). Traversal variants (one template,
// one entry point each):
//   trace_stack                stack-based traversal, stack in local memory (seed extract §4.4)
//   trace_stackless            restart with the flags register (Alg. 4.1, errata fixed)
//   trace_pushdown             Alg. 4.2, push-down lines only
//   trace_shortstack           Alg. 4.2, short-stack lines only (4 entries, shared memory, round robin)
//   trace_pushdown_shortstack  Alg. 4.2, both
// The native caster (src/host/raycast.rs) performs the same float operations
// in the same order, so hits agree bit for bit; keep the two in step.
//
// Counting. This file compiles to the kernels as the thesis runs them: no
// tallies. The work the tables count (rays, shadow and reflection rays among
// them, inner-node steps, leaf visits, plane and barycentric tests,
// local-memory stack pushes and pops, texture-map texel fetches) is read off
// the emulator's per-instruction counters: a line ending in the comment
// `@count NAME OPCODE` executes exactly one OPCODE instruction per NAME event,
// and src/host/rt_kernels.rs sums, over every PTX instruction that `.loc`
// places on such a line, the lanes that executed it. Comments cost nothing.
// raytrace_stats.cu compiles the same source with RAYTRACE_STATS defined: the
// `TALLY` statements then count in the kernel and write a stats buffer, the
// cross-check that both agree (tests/raytrace.rs).
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define STACK 0
#define STACKLESS 1
#define PUSHDOWN 2
#define SHORTSTACK 3
#define PUSHDOWN_SHORTSTACK 4
#define SHORT_CAPACITY 4
#define CTA_THREADS 256
#define SS_WORDS (3 * SHORT_CAPACITY * CTA_THREADS)
#define STATS_WORDS 11                                // per pixel, the instrumented build's tallies

// Node caches (§4.3.1): the heap-ordered top of the tree, preloaded by each CTA.
// I: the top 10 levels as 8-byte nodes; II: the top 8 levels with their AABBs.
#define NC1_NODES 1024
#define NC2_NODES 256
__shared__ uint2 node_cache[NC1_NODES];
__shared__ float aabb_cache[6 * NC2_NODES];

// Short stacks of the short-stack variants: entry e of thread t, word w at
// [(3e + w) * 256 + t] (4 entries x 12 bytes per thread, 12 KB per CTA).
__shared__ float short_stacks[SS_WORDS];

// Scene and camera, laid out by src/host/rt_kernels.rs.
struct Params {
  float cam_pos[3], cam_fwd[3], cam_right[3], cam_up[3];
  float light_pos[3], light_int[3];
  float lo[3], hi[3];
  float eps, tan_half, aspect;
  int width, height, num_pixels, has_light;
};

struct V3 { float x, y, z; };
static __device__ __forceinline__ V3 v3(float x, float y, float z) { V3 r = {x, y, z}; return r; }
static __device__ __forceinline__ float comp(V3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }
static __device__ __forceinline__ float dot3(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static __device__ __forceinline__ V3 normalize3(V3 v) {
  float inv = 1.0f / sqrtf(v.x * v.x + v.y * v.y + v.z * v.z);
  return v3(v.x * inv, v.y * inv, v.z * inv);
}

struct Scene {
  const Params *p;
  const uint2 *nodes;      // 8-byte nodes: split bits, pair << 2 | axis (3 = leaf: first << 2 | 3, count)
  const unsigned *refs;    // triangle references
  const float4 *tris;      // 3 float4 per triangle: [n'i n'j n'd k], [e'1], [e'2]
  const unsigned *tri_mat; // material per triangle
  const float4 *mats;      // [r g b kind], kind: 0 diffuse, 1 mirror, 2 emitter; then [emission, 0]
  const float4 *surf;      // per material [reflection weight r g b, texture (int bits; -1: none)]
  const float *uvs;        // per triangle the texture coordinates of its 3 vertices (u, v)
  const uint4 *tex_info;   // per texture [first texel, width, height, 0]
  const unsigned *texels;  // every texture's texels, r | g << 8 | b << 16 | a << 24, rows top down
  const float *aabbs;      // 6 floats per heap node (node cache II)
};

#ifdef RAYTRACE_STATS
struct Stats { unsigned inner, leaves, planes, barys, rays, tex_nodes, local_stack, shadow, reflection, texels, pushes; };
#define TALLY(x) (x)
#else
struct Stats {};
#define TALLY(x) ((void)0)
#endif

// A node fetch: from the shared-memory node cache when `i` is cached (NC I:
// index < 2^10, NC II: index < 2^8), else 8 bytes through the texture path.
template <int NC>
static __device__ __forceinline__ uint2 node_at(const Scene &s, unsigned i, bool *tex) {
  if ((NC == 1 && i < NC1_NODES) || (NC == 2 && i < NC2_NODES)) {
    *tex = false;
    return node_cache[i];                             // @count cached_node ld.shared.v2.u32
  }
  *tex = true;
  const unsigned *w = (const unsigned *)(s.nodes + i);
  uint2 n;
  n.x = __ldg(w);
  n.y = __ldg(w + 1);
  return n;
}

// Alg. 3.3: Wald's test; updates (t_hit, tri_hit) and returns true on a hit.
static __device__ __forceinline__ bool wald(const Scene &s, unsigned t, V3 o, V3 d, float t_min, float *t_hit,
                                            Stats &st) {
  const float *w = (const float *)(s.tris + 3 * t);
  float n0 = __ldg(w), n1 = __ldg(w + 1), n2 = __ldg(w + 2);
  int k = __float_as_int(__ldg(w + 3));
  int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;   // (k + 1) mod 3, (k + 2) mod 3
  TALLY(st.planes++);
  // line 3: the plane intersection
  float num = n2 - comp(o, k) - n0 * comp(o, a) - n1 * comp(o, b);
  float tt = num / (comp(d, k) + n0 * comp(d, a) + n1 * comp(d, b));   // @count planes div.rn.f32
  // lines 4-6: early out before e'1, e'2 are loaded
  if (!(tt >= t_min && tt <= *t_hit)) return false;
  TALLY(st.barys++);
  // lines 7-8: barycentric coordinates
  float hx = comp(o, a) + tt * comp(d, a);            // @count barys add.rn.f32
  float hy = comp(o, b) + tt * comp(d, b);
  float u = __ldg(w + 8) * hx + __ldg(w + 9) * hy + __ldg(w + 10);
  float v = __ldg(w + 4) * hx + __ldg(w + 5) * hy + __ldg(w + 6);
  if (u < 0.0f || v < 0.0f || u + v > 1.0f) return false;
  *t_hit = tt;
  return true;
}

// Tests the leaf's triangles for t in [max(t_a - eps, t_min), min(t_hit, t_b + eps)].
static __device__ __forceinline__ int visit_leaf(const Scene &s, uint2 n, V3 o, V3 d, float t_min, float t_a,
                                                 float t_b, bool any, float *t_hit, Stats &st) {
  TALLY(st.leaves++);
  float lo = fmaxf(t_a - s.p->eps, t_min);
  float saved = *t_hit;
  float hi = t_b + s.p->eps;                          // @count leaves add.rn.f32
  *t_hit = fminf(*t_hit, hi);
  int found = -1;
  unsigned first = n.y >> 2, count = n.x;
  for (unsigned r = 0; r < count; r++) {
    unsigned t = __ldg(s.refs + first + r);
    if (wald(s, t, o, d, lo, t_hit, st)) {
      found = (int)t;
      if (any) return found;
    }
  }
  if (found < 0) *t_hit = saved;
  return found;
}

// Returns the nearest (or, with `any`, the first) hit in (t_min, t_max); -1 for none.
// V: traversal variant; NC: node cache (0, I, II); SC: stack cache (0, I, II, III) of the stack variant.
template <int V, int NC = 0, int SC = 0>
static __device__ int trace(const Scene &s, V3 o, V3 d, float t_min, float t_max, bool any, float *t_out, Stats &st,
                            float *short_stack) {
  TALLY(st.rays++);
  float inv_x = 1.0f / d.x;                           // @count rays rcp.rn.f32
  V3 inv = v3(inv_x, 1.0f / d.y, 1.0f / d.z);
  const Params *p = s.p;
  // clip to the scene box
  float t0x = (p->lo[0] - o.x) * inv.x, t1x = (p->hi[0] - o.x) * inv.x;
  float t0y = (p->lo[1] - o.y) * inv.y, t1y = (p->hi[1] - o.y) * inv.y;
  float t0z = (p->lo[2] - o.z) * inv.z, t1z = (p->hi[2] - o.z) * inv.z;
  float tn = fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fminf(t0z, t1z));
  float tf = fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
  float ta = fmaxf(t_min, tn), tb = fminf(t_max, tf);
  if (!(ta <= tb)) return -1;
  float t_hit = t_max;
  if (V == STACK) {
    // Stack-based traversal (seed extract §4.4); 8-byte entries in local memory,
    // with the stack caches of §4.3.2 (Alg. 4.3-4.6).
    struct Entry { unsigned node; float tb; } stack[33];
    int size = 0;
    unsigned head_node = 0;                           // stack cache I: the top entry in registers
    float head_tb = 0.0f;
    unsigned top1 = 0, top2 = 0;                      // stack cache II: 8-bit node indices of the top 8 levels
    const float t_end = tb;                           // the ray's end, for stack cache II's clipping
    bool postponed = false;                           // stack cache III: a leaf waiting for the next one
    uint2 leaf = make_uint2(0, 0);
    float leaf_ta = 0.0f;
    unsigned node = 0;
    for (;;) {
      bool tex;
      uint2 n = node_at<NC>(s, node, &tex);
      while ((n.y & 3) != 3) {                        // inner node: one traversal step
        TALLY(st.inner++);
        TALLY(st.tex_nodes += tex);
        int k = n.y & 3;
        float ts = (__int_as_float(n.x) - comp(o, k)) * comp(inv, k);   // @count inner mul.rn.f32
        unsigned left = 2 * (n.y >> 2) + 1, right = left + 1;
        bool neg = __float_as_int(comp(d, k)) < 0;    // the IEEE sign bit: works for d_k = -0
        unsigned near = neg ? right : left, far = neg ? left : right;
        if (ts > tb || ts != ts) {
          node = near;
        } else if (ts < ta) {
          node = far;
        } else {
          if (SC == 1) {                              // Alg. 4.3
            if (head_node > 0) {                      // @count regpush setp.eq.s32
              stack[size].node = head_node;           // @count spill st.local.u32
              stack[size].tb = head_tb;
              size++;
              TALLY(st.local_stack++);
            }                                         // the old head spilled: a local access, not a push
            TALLY(st.pushes++);                       // every push goes to the register head
            head_node = far;
            head_tb = tb;
          } else if (SC == 2 && far < NC2_NODES) {    TALLY(st.pushes++);  // Alg. 4.5 lines 1-6: a register push
            if (top1 < (1u << 24)) top1 = (top1 << 8) | far;  // @count regpush setp.gt.u32
            else top2 = (top2 << 8) | far;
          } else {                                    // push the far child and the end of its interval
            stack[size].node = far;                   // @count push st.local.u32
            stack[size].tb = tb;
            size++;
            TALLY(st.local_stack++);
            TALLY(st.pushes++);
          }
          tb = ts;
          node = near;
        }
        n = node_at<NC>(s, node, &tex);
      }
      int h;
      if (SC == 3 && !postponed) {
        // stack cache III: postpone this leaf and traverse on to the next one (§4.3.2.3)
        postponed = true;
        leaf = n;
        leaf_ta = ta;
        if (size == 0) {                              // no next leaf: visit the postponed one alone
          h = visit_leaf(s, n, o, d, t_min, ta, tb, any, &t_hit, st);
          if (h >= 0) *t_out = t_hit;
          return h;
        }
        h = -1;
      } else if (SC == 3) {
        // visit the postponed leaf over [leaf.t_a, t_a], then this one over [t_a, t_b]
        postponed = false;
        h = visit_leaf(s, leaf, o, d, t_min, leaf_ta, ta, any, &t_hit, st);
        if (h < 0) h = visit_leaf(s, n, o, d, t_min, ta, tb, any, &t_hit, st);
      } else {
        h = visit_leaf(s, n, o, d, t_min, ta, tb, any, &t_hit, st);
      }
      if (h >= 0) {
        *t_out = t_hit;
        return h;
      }
      if (SC == 1 && head_node > 0) {                 // Alg. 4.4
        ta = tb;
        node = head_node;
        tb = head_tb;
        head_node = 0;
      } else if (size > 0) {
        size--;
        TALLY(st.local_stack++);
        ta = tb;                                      // the start is the previous end
        tb = stack[size].tb;
        node = stack[size].node;                      // @count pop ld.local.u32
      } else if (SC == 2 && (top1 > 0 || top2 > 0)) { // Alg. 4.6 lines 4-12
        if (top2 > 0) {
          node = top2 & 255;
          top2 >>= 8;
        } else {
          node = top1 & 255;
          top1 >>= 8;
        }
        ta = tb;                                      // [t_a, t_b] <- [t_b, t_max] clipped by AABB(node)
        const float *bx = aabb_cache + 6 * node;
        float fx = fmaxf((bx[0] - o.x) * inv.x, (bx[3] - o.x) * inv.x);
        float fy = fmaxf((bx[1] - o.y) * inv.y, (bx[4] - o.y) * inv.y);
        float fz = fmaxf((bx[2] - o.z) * inv.z, (bx[5] - o.z) * inv.z);
        tb = fminf(t_end, fminf(fminf(fx, fy), fz));
      } else {
        if (SC == 3 && postponed) {                   // the stack ran out with a leaf postponed
          h = visit_leaf(s, leaf, o, d, t_min, leaf_ta, tb, any, &t_hit, st);
          if (h >= 0) *t_out = t_hit;
          return h;
        }
        return -1;                                    // empty stacks: the ray misses
      }
    }
  } else {
    // Alg. 4.2 (Alg. 4.1 when neither extension is on), errata fixed.
    const bool PD = V == PUSHDOWN || V == PUSHDOWN_SHORTSTACK;
    const bool SS = V == SHORTSTACK || V == PUSHDOWN_SHORTSTACK;
    float r_tmin = ta, r_tmax = tb;                   // the restart interval
    unsigned restart = 0, restart_flag = 1u << 31;
    unsigned flags = 0;
    int front = 0, size = 0;                          // round-robin short stack (lines 1-2)
    bool push = true;
    unsigned node, flag;
    do {
      if (SS && size > 0) {                           // lines 7-9: pop
        ta = tb;
        size--;
        int at = (front + size) % SHORT_CAPACITY;
        node = __float_as_uint(short_stack[3 * at * CTA_THREADS]);
        flag = __float_as_uint(short_stack[(3 * at + 1) * CTA_THREADS]);
        tb = short_stack[(3 * at + 2) * CTA_THREADS];
      } else {                                        // lines 10-16: restart
        ta = r_tmin;
        tb = r_tmax;
        node = restart;
        flag = restart_flag;
        push = true;
      }
      bool tex;
      uint2 n = node_at<NC>(s, node, &tex);
      while ((n.y & 3) != 3) {                        // line 17
        TALLY(st.inner++);
        TALLY(st.tex_nodes += tex);
        int k = n.y & 3;
        float ts = (__int_as_float(n.x) - comp(o, k)) * comp(inv, k);   // @count inner mul.rn.f32
        unsigned left = 2 * (n.y >> 2) + 1, right = left + 1;
        bool neg = __float_as_int(comp(d, k)) < 0;
        unsigned near = neg ? right : left, far = neg ? left : right;
        if (ts < ta) {                                // lines 18-20
          flags |= flag;
          node = far;
        } else if (ts > tb || ts != ts) {             // lines 21-23 (erratum: t_s > t_b)
          flags |= flag;
          node = near;
        } else if (flags & flag) {                    // lines 25-27
          ta = ts;
          node = far;
        } else {
          if (PD && push) {                           // lines 29-35: push down the restart point
            r_tmin = ta;
            r_tmax = tb;
            restart = node;
            restart_flag = flag;
            push = false;
          }
          if (SS) {                                   // line 36: push (far, flag >> 1, t_b)
            int at = (front + size) % SHORT_CAPACITY;
            short_stack[3 * at * CTA_THREADS] = __uint_as_float(far);
            short_stack[(3 * at + 1) * CTA_THREADS] = __uint_as_float(flag >> 1);
            short_stack[(3 * at + 2) * CTA_THREADS] = tb;
            if (size < SHORT_CAPACITY) size++;
            else front = (front + 1) % SHORT_CAPACITY;
          }
          tb = ts;                                    // lines 37-38
          node = near;
        }
        flag >>= 1;                                   // line 41
        n = node_at<NC>(s, node, &tex);
      }
      flags += flag << 1;                             // line 43: ripple the carry
      int h = visit_leaf(s, n, o, d, t_min, ta, tb, any, &t_hit, st);  // line 44
      if (h >= 0) {                                   // a hit ends the traversal
        *t_out = t_hit;
        return h;
      }
    } while (flags != 0);                             // line 45
    return -1;
  }
}

static __device__ V3 normal_of(const Scene &s, unsigned t, V3 d) {
  const float *w = (const float *)(s.tris + 3 * t);
  int k = __float_as_int(__ldg(w + 3));
  float n[3];
  n[k] = 1.0f;
  n[k == 2 ? 0 : k + 1] = __ldg(w);
  n[k == 0 ? 2 : k - 1] = __ldg(w + 1);
  V3 v = normalize3(v3(n[0], n[1], n[2]));
  if (v.x * d.x + v.y * d.y + v.z * d.z > 0.0f) v = v3(-v.x, -v.y, -v.z);
  return v;
}

// Emission plus diffuse direct light from the point light (one shadow ray, cast from the light).
template <int V, int NC, int SC>
static __device__ V3 direct(const Scene &s, V3 o, V3 d, float t, unsigned tri, Stats &st, float *ss) {
  unsigned m = __ldg(s.tri_mat + tri);
  const float *mat = (const float *)(s.mats + 2 * m);
  V3 col = v3(__ldg(mat), __ldg(mat + 1), __ldg(mat + 2));
  int kind = (int)__ldg(mat + 3);
  V3 c = v3(__ldg(mat + 4), __ldg(mat + 5), __ldg(mat + 6));
  if (kind != 0) return c;
  const Params *p = s.p;
  int tex = __float_as_int(__ldg((const float *)(s.surf + m) + 3));
  if (tex >= 0) {
    // the texture map: barycentric weights of the hit as Wald's test computed them (Alg. 3.3 lines 7-8)
    const float *w = (const float *)(s.tris + 3 * tri);
    int k = __float_as_int(__ldg(w + 3));
    int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
    float hx = comp(o, a) + t * comp(d, a);
    float hy = comp(o, b) + t * comp(d, b);
    float u = __ldg(w + 8) * hx + __ldg(w + 9) * hy + __ldg(w + 10);
    float v = __ldg(w + 4) * hx + __ldg(w + 5) * hy + __ldg(w + 6);
    const float *uv = s.uvs + 6 * tri;
    float wt = 1.0f - u - v;
    float tu = wt * __ldg(uv) + u * __ldg(uv + 2) + v * __ldg(uv + 4);
    float tv = wt * __ldg(uv + 1) + u * __ldg(uv + 3) + v * __ldg(uv + 5);
    const unsigned *ti = (const unsigned *)(s.tex_info + tex);
    unsigned first = __ldg(ti);
    int tw = (int)__ldg(ti + 1), th = (int)__ldg(ti + 2);
    int x = __float2int_rd(tu * (float)tw) % tw;    // nearest texel, repeated
    int y = __float2int_rd((1.0f - tv) * (float)th) % th;
    if (x < 0) x += tw;
    if (y < 0) y += th;
    TALLY(st.texels++);
    unsigned texel = __ldg(s.texels + first + (unsigned)(y * tw + x));   // @count texels mad.lo.s32
    col = v3(col.x * ((float)(texel & 255u) / 255.0f), col.y * ((float)((texel >> 8) & 255u) / 255.0f),
             col.z * ((float)((texel >> 16) & 255u) / 255.0f));
  }
  V3 pt = v3(o.x + d.x * t, o.y + d.y * t, o.z + d.z * t);
  V3 n = normal_of(s, tri, d);
  if (p->has_light) {
    // the shadow ray goes from the point light toward the hit point (seed 000
    // L3411, L1561) and ends eps before it
    V3 lp = v3(p->light_pos[0], p->light_pos[1], p->light_pos[2]);
    V3 from = v3(pt.x - lp.x, pt.y - lp.y, pt.z - lp.z);
    float dist = sqrtf(dot3(from, from));
    V3 dir = v3(from.x / dist, from.y / dist, from.z / dist);
    float cos = -dot3(n, dir);
    if (cos > 0.0f) {
      float ts;
      TALLY(st.shadow++);
      float t_end = dist - p->eps;                    // @count shadow sub.rn.f32
      if (trace<V, NC, SC>(s, lp, dir, p->eps, t_end, true, &ts, st, ss) < 0) {
        float g = cos / (dist * dist) / 3.14159265358979323846f;
        c.x += col.x * p->light_int[0] * g;
        c.y += col.y * p->light_int[1] * g;
        c.z += col.z * p->light_int[2] * g;
      }
    }
  }
  c.x += 0.02f * col.x;
  c.y += 0.02f * col.y;
  c.z += 0.02f * col.z;
  return c;
}

template <int V, int NC, int SC>
static __device__ void render(const Params *p, const uint2 *nodes, const unsigned *refs, const float4 *tris,
                              const unsigned *tri_mat, const float4 *mats, const float4 *surf, const float *uvs,
                              const uint4 *tex_info, const unsigned *texels, const float *aabbs, unsigned *next,
                              float4 *color, int *hit_tri, unsigned *stats) {
  Scene s = {p, nodes, refs, tris, tri_mat, mats, surf, uvs, tex_info, texels, aabbs};
  if (NC == 1) {
    // every thread preloads 4 nodes of the top 10 levels, then the CTA synchronises
    for (int i = threadIdx.x; i < NC1_NODES; i += CTA_THREADS) {
      const unsigned *w = (const unsigned *)(nodes + i);
      node_cache[i].x = __ldg(w);
      node_cache[i].y = __ldg(w + 1);
    }
    __syncthreads();
  } else if (NC == 2) {
    // every thread preloads one node of the top 8 levels and its AABB
    for (int i = threadIdx.x; i < NC2_NODES; i += CTA_THREADS) {
      const unsigned *w = (const unsigned *)(nodes + i);
      node_cache[i].x = __ldg(w);
      node_cache[i].y = __ldg(w + 1);
      for (int j = 0; j < 6; j++) aabb_cache[6 * i + j] = __ldg(aabbs + 6 * i + j);
    }
    __syncthreads();
  }
  float *ss = short_stacks + threadIdx.x;
  int lane = threadIdx.x & 31;
  for (;;) {
    // the job queue: blocks of 32 consecutive pixels
    unsigned base = 0;
    if (lane == 0) base = atomicAdd(next, 32u);
    base = (unsigned)__shfl_sync(0xffffffffu, (int)base, 0);
    if (base >= (unsigned)p->num_pixels) break;
    int pix = (int)base + lane;
    if (pix >= p->num_pixels) continue;
    int x = pix % p->width, y = pix / p->width;
#ifdef RAYTRACE_STATS
    Stats st = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
#else
    Stats st;
#endif
    float px = (((float)x + 0.5f) / (float)p->width * 2.0f - 1.0f) * p->tan_half * p->aspect;
    float py = (1.0f - ((float)y + 0.5f) / (float)p->height * 2.0f) * p->tan_half;
    V3 o = v3(p->cam_pos[0], p->cam_pos[1], p->cam_pos[2]);
    V3 d = normalize3(v3(p->cam_fwd[0] + px * p->cam_right[0] + py * p->cam_up[0],
                         p->cam_fwd[1] + px * p->cam_right[1] + py * p->cam_up[1],
                         p->cam_fwd[2] + px * p->cam_right[2] + py * p->cam_up[2]));
    float t;
    int h = trace<V, NC, SC>(s, o, d, p->eps, __int_as_float(0x7f800000), false, &t, st, ss);   // the primary ray
    V3 c = v3(0.0f, 0.0f, 0.0f);
    if (h >= 0) {
      c = direct<V, NC, SC>(s, o, d, t, (unsigned)h, st, ss);
      unsigned m = __ldg(tri_mat + h);
      const float *rw = (const float *)(surf + m);
      V3 w = v3(__ldg(rw), __ldg(rw + 1), __ldg(rw + 2));
      if (w.x > 0.0f || w.y > 0.0f || w.z > 0.0f) {    // a specular surface: reflect
        V3 n = normal_of(s, (unsigned)h, d);
        V3 pt = v3(o.x + d.x * t, o.y + d.y * t, o.z + d.z * t);
        TALLY(st.reflection++);
        float s2 = 2.0f * dot3(d, n);                   // @count reflection add.rn.f32 (2 x: x + x)
        V3 r = normalize3(v3(d.x - s2 * n.x, d.y - s2 * n.y, d.z - s2 * n.z));
        float t2;
        int h2 = trace<V, NC, SC>(s, pt, r, p->eps, __int_as_float(0x7f800000), false, &t2, st, ss);
        if (h2 >= 0) {
          V3 c2 = direct<V, NC, SC>(s, pt, r, t2, (unsigned)h2, st, ss);
          c.x += w.x * c2.x;
          c.y += w.y * c2.y;
          c.z += w.z * c2.z;
        }
      }
    }
    color[pix] = make_float4(c.x, c.y, c.z, 1.0f);
    hit_tri[pix] = h;
#ifdef RAYTRACE_STATS
    unsigned *sp = stats + STATS_WORDS * pix;
    sp[0] = st.inner;
    sp[1] = st.leaves;
    sp[2] = st.planes;
    sp[3] = st.barys;
    sp[4] = st.rays;
    sp[5] = st.tex_nodes;
    sp[6] = st.local_stack;
    sp[7] = st.shadow;
    sp[8] = st.reflection;
    sp[9] = st.texels;
    sp[10] = st.pushes;
#else
    (void)stats;
#endif
  }
}

#define ENTRY(name, V, NC, SC)                                                                             \
  extern "C" __global__ void name(const Params *p, const uint2 *nodes, const unsigned *refs,               \
                                  const float4 *tris, const unsigned *tri_mat, const float4 *mats,         \
                                  const float4 *surf, const float *uvs, const uint4 *tex_info,             \
                                  const unsigned *texels, const float *aabbs, unsigned *next,              \
                                  float4 *color, int *hit_tri, unsigned *stats) {                          \
    render<V, NC, SC>(p, nodes, refs, tris, tri_mat, mats, surf, uvs, tex_info, texels, aabbs, next, color, \
                      hit_tri, stats);                                                                     \
  }
ENTRY(trace_stack, STACK, 0, 0)
ENTRY(trace_stackless, STACKLESS, 0, 0)
ENTRY(trace_pushdown, PUSHDOWN, 0, 0)
ENTRY(trace_shortstack, SHORTSTACK, 0, 0)
ENTRY(trace_pushdown_shortstack, PUSHDOWN_SHORTSTACK, 0, 0)
// Table 4.8's cache columns 2-7
ENTRY(trace_nc1, STACK, 1, 0)
ENTRY(trace_sc1, STACK, 0, 1)
ENTRY(trace_sc3, STACK, 0, 3)
ENTRY(trace_nc1_sc1, STACK, 1, 1)
ENTRY(trace_nc2_sc2, STACK, 2, 2)
ENTRY(trace_nc1_sc3, STACK, 1, 3)
