// Seed 004 (Purcell et al. 2003) §2.2: the uniform-grid photon map, built
// with data-parallel passes, one launch per rendering pass.
//
// A: bitonic merge sort + binary search (§2.2.1, Fig. 3, Fig. 4)
//   cell_keys       one element per photon slot: (cell, photon), cell = the
//                   grid's cell count for invalid photons and padding, so
//                   they sort last
//   bitonic_pass    Fig. 3 ported, one launch per (stage, step) pair; reads
//                   the element and its partner, writes min or max (gather
//                   only, ping-pong buffers)
//   bitonic_pass_2003  the same pass as the Cg program computes it: 2-D
//                   texture addressing (convert1dto2d), float floor/fmod in
//                   place of integer arithmetic, float4 elements (.y the key)
//   binary_search   one thread per grid cell (and one past the last): the
//                   first sorted element whose cell >= c, steps unrolled in
//                   one pass
// B: stencil routing (§2.2.2, Fig. 5)
//   stencil_route   one thread per photon slot (a drawn point); each cell
//                   owns m^2 slots; the first m^2 photons of a cell in draw
//                   order (photon index order) keep the slots, whatever the
//                   schedule: see the comment at the kernel
//   stencil_fill    one thread per cell slot: copies the routed photon's
//                   data into the cell's block and the cell's power
//                   redistribution factor (destined / stored)
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

static __device__ __forceinline__ int imin(int a, int b) { return a < b ? a : b; }
static __device__ __forceinline__ int imax(int a, int b) { return a > b ? a : b; }
static __device__ __forceinline__ unsigned umin(unsigned a, unsigned b) { return a < b ? a : b; }
static __device__ __forceinline__ unsigned umax(unsigned a, unsigned b) { return a > b ? a : b; }

// The grid: lower corner, inverse cell size, cells per axis.
struct Grid {
  float lo[4];
  float inv[4];
  int dims[4];  // nx, ny, nz, nx * ny * nz
};

static __device__ __forceinline__ unsigned cell_of(const Grid &g, float x, float y, float z) {
  int cx = imin(imax((int)__builtin_floorf((x - g.lo[0]) * g.inv[0]), 0), g.dims[0] - 1);
  int cy = imin(imax((int)__builtin_floorf((y - g.lo[1]) * g.inv[1]), 0), g.dims[1] - 1);
  int cz = imin(imax((int)__builtin_floorf((z - g.lo[2]) * g.inv[2]), 0), g.dims[2] - 1);
  return (unsigned)((cz * g.dims[1] + cy) * g.dims[0] + cx);
}

// Sort elements of photon slots [first, first + count) padded to n (a power
// of two): elem[e] = (cell, slot).
extern "C" __global__ void cell_keys(Grid g, const float4 *pos, int first, int count, int n, uint2 *elem) {
  int e = WL_TID;
  if (e >= n) return;
  unsigned key = (unsigned)g.dims[3];
  unsigned slot = 0xffffffffu;
  if (e < count) {
    slot = (unsigned)(first + e);
    float4 p = pos[slot];
    if (p.w != 0.0f) key = cell_of(g, p.x, p.y, p.z);
  }
  elem[e] = make_uint2(key, slot);
}

// One pass of the bitonic merge sort (Fig. 3): `offset` is the partner
// distance, stage = 2 * offset, `stepno` the size of the merged blocks.
extern "C" __global__ void bitonic_pass(const uint2 *in, uint2 *out, int n, int offset, int stepno) {
  int e = WL_TID;
  if (e >= n) return;
  int stage = 2 * offset;
  int csign = (e % stage < offset) ? 1 : -1;
  int cdir = ((e / stepno) % 2 == 0) ? 1 : -1;
  uint2 val0 = in[e];
  uint2 val1 = in[csign * offset + e];
  uint2 cmin = (val0.x < val1.x) ? val0 : val1;
  uint2 cmax = (val0.x > val1.x) ? val0 : val1;
  out[e] = (csign == cdir) ? cmin : cmax;
}

// convert1dto2d: a 1-D address as a texel of a texture `width` texels wide
// (the seed does not print its body, 004:L98: row = floor(a / width)).
static __device__ __forceinline__ float2 convert1dto2d(float a, float width) {
  float y = __builtin_floorf(a / width);
  return make_float2(a - y * width, y);
}
// f4texRECT: the texel at (x, y) of a texture `width` texels wide.
static __device__ __forceinline__ float4 f4texRECT(const float4 *tex, float2 xy, float width) {
  return tex[(int)xy.y * (int)width + (int)xy.x];
}
static __device__ __forceinline__ float fmod_cg(float a, float b) { return a - b * __builtin_floorf(a / b); }

// Fig. 3 as the Cg program computes it: a 2-D launch over a texture `width`
// texels wide, one thread per texel; elements are float4 with the key in .y.
extern "C" __global__ void bitonic_pass_2003(const float4 *sortedplist, float4 *dst, float width, float offset,
                                             float stage, float stepno) {
  float2 elem2d = make_float2((float)(blockIdx.x * blockDim.x + threadIdx.x),
                              (float)(blockIdx.y * blockDim.y + threadIdx.y));
  float elem1d = elem2d.y * width + elem2d.x;
  float csign = (fmod_cg(elem1d, stage) < offset) ? 1.0f : -1.0f;
  float cdir = (fmod_cg(__builtin_floorf(elem1d / stepno), 2.0f) == 0.0f) ? 1.0f : -1.0f;
  float4 val0 = f4texRECT(sortedplist, elem2d, width);
  float adr1d = csign * offset + elem1d;
  float2 adr2d = convert1dto2d(adr1d, width);
  float4 val1 = f4texRECT(sortedplist, adr2d, width);
  float4 cmin = (val0.y < val1.y) ? val0 : val1;
  float4 cmax = (val0.y > val1.y) ? val0 : val1;
  dst[(int)elem2d.y * (int)width + (int)elem2d.x] = (csign == cdir) ? cmin : cmax;
}

// first[c] = the first element of the sorted list whose cell >= c, for c in
// [0, cells]; a cell's photons are elements [first[c], first[c + 1]).
// log2(n) + 1 steps of one fetch each.
extern "C" __global__ void binary_search(const uint2 *sorted, int n, int cells, unsigned *first) {
  int c = WL_TID;
  if (c > cells) return;
  int lo = 0;
  for (int s = n; s > 0; s >>= 1) {
    int probe = lo + s - 1;
    if (probe < n && sorted[probe].x < (unsigned)c) lo += s;
  }
  first[c] = (unsigned)lo;
}

// Stencil routing. In OpenGL the points are drawn in submission order, so
// the stencil test (pass iff stencil == m^2 - 1, always increment) gives the
// first m^2 photons of a cell its slots. Concurrent threads have no draw
// order; a slot counter (atomicAdd) alone would keep a schedule-dependent
// subset. Instead each photon is inserted into its cell's slots, kept sorted
// by photon index, with atomicMin: at each slot the smaller of the resident
// and the carried index stays and the larger travels on. Every index but a
// slot's final resident passes that slot exactly once, so slot s ends with
// the (s+1)-th smallest index of the cell whatever the order of arrival: the
// first m^2 in draw order, as the stencil keeps them. What travels past the
// last slot is dropped. destined[c] counts the photons drawn into the cell
// (the stencil's increments, unclamped), for the power redistribution.
extern "C" __global__ void stencil_route(Grid g, const float4 *pos, int first, int count, int slots,
                                         unsigned *cell_slots, unsigned *destined) {
  int e = WL_TID;
  if (e >= count) return;
  unsigned v = (unsigned)(first + e);
  float4 p = pos[v];
  if (p.w == 0.0f) return;
  unsigned c = cell_of(g, p.x, p.y, p.z);
  atomicAdd(&destined[c], 1u);
  unsigned *block = cell_slots + (unsigned long long)c * slots;
  for (int s = 0; s < slots; ++s) {
    unsigned old = atomicMin(&block[s], v);
    if (old == 0xffffffffu) return;
    v = umax(old, v);
  }
}

// After routing: the routed photons' data in the cells' blocks (slot order),
// the stored count and the redistribution factor per cell (one thread per
// slot; the first slot's thread writes the cell's entries).
extern "C" __global__ void stencil_fill(const unsigned *cell_slots, const unsigned *destined, int cells, int slots,
                                        const float4 *pos, const float4 *pw, const float4 *dir, float4 *bpos,
                                        float4 *bpow, float4 *bdir, unsigned *stored, float *scale) {
  int i = WL_TID;
  if (i >= cells * slots) return;
  unsigned v = cell_slots[i];
  if (v != 0xffffffffu) {
    bpos[i] = pos[v];
    bpow[i] = pw[v];
    bdir[i] = dir[v];
  } else {
    bpos[i] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    bpow[i] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    bdir[i] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  }
  if (i % slots == 0) {
    int c = i / slots;
    unsigned d = destined[c];
    unsigned s = umin(d, (unsigned)slots);
    stored[c] = s;
    scale[c] = s == 0 ? 0.0f : (float)d / (float)s;
  }
}
