// Thesis 003 (Lin 2017), §6.5: the GPU full-SAH kd-tree construction
// (003:L548-587), level by level (breadth first), as the kernels the host
// (src/host/path/gpu_build.rs) launches one after another. The thesis uses
// Thrust; its primitives are written out here: a merge sort (the root's event
// sort, 003:L554), an exclusive scan in three kernels (kd_scan_blocks,
// kd_scan_sums, kd_scan_add; kernels/cta_scan.h in each CTA), a segmented
// minimum by a 64-bit atomicMin per node (reduce_by_key, 003:L562) and stream
// compaction by scan and scatter (003:L564-576).
//
// Events (003:L552-556), per dimension d, SoA, dimension-major (index d*E + e,
// E = 2 x the level's triangle references; every reference has a start and an
// end event in each dimension): pos (float), flags (bit 0: end event, bit 1:
// the triangle is flat in d), tri (the event's address in the level's
// triangle list). Within a node's segment the events are sorted by position,
// and at equal positions: the flat triangles' starts, their ends, the other
// ends, the other starts (Wald's "ends before starts", 003:L554, with the flat
// triangles put where a sweep counts them on the left, 003:L562), then by
// triangle. Children inherit the order through stable compaction.
//
// One level (host: gpu_build::build):
//   kd_scan(ends)     exclusive scan of the end flags over all events (003:L560)
//   kd_sah            per event of the node's axis (or every axis: `all_axes`):
//                     the SAH cost of its position, atomicMin of (cost, dim,
//                     event) into the node's best (003:L562)
//   kd_decide         per node: split or leaf (003:L564)
//   kd_scan(split)    ranks of the split nodes among the level's
//   kd_clear          the triangle bit array [left T | right T | leaf T]
//   kd_assign         per event of the node's split dimension: the bits (003:L564-568)
//   kd_scan(bits)     the next level's triangle addresses and the leaf offsets
//   kd_nodes          per node: its record in the tree, its children's node structs (003:L576)
//   kd_spawn_tris     triangle list and owners of the next level, leaf triangles (003:L568-570)
//   kd_event_flags    per event and side: its triangle's bit (003:L572)
//   kd_scan(events)   the next level's event addresses
//   kd_event_scatter  the next level's events, their triangle addresses renumbered (003:L572-574)
#include "../prelude.h"
#include "cta_scan.h"

// The SAH costs round every product and sum (no fused multiply-add), so
// that both dialects build the serial twin's tree: clang by the pragma, nvcc
// (which contracts by default) by the _rn intrinsics.
#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#define MUL(a, b) ((a) * (b))
#define ADD(a, b) ((a) + (b))
#else
#define MUL(a, b) __fmul_rn(a, b)
#define ADD(a, b) __fadd_rn(a, b)
#endif

#define KD_THREADS 256
#define KD_LEAF 3u
#define EV_END 1u
#define EV_FLAT 2u
// sort classes at one position (bits 30-31 of a key's low word)
#define CLASS_FLAT_START 0u
#define CLASS_FLAT_END 1u
#define CLASS_END 2u
#define CLASS_START 3u
#define NO_SPLIT 0xffffffffffffffffull

typedef unsigned long long u64;

static __device__ __forceinline__ u64 atomic_min_u64(u64 *a, u64 v) { return __nvvm_atom_min_gen_ull(a, v); }

// A node of the level being built (16 words, as gpu_build::NODE_WORDS).
struct KdNode {
  float lo[3];
  float hi[3];
  unsigned tri_off;    // first triangle of the node in the level's triangle list
  unsigned n;          // its triangles
  unsigned axis;       // the axis its SAH evaluates (longest extent, 003:L560, L576)
  unsigned depth;      // the root is 0
  unsigned split_dim;  // kd_decide: the split's dimension, or KD_LEAF
  unsigned best_ev;    // kd_decide: the split event's index in the node's segment
  float split;         // kd_decide: the split position
  unsigned pad[3];
};

// Float order as unsigned order (-0 taken as +0).
static __device__ __forceinline__ unsigned ord(float x) {
  unsigned b = __float_as_uint(x);
  if (b == 0x80000000u) b = 0u;
  return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

static __device__ __forceinline__ float unord(unsigned u) {
  return __uint_as_float((u & 0x80000000u) ? (u & 0x7fffffffu) : ~u);
}

// Surface area as host::kdtree::Aabb::area.
static __device__ __forceinline__ float area(const float *lo, const float *hi) {
  float x = fmaxf(hi[0] - lo[0], 0.0f), y = fmaxf(hi[1] - lo[1], 0.0f), z = fmaxf(hi[2] - lo[2], 0.0f);
  return MUL(2.0f, ADD(ADD(MUL(x, y), MUL(y, z)), MUL(z, x)));
}

// ---- the root's events -------------------------------------------------------

// One thread per (dimension, triangle): the triangle's two event keys
// (order(pos) << 32 | class << 30 | triangle) at keys[d*2N + 2t], [.. + 1].
extern "C" __global__ void kd_init_events(const float *verts, unsigned n, u64 *keys) {
  unsigned j = WL_TID;
  if (j >= 3u * n) return;
  unsigned d = j / n, t = j - d * n;
  const float *v = verts + 9u * t;
  float a = v[d], b = v[3 + d], c = v[6 + d];
  float lo = fminf(a, fminf(b, c)), hi = fmaxf(a, fmaxf(b, c));
  bool flat = lo == hi;
  u64 ks = ((u64)ord(lo) << 32) | ((u64)(flat ? CLASS_FLAT_START : CLASS_START) << 30) | t;
  u64 ke = ((u64)ord(hi) << 32) | ((u64)(flat ? CLASS_FLAT_END : CLASS_END) << 30) | t;
  keys[d * 2u * n + 2u * t] = ks;
  keys[d * 2u * n + 2u * t + 1u] = ke;
}

// One merge pass over `segs` segments of m keys each: runs of `width` are
// merged pairwise; every key finds its place by a binary search in the other
// run (the keys are distinct).
extern "C" __global__ void kd_merge_pass(const u64 *in, u64 *out, unsigned m, unsigned segs, unsigned width) {
  unsigned i = WL_TID;
  if (i >= m * segs) return;
  unsigned s = i / m, j = i - s * m;
  const u64 *seg = in + (u64)s * m;
  unsigned r = j / width, k = j - r * width;
  unsigned pair = (r & ~1u) * width;
  unsigned other = (r ^ 1u) * width;
  unsigned len = other < m ? (m - other < width ? m - other : width) : 0u;
  u64 key = seg[j];
  unsigned lo = 0, hi = len;
  while (lo < hi) {
    unsigned mid = (lo + hi) >> 1;
    if (seg[other + mid] < key) lo = mid + 1; else hi = mid;
  }
  out[(u64)s * m + pair + k + lo] = key;
}

// The sorted keys as the SoA events of the root (triangle address = triangle).
extern "C" __global__ void kd_unpack(const u64 *keys, unsigned total, float *pos, unsigned *flags, unsigned *tri) {
  unsigned i = WL_TID;
  if (i >= total) return;
  u64 k = keys[i];
  unsigned cls = (unsigned)(k >> 30) & 3u;
  pos[i] = unord((unsigned)(k >> 32));
  flags[i] = ((cls == CLASS_FLAT_END || cls == CLASS_END) ? EV_END : 0u) |
             ((cls == CLASS_FLAT_START || cls == CLASS_FLAT_END) ? EV_FLAT : 0u);
  tri[i] = (unsigned)k & 0x3fffffffu;
}

// ---- the exclusive scan (three kernels) ----------------------------------------

// Per CTA: out[j] = the exclusive scan of (in[j] & mask) != 0 within the CTA;
// sums[block] = the CTA's total.
extern "C" __global__ void kd_scan_blocks(const unsigned *in, unsigned mask, unsigned n, unsigned *out,
                                          unsigned *sums) {
  __shared__ unsigned buf[KD_THREADS];
  unsigned j = WL_TID;
  cta_scan_block<KD_THREADS>(buf, j < n && (in[j] & mask) != 0u ? 1u : 0u, j, n, out, sums);
}

// One CTA: the exclusive scan of the CTA totals; the grand total in sums[blocks].
extern "C" __global__ void kd_scan_sums(unsigned *sums, unsigned blocks) {
  __shared__ unsigned buf[KD_THREADS];
  cta_scan_sums<KD_THREADS>(buf, sums, blocks);
}

// out[j] += its CTA's offset; out[n] = the grand total.
extern "C" __global__ void kd_scan_add(unsigned *out, const unsigned *sums, unsigned n, unsigned blocks) {
  unsigned j = WL_TID;
  if (j < n) out[j] += sums[blockIdx.x];
  if (j == n) out[n] = sums[blocks];
}

// ---- one level ------------------------------------------------------------------

// Per event: the SAH cost of a split at its position (003:L560-562). Ends up
// to and including the event leave the right side, starts before it are on
// the left; a position not strictly inside the node is no candidate.
extern "C" __global__ void kd_sah(const KdNode *nodes, u64 *best, const float *pos, const unsigned *flags,
                                  const unsigned *tri, const unsigned *ends, const unsigned *tri_owner, unsigned ev,
                                  unsigned all_axes, unsigned max_depth, float k_t, float k_i) {
  unsigned g = WL_TID;
  if (g >= 3u * ev) return;
  unsigned d = g / ev, e = g - d * ev;
  unsigned o = tri_owner[tri[g]];
  const KdNode *nd = nodes + o;
  if (nd->depth >= max_depth) return;
  if (!all_axes && d != nd->axis) return;
  float p = pos[g];
  if (!(p > nd->lo[d] && p < nd->hi[d])) return;
  float a = area(nd->lo, nd->hi);
  if (!(a > 0.0f)) return;
  unsigned off = 2u * nd->tri_off;
  unsigned rel = e - off;
  unsigned is_end = flags[g] & EV_END;
  unsigned e_incl = ends[g] + is_end - ends[d * ev + off];
  unsigned n_r = nd->n - e_incl;
  unsigned n_l = rel - e_incl + is_end;
  float l_hi[3] = {nd->hi[0], nd->hi[1], nd->hi[2]};
  float r_lo[3] = {nd->lo[0], nd->lo[1], nd->lo[2]};
  l_hi[d] = p;
  r_lo[d] = p;
  float cost = ADD(k_t, MUL(k_i, ADD(MUL(area(nd->lo, l_hi) / a, (float)n_l), MUL(area(r_lo, nd->hi) / a, (float)n_r))));
  u64 key = ((u64)__float_as_uint(cost) << 32) | ((u64)d << 30) | rel;
  atomic_min_u64(best + o, key);
}

// Per node: split at its best event, or make it a leaf (003:L564): no
// candidate, the deepest level, no triangle, or the best cost not below
// K_I n while the node fits a leaf (6-bit count).
extern "C" __global__ void kd_decide(KdNode *nodes, const u64 *best, unsigned count, const float *pos, unsigned ev,
                                     unsigned max_depth, unsigned max_leaf, float k_i, unsigned *is_split) {
  unsigned o = WL_TID;
  if (o >= count) return;
  KdNode *nd = nodes + o;
  u64 b = best[o];
  bool split = false;
  if (b != NO_SPLIT && nd->depth < max_depth && nd->n > 0u) {
    float cost = __uint_as_float((unsigned)(b >> 32));
    split = cost < MUL(k_i, (float)nd->n) || nd->n > max_leaf;
  }
  if (split) {
    unsigned d = (unsigned)(b >> 30) & 3u, rel = (unsigned)b & 0x3fffffffu;
    nd->split_dim = d;
    nd->best_ev = rel;
    nd->split = pos[d * ev + 2u * nd->tri_off + rel];
  } else {
    nd->split_dim = KD_LEAF;
  }
  is_split[o] = split ? 1u : 0u;
}

extern "C" __global__ void kd_clear(unsigned *a, unsigned n) {
  unsigned j = WL_TID;
  if (j < n) a[j] = 0u;
}

// Per event of its node's split dimension (dimension 0 for a leaf): a start
// before the split event puts its triangle left, an end after it right, a
// flat triangle in the plane goes both ways (003:L564-566); a leaf's
// triangles are marked once, by their starts (003:L568).
extern "C" __global__ void kd_assign(const KdNode *nodes, const float *pos, const unsigned *flags, const unsigned *tri,
                                     const unsigned *tri_owner, unsigned ev, unsigned t, unsigned *bits) {
  unsigned g = WL_TID;
  if (g >= 3u * ev) return;
  unsigned d = g / ev, e = g - d * ev;
  unsigned a = tri[g];
  const KdNode *nd = nodes + tri_owner[a];
  unsigned f = flags[g];
  if (nd->split_dim == KD_LEAF) {
    if (d == 0u && !(f & EV_END)) bits[2u * t + a] = 1u;
    return;
  }
  if (d != nd->split_dim) return;
  unsigned rel = e - 2u * nd->tri_off;
  if (!(f & EV_END) && rel < nd->best_ev) bits[a] = 1u;
  if ((f & EV_END) && rel > nd->best_ev) bits[t + a] = 1u;
  if ((f & EV_FLAT) && pos[g] == nd->split) {
    bits[a] = 1u;
    bits[t + a] = 1u;
  }
}

// The longest axis of a box; ties to the lower axis.
static __device__ __forceinline__ unsigned longest(const float *lo, const float *hi) {
  float x = fmaxf(hi[0] - lo[0], 0.0f), y = fmaxf(hi[1] - lo[1], 0.0f), z = fmaxf(hi[2] - lo[2], 0.0f);
  return (x >= y && x >= z) ? 0u : (y >= z ? 1u : 2u);
}

// Per node: its record in the tree (tree[4o..]: axis or KD_LEAF, split, left
// child or first leaf reference, right child or count; the level's first
// node is node level_base of the tree) and, when split, its
// children's node structs: left children first, then right, in the order of
// their parents (003:L570, L576).
extern "C" __global__ void kd_nodes(const KdNode *nodes, unsigned count, const unsigned *split_rank, unsigned splits,
                                    const unsigned *addr, unsigned t, unsigned leaf_base, unsigned level_base,
                                    unsigned *tree, KdNode *next, u64 *next_best) {
  unsigned o = WL_TID;
  if (o >= count) return;
  const KdNode *nd = nodes + o;
  unsigned *rec = tree + 4u * o;
  if (nd->split_dim == KD_LEAF) {
    rec[0] = KD_LEAF;
    rec[1] = 0u;
    rec[2] = leaf_base + addr[2u * t + nd->tri_off] - addr[2u * t];
    rec[3] = nd->n;
    return;
  }
  unsigned d = nd->split_dim, r = split_rank[o];
  unsigned next_base = level_base + count;
  rec[0] = d;
  rec[1] = __float_as_uint(nd->split);
  rec[2] = next_base + r;
  rec[3] = next_base + splits + r;
  for (unsigned side = 0; side < 2u; ++side) {
    KdNode c;
    for (unsigned k = 0; k < 3u; ++k) {
      c.lo[k] = nd->lo[k];
      c.hi[k] = nd->hi[k];
    }
    if (side == 0u) c.hi[d] = nd->split; else c.lo[d] = nd->split;
    unsigned first = addr[side * t + nd->tri_off];
    c.tri_off = first;
    c.n = addr[side * t + nd->tri_off + nd->n] - first;
    c.axis = longest(c.lo, c.hi);
    c.depth = nd->depth + 1u;
    c.split_dim = KD_LEAF;
    c.best_ev = 0u;
    c.split = 0.0f;
    c.pad[0] = c.pad[1] = c.pad[2] = 0u;
    unsigned k = side == 0u ? r : splits + r;
    next[k] = c;
    next_best[k] = NO_SPLIT;
  }
}

// Per entry of [left T | right T | leaf T]: the next level's triangle list
// and owners, and the level's leaf triangles, leaf by leaf (003:L568-570).
extern "C" __global__ void kd_spawn_tris(const unsigned *tri_list, const unsigned *tri_owner, const unsigned *bits,
                                         const unsigned *addr, unsigned t, const unsigned *split_rank,
                                         unsigned splits, unsigned *next_list,
                                         unsigned *next_owner, unsigned *leaf_tris) {
  unsigned k = WL_TID;
  if (k >= 3u * t || bits[k] == 0u) return;
  unsigned side = k / t, a = k - side * t;
  unsigned at = addr[k];
  if (side == 2u) {
    leaf_tris[at - addr[2u * t]] = tri_list[a];
    return;
  }
  next_list[at] = tri_list[a];
  next_owner[at] = (side == 0u ? 0u : splits) + split_rank[tri_owner[a]];
}

// Per event and side (index (d*2 + side)*E + e): whether the event goes to
// that side's child, read from its triangle's bit (003:L572).
extern "C" __global__ void kd_event_flags(const unsigned *tri, unsigned ev, unsigned t, const unsigned *bits,
                                          unsigned *ev_bits) {
  unsigned h = WL_TID;
  if (h >= 6u * ev) return;
  unsigned ds = h / ev, e = h - ds * ev;
  unsigned d = ds >> 1, side = ds & 1u;
  ev_bits[h] = bits[side * t + tri[d * ev + e]];
}

// The next level's events at their scanned addresses; triangle addresses
// renumbered by the triangle scan (003:L572-574).
extern "C" __global__ void kd_event_scatter(const float *pos, const unsigned *flags, const unsigned *tri, unsigned ev,
                                           unsigned t, const unsigned *ev_bits, const unsigned *ev_addr,
                                           const unsigned *addr, float *next_pos, unsigned *next_flags,
                                           unsigned *next_tri) {
  unsigned h = WL_TID;
  if (h >= 6u * ev || ev_bits[h] == 0u) return;
  unsigned ds = h / ev, e = h - ds * ev;
  unsigned d = ds >> 1, side = ds & 1u;
  unsigned g = d * ev + e;
  unsigned at = ev_addr[h];
  next_pos[at] = pos[g];
  next_flags[at] = flags[g];
  next_tri[at] = addr[side * t + tri[g]];
}
