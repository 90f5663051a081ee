// Seed 004 (Purcell et al. 2003) §2.3: the kNN-grid radiance estimate, one
// photon lookup per iteration, `iters` iterations per launch (a rendering
// pass), the search state carried between launches in a state buffer.
//
// Search (004:L132-136, Fig. 6): the query point's cell first, then the
// concentric shells of cells around it (Chebyshev rings, clipped to the grid;
// in a ring, cells in z, y, x order). Each examined photon is
//   rejected  if it arrived from behind the surface (Jensen's direction test:
//             incoming direction . query normal >= 0);
//   rejected  if farther than the maximum search radius r_max;
//   added     if fewer than k are accumulated, the radius growing to it;
//   added     if k or more are accumulated and it lies within the radius;
//   rejected  otherwise (the radius no longer grows).
// The search ends when the explored rings cover the sphere of the radius
// (r_max while fewer than k photons are found), so it returns every photon
// within a sphere: at least k, or all within r_max.
//
// An iteration looks at one slot of the current cell: a photon, or the end of
// the cell (then the search moves to the next cell). Every iteration makes
// the same fetches, as a fragment program without branching would, and a
// finished pixel still runs the iteration without changing its state (a 2003
// fragment cannot be killed); what differs between the variants is whether a
// 16 x 16 tile whose pixels are all finished is drawn at all.
//
// Per-iteration fetches (global loads), as the maps lay out their data:
//   bitonic map (knn_bitonic): first[c], first[c + 1], the sorted element
//     (cell, photon), photon position, power, direction          = 6
//   stencil map (knn_stencil): stored[c], scale[c], and the slot's position,
//     power, direction in the cell's block                        = 5
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

static __device__ __forceinline__ int imin(int a, int b) { return a < b ? a : b; }
static __device__ __forceinline__ int imax(int a, int b) { return a > b ? a : b; }
static __device__ __forceinline__ int iabs(int a) { return a < 0 ? -a : a; }

// Texture fetches: one load instruction each, never removed, merged or moved
// into a branch by the compiler (a fragment program's TEX instructions run
// on every iteration).
static __device__ __forceinline__ float4 tex4(const float4 *p) {
  float4 v;
  asm volatile("ld.global.v4.f32 {%0, %1, %2, %3}, [%4];"
               : "=f"(v.x), "=f"(v.y), "=f"(v.z), "=f"(v.w)
               : "l"(p));
  return v;
}
static __device__ __forceinline__ uint2 tex2u(const uint2 *p) {
  uint2 v;
  asm volatile("ld.global.v2.u32 {%0, %1}, [%2];" : "=r"(v.x), "=r"(v.y) : "l"(p));
  return v;
}
static __device__ __forceinline__ unsigned tex1u(const unsigned *p) {
  unsigned v;
  asm volatile("ld.global.u32 %0, [%1];" : "=r"(v) : "l"(p));
  return v;
}
static __device__ __forceinline__ float tex1f(const float *p) {
  float v;
  asm volatile("ld.global.f32 %0, [%1];" : "=f"(v) : "l"(p));
  return v;
}

// The grid (as in grid.cu) and the search's parameters.
struct Search {
  float lo[4];    // lower corner
  float inv[4];   // inverse cell size
  float size[4];  // cell size
  int dims[4];    // nx, ny, nz, cells
  int k;          // photons sought
  float r_max;    // maximum search radius
  int iters;      // iterations per launch
  int tiled;      // 1: a 16 x 16 tile (CTA) whose pixels are all done is not drawn
  int slots;      // stencil map: slots per cell (m^2)
  int pad[3];
};

// Per-pixel search state, kept between launches.
struct State {
  float sum[3];   // accumulated photon power
  float r;        // search radius (the farthest photon added while n < k)
  int n;          // photons added
  int ring;       // current ring
  int dx, dy, dz; // current cell, relative to the query's cell
  int local;      // next slot in the current cell
  int done;       // 1: finished
  int used;       // iterations the pixel did before it finished
};

// The clipped range of ring offsets along one axis.
struct Range { int lo, hi; };
static __device__ __forceinline__ Range clip(int base, int n, int ring) {
  Range r = {imax(-ring, -base), imin(ring, n - 1 - base)};
  return r;
}

// The first dx >= x.lo on row (dy, dz) of ring R that lies on the shell, or
// R + 1 when there is none.
static __device__ __forceinline__ int first_x(Range x, int dy, int dz, int R) {
  if (iabs(dy) == R || iabs(dz) == R) return x.lo;
  if (x.lo == -R) return -R;
  if (x.hi == R) return R;
  return R + 1;
}
// The dx after `dx` on row (dy, dz), or R + 1.
static __device__ __forceinline__ int next_x(Range x, int dx, int dy, int dz, int R) {
  if (iabs(dy) == R || iabs(dz) == R) return dx < x.hi ? dx + 1 : R + 1;
  if (dx == -R && x.hi == R && R > 0) return R;
  return R + 1;
}

// Whether the rings 0..R cover a sphere of radius `rad` about q: the distance
// from q to the nearest face of the explored box, faces on the grid's border
// not counted (no photon lies beyond them).
static __device__ __forceinline__ bool covers(const Search &s, const float *q, const int *b, int R, float rad) {
  for (int a = 0; a < 3; ++a) {
    if (b[a] - R > 0) {
      float face = s.lo[a] + (float)(b[a] - R) * s.size[a];
      if (q[a] - face < rad) return false;
    }
    if (b[a] + R < s.dims[a] - 1) {
      float face = s.lo[a] + (float)(b[a] + R + 1) * s.size[a];
      if (face - q[a] < rad) return false;
    }
  }
  return true;
}

// Moves st to the next cell of the search (finishing it when the explored
// rings cover the sphere, or the grid is exhausted).
static __device__ __forceinline__ void advance(const Search &s, const float *q, const int *b, State &st) {
  st.local = 0;
  int R = st.ring;
  Range x = clip(b[0], s.dims[0], R), y = clip(b[1], s.dims[1], R), z = clip(b[2], s.dims[2], R);
  int dx = next_x(x, st.dx, st.dy, st.dz, R), dy = st.dy, dz = st.dz;
  while (dx > R) {
    // next row of this ring, or the next ring
    if (dy < y.hi) {
      dy += 1;
    } else if (dz < z.hi) {
      dy = y.lo;
      dz += 1;
    } else {
      // ring R complete
      float rad = st.n >= s.k ? st.r : s.r_max;
      bool whole = x.lo == -b[0] && x.hi == s.dims[0] - 1 - b[0] && y.lo == -b[1] &&
                   y.hi == s.dims[1] - 1 - b[1] && z.lo == -b[2] && z.hi == s.dims[2] - 1 - b[2];
      if (whole || covers(s, q, b, R, rad)) {
        st.done = 1;
        return;
      }
      R += 1;
      st.ring = R;
      x = clip(b[0], s.dims[0], R);
      y = clip(b[1], s.dims[1], R);
      z = clip(b[2], s.dims[2], R);
      dy = y.lo;
      dz = z.lo;
    }
    dx = first_x(x, dy, dz, R);
  }
  st.dx = dx;
  st.dy = dy;
  st.dz = dz;
}

// The accept/reject rule for one photon at distance d.
static __device__ __forceinline__ void consider(const Search &s, State &st, float d, float4 w, float scale) {
  if (d > s.r_max) return;
  if (st.n < s.k) {
    st.r = fmaxf(st.r, d);
  } else if (d > st.r) {
    return;
  }
  st.n += 1;
  st.sum[0] += w.x * scale;
  st.sum[1] += w.y * scale;
  st.sum[2] += w.z * scale;
}

template <int MAP>
static __device__ __forceinline__ void estimate(Search s, const float4 *query, const float4 *normal, State *state, int width, int height,
                                                const unsigned *first, const uint2 *sorted, int sorted_n,
                                                const unsigned *stored, const float *scale, const float4 *pos,
                                                const float4 *pw, const float4 *dir) {
  int px = blockIdx.x * blockDim.x + threadIdx.x, py = blockIdx.y * blockDim.y + threadIdx.y;
  bool inside = px < width && py < height;
  int p = inside ? py * width + px : 0;
  State st = state[p];
  if (s.tiled) {
    // the occlusion query: a tile none of whose pixels is active is not drawn
    __shared__ int active;
    if (threadIdx.x == 0 && threadIdx.y == 0) active = 0;
    __syncthreads();
    if (inside && !st.done) active = 1;
    __syncthreads();
    if (!active) return;
  }
  if (!inside) return;
  float4 q4 = query[p];
  float4 nrm = normal[p];
  float q[3] = {q4.x, q4.y, q4.z};
  int b[3];
  for (int a = 0; a < 3; ++a)
    b[a] = imin(imax((int)__builtin_floorf((q[a] - s.lo[a]) * s.inv[a]), 0), s.dims[a] - 1);
  for (int it = 0; it < s.iters; ++it) {
    int cx = imin(imax(b[0] + st.dx, 0), s.dims[0] - 1);
    int cy = imin(imax(b[1] + st.dy, 0), s.dims[1] - 1);
    int cz = imin(imax(b[2] + st.dz, 0), s.dims[2] - 1);
    int c = (cz * s.dims[1] + cy) * s.dims[0] + cx;
    bool valid;
    float4 pp, w, d;
    float sc;
    if (MAP == 0) {
      unsigned start = tex1u(first + c), end = tex1u(first + c + 1);
      unsigned j = start + (unsigned)st.local;
      valid = j < end;
      uint2 e = tex2u(sorted + imin((int)j, sorted_n - 1));
      unsigned ph = e.y == 0xffffffffu ? 0u : e.y;
      pp = tex4(pos + ph);
      w = tex4(pw + ph);
      d = tex4(dir + ph);
      sc = 1.0f;
    } else {
      unsigned cnt = tex1u(stored + c);
      sc = tex1f(scale + c);
      valid = (unsigned)st.local < cnt;
      int slot = c * s.slots + imin(st.local, s.slots - 1);
      pp = tex4(pos + slot);
      w = tex4(pw + slot);
      d = tex4(dir + slot);
    }
    if (!st.done) {
      st.used += 1;
      if (valid) {
        float ex = pp.x - q[0], ey = pp.y - q[1], ez = pp.z - q[2];
        // photons arriving from behind the surface are rejected (Jensen's direction test)
        bool front = d.x * nrm.x + d.y * nrm.y + d.z * nrm.z < 0.0f;
        if (front) consider(s, st, sqrtf(ex * ex + ey * ey + ez * ez), w, sc);
        st.local += 1;
      } else {
        advance(s, q, b, st);
      }
    }
  }
  state[p] = st;
}

extern "C" __global__ void knn_bitonic(Search s, const float4 *query, const float4 *normal, State *state, int width, int height,
                                       const unsigned *first, const uint2 *sorted, int sorted_n, const float4 *pos,
                                       const float4 *pw, const float4 *dir) {
  estimate<0>(s, query, normal, state, width, height, first, sorted, sorted_n, nullptr, nullptr, pos, pw, dir);
}

extern "C" __global__ void knn_stencil(Search s, const float4 *query, const float4 *normal, State *state, int width, int height,
                                       const unsigned *stored, const float *scale, const float4 *bpos,
                                       const float4 *bpow, const float4 *bdir) {
  estimate<1>(s, query, normal, state, width, height, nullptr, nullptr, 0, stored, scale, bpos, bpow, bdir);
}

// ---------------------------------------------------------------------------
// The 2003-faithful radiance estimate: the same search as `estimate` with the
// two constraints of fp30 that Table 2's Addr and Pack columns count
// (004:L199-203):
//   - every array is a 2-D float texture `tw` texels wide holding floats
//     (indices as floats), addressed by convert1dto2d: the address arithmetic
//     is float (floor, multiply, subtract) and a texel's offset is row *
//     width + column;
//   - the search state is one float4 (a fragment program's 128-bit output),
//     unpacked at the start of an iteration and packed at its end, the loop
//     carrying only the packed float4, as one pass per iteration would:
//       x: cell x | cell y << 8 | cell z << 16 | done << 24 (absolute cell
//          coordinates, at most 256 per axis; the ring is their Chebyshev
//          distance from the query's cell)
//       y: next slot in the cell | photons added << 16 (at most 65535)
//       z: power r | power g << 12 | shared exponent << 24
//       w: power b | search radius as a half << 16
//     the power as three 12-bit mantissas under the largest channel's
//     exponent (rounded to nearest; re-packing an unchanged sum is exact).
// Per iteration it makes the natural kernel's fetches (6 on map A, 5 on map
// B); the walk through the cells (advance) is the natural kernel's.

static __device__ __forceinline__ float2 convert1dto2d(float a, float width) {
  float y = __builtin_floorf(a / width);
  return make_float2(a - y * width, y);
}
static __device__ __forceinline__ int texel(float2 xy, float width) { return (int)xy.y * (int)width + (int)xy.x; }
static __device__ __forceinline__ float4 f4tex(const float4 *t, float a, float width) {
  return tex4(t + texel(convert1dto2d(a, width), width));
}
static __device__ __forceinline__ float f1tex(const float *t, float a, float width) {
  return tex1f(t + texel(convert1dto2d(a, width), width));
}
static __device__ __forceinline__ float2 f2tex(const float2 *t, float a, float width) {
  float2 v;
  asm volatile("ld.global.v2.f32 {%0, %1}, [%2];" : "=f"(v.x), "=f"(v.y) : "l"(t + texel(convert1dto2d(a, width), width)));
  return v;
}
static __device__ __forceinline__ unsigned short f2h(float x) {
  unsigned short h;
  asm("cvt.rn.f16.f32 %0, %1;" : "=h"(h) : "f"(x));
  return h;
}
static __device__ __forceinline__ float h2f(unsigned short h) {
  float x;
  asm("cvt.f32.f16 %0, %1;" : "=f"(x) : "h"(h));
  return x;
}

static __device__ __forceinline__ State unpack(float4 ps, const int *b) {
  unsigned x = __float_as_uint(ps.x), y = __float_as_uint(ps.y), z = __float_as_uint(ps.z), w = __float_as_uint(ps.w);
  State st;
  st.dx = (int)(x & 0xffu) - b[0];
  st.dy = (int)((x >> 8) & 0xffu) - b[1];
  st.dz = (int)((x >> 16) & 0xffu) - b[2];
  st.done = (int)((x >> 24) & 1u);
  st.ring = imax(iabs(st.dx), imax(iabs(st.dy), iabs(st.dz)));
  st.local = (int)(y & 0xffffu);
  st.n = (int)(y >> 16);
  unsigned e = z >> 24;
  float unit = e >= 12u ? __uint_as_float((e - 11u) << 23) : 0.0f;
  st.sum[0] = (float)(z & 0xfffu) * unit;
  st.sum[1] = (float)((z >> 12) & 0xfffu) * unit;
  st.sum[2] = (float)(w & 0xfffu) * unit;
  st.r = h2f((unsigned short)(w >> 16));
  st.used = 0;
  return st;
}

static __device__ __forceinline__ float4 pack(const State &st, const int *b) {
  unsigned x = (unsigned)(b[0] + st.dx) | ((unsigned)(b[1] + st.dy) << 8) | ((unsigned)(b[2] + st.dz) << 16) |
               ((unsigned)st.done << 24);
  unsigned y = (unsigned)st.local | ((unsigned)imin(st.n, 65535) << 16);
  float m = fmaxf(st.sum[0], fmaxf(st.sum[1], st.sum[2]));
  unsigned e = (__float_as_uint(m) >> 23) & 0xffu;
  unsigned q[3] = {0u, 0u, 0u};
  if (e >= 12u) {
    // the largest channel's mantissa in [2^11, 2^12): scale 2^(11 - (e - 127))
    float scale = __uint_as_float((265u - e) << 23);
    for (int i = 0; i < 3; ++i) q[i] = (unsigned)imin((int)(st.sum[i] * scale + 0.5f), 4095);
  } else {
    e = 0u;
  }
  unsigned z = q[0] | (q[1] << 12) | (e << 24);
  unsigned w = q[2] | ((unsigned)f2h(st.r) << 16);
  return make_float4(__uint_as_float(x), __uint_as_float(y), __uint_as_float(z), __uint_as_float(w));
}

template <int MAP>
static __device__ __forceinline__ void estimate_2003(Search s, float tw, const float4 *query, const float4 *normal,
                                                     float4 *state, int width, int height, const float *first,
                                                     const float2 *sorted, float sorted_n, const float *stored,
                                                     const float *scale, const float4 *pos, const float4 *pw,
                                                     const float4 *dir) {
  int px = blockIdx.x * blockDim.x + threadIdx.x, py = blockIdx.y * blockDim.y + threadIdx.y;
  bool inside = px < width && py < height;
  int p = inside ? py * width + px : 0;
  // the state, as four scalar fetches (once per pass)
  const unsigned *sp = (const unsigned *)(state + p);
  float4 ps = make_float4(__uint_as_float(tex1u(sp)), __uint_as_float(tex1u(sp + 1)), __uint_as_float(tex1u(sp + 2)),
                          __uint_as_float(tex1u(sp + 3)));
  if (s.tiled) {
    __shared__ int active;
    if (threadIdx.x == 0 && threadIdx.y == 0) active = 0;
    __syncthreads();
    if (inside && !((__float_as_uint(ps.x) >> 24) & 1u)) active = 1;
    __syncthreads();
    if (!active) return;
  }
  if (!inside) return;
  float4 q4 = query[p];
  float4 nrm = normal[p];
  float q[3] = {q4.x, q4.y, q4.z};
  int b[3];
  for (int a = 0; a < 3; ++a)
    b[a] = imin(imax((int)__builtin_floorf((q[a] - s.lo[a]) * s.inv[a]), 0), s.dims[a] - 1);
  for (int it = 0; it < s.iters; ++it) {
    State st = unpack(ps, b);
    // the cell's index in float, as a fragment program computes it
    float cx = (float)(b[0] + st.dx), cy = (float)(b[1] + st.dy), cz = (float)(b[2] + st.dz);
    float c = (cz * (float)s.dims[1] + cy) * (float)s.dims[0] + cx;
    bool valid;
    float4 pp, w, d;
    float sc;
    if (MAP == 0) {
      float start = f1tex(first, c, tw), end = f1tex(first, c + 1.0f, tw);
      float j = start + (float)st.local;
      valid = j < end;
      float2 e = f2tex(sorted, fminf(j, sorted_n - 1.0f), tw);
      float ph = e.y >= 0.0f ? e.y : 0.0f;  // -1: no photon
      pp = f4tex(pos, ph, tw);
      w = f4tex(pw, ph, tw);
      d = f4tex(dir, ph, tw);
      sc = 1.0f;
    } else {
      float cnt = f1tex(stored, c, tw);
      sc = f1tex(scale, c, tw);
      valid = (float)st.local < cnt;
      float slot = c * (float)s.slots + fminf((float)st.local, (float)(s.slots - 1));
      pp = f4tex(pos, slot, tw);
      w = f4tex(pw, slot, tw);
      d = f4tex(dir, slot, tw);
    }
    if (!st.done) {
      if (valid) {
        float ex = pp.x - q[0], ey = pp.y - q[1], ez = pp.z - q[2];
        bool front = d.x * nrm.x + d.y * nrm.y + d.z * nrm.z < 0.0f;
        if (front) consider(s, st, sqrtf(ex * ex + ey * ey + ez * ez), w, sc);
        st.local += 1;
      } else {
        advance(s, q, b, st);
      }
    }
    ps = pack(st, b);
  }
  unsigned *out = (unsigned *)(state + p);
  out[0] = __float_as_uint(ps.x);
  out[1] = __float_as_uint(ps.y);
  out[2] = __float_as_uint(ps.z);
  out[3] = __float_as_uint(ps.w);
}

extern "C" __global__ void knn_bitonic_2003(Search s, float tw, const float4 *query, const float4 *normal,
                                            float4 *state, int width, int height, const float *first,
                                            const float2 *sorted, float sorted_n, const float4 *pos,
                                            const float4 *pw, const float4 *dir) {
  estimate_2003<0>(s, tw, query, normal, state, width, height, first, sorted, sorted_n, nullptr, nullptr, pos, pw, dir);
}

extern "C" __global__ void knn_stencil_2003(Search s, float tw, const float4 *query, const float4 *normal,
                                            float4 *state, int width, int height, const float *stored,
                                            const float *scale, const float4 *bpos, const float4 *bpow,
                                            const float4 *bdir) {
  estimate_2003<1>(s, tw, query, normal, state, width, height, nullptr, nullptr, 0.0f, stored, scale, bpos, bpow, bdir);
}
