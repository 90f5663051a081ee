// The validation suite: kernels written the way well-known CUDA samples and
// GPU benchmark suites write them (warp-shuffle reduction and scan, tiled
// matrix product, bitonic sort, an unrolled sorting network, shared-atomic
// histogram, Needleman-Wunsch by anti-diagonals, a 1-D stencil, level-
// synchronous BFS), plus single-warp probes of the shared-memory and atomic
// rules. Launches, inputs and what Nsight Compute measured on an H200:
// tests/fixtures/validation/h200.json (tools/device/validation.py); the
// comparison: tests/validation_suite.rs, docs/validation.md.
#include "../prelude.h"

#define K extern "C" __global__ void
#define VD static __device__ __forceinline__

VD unsigned umin(unsigned a, unsigned b) { return a < b ? a : b; }
VD unsigned umax(unsigned a, unsigned b) { return a < b ? b : a; }
VD int imax(int a, int b) { return a < b ? b : a; }

// ---- reduction with warp shuffles (CUDA samples' reduce, "faster reductions with shuffles")
VD float warp_sum(float v) {
#pragma unroll
  for (int o = 16; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
  return v;
}
K reduce_shfl(const float *in, float *out, int n) {
  __shared__ float partial[32];
  float s = 0.0f;
  for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += blockDim.x * gridDim.x) s += in[i];
  s = warp_sum(s);
  int lane = threadIdx.x & 31, w = threadIdx.x >> 5;
  if (lane == 0) partial[w] = s;
  __syncthreads();
  if (w == 0) {
    s = lane < (int)(blockDim.x >> 5) ? partial[lane] : 0.0f;
    s = warp_sum(s);
    if (lane == 0) out[blockIdx.x] = s;
  }
}

// ---- tiled matrix product (CUDA samples' matrixMul), 16 x 16 tiles, inner loop unrolled
#define TILE 16
K matmul_tiled(const float *A, const float *B, float *C, int n) {
  __shared__ float As[TILE][TILE];
  __shared__ float Bs[TILE][TILE];
  int tx = threadIdx.x, ty = threadIdx.y;
  int row = blockIdx.y * TILE + ty, col = blockIdx.x * TILE + tx;
  float acc = 0.0f;
  for (int t = 0; t < n / TILE; t++) {
    As[ty][tx] = A[row * n + t * TILE + tx];
    Bs[ty][tx] = B[(t * TILE + ty) * n + col];
    __syncthreads();
#pragma unroll
    for (int k = 0; k < TILE; k++) acc += As[ty][k] * Bs[k][tx];
    __syncthreads();
  }
  C[row * n + col] = acc;
}

// ---- bitonic sort in shared memory (CUDA samples' bitonicSortShared), 1024 keys per block
VD void cmp_swap(unsigned &a, unsigned &b, unsigned dir) {
  if ((a > b) == dir) {
    unsigned t = a;
    a = b;
    b = t;
  }
}
K bitonic_shared(unsigned *keys) {
  __shared__ unsigned s[1024];
  unsigned *d = keys + blockIdx.x * 1024;
  s[threadIdx.x] = d[threadIdx.x];
  s[threadIdx.x + 512] = d[threadIdx.x + 512];
  for (unsigned size = 2; size < 1024; size <<= 1) {
    unsigned dir = (threadIdx.x & (size / 2)) != 0;
    for (unsigned stride = size / 2; stride > 0; stride >>= 1) {
      __syncthreads();
      unsigned pos = 2 * threadIdx.x - (threadIdx.x & (stride - 1));
      cmp_swap(s[pos], s[pos + stride], dir);
    }
  }
  for (unsigned stride = 512; stride > 0; stride >>= 1) {
    __syncthreads();
    unsigned pos = 2 * threadIdx.x - (threadIdx.x & (stride - 1));
    cmp_swap(s[pos], s[pos + stride], 1);
  }
  __syncthreads();
  d[threadIdx.x] = s[threadIdx.x];
  d[threadIdx.x + 512] = s[threadIdx.x + 512];
}

// ---- an unrolled sorting network: each thread sorts 8 keys of a shared tile
// (Batcher's odd-even merge network, 19 comparators), loaded and stored as
// 8 adjacent words
#define CS(i, j)                      \
  {                                   \
    unsigned x = v##i, y = v##j;      \
    v##i = umin(x, y);                \
    v##j = umax(x, y);                \
  }
K sort8_network(unsigned *keys) {
  __shared__ unsigned s[256 * 8];
  unsigned *d = keys + blockIdx.x * 2048;
  for (int k = 0; k < 8; k++) s[k * 256 + threadIdx.x] = d[k * 256 + threadIdx.x];
  __syncthreads();
  unsigned *p = s + threadIdx.x * 8;
  unsigned v0 = p[0], v1 = p[1], v2 = p[2], v3 = p[3], v4 = p[4], v5 = p[5], v6 = p[6], v7 = p[7];
  CS(0, 1) CS(2, 3) CS(4, 5) CS(6, 7)
  CS(0, 2) CS(1, 3) CS(4, 6) CS(5, 7)
  CS(1, 2) CS(5, 6)
  CS(0, 4) CS(1, 5) CS(2, 6) CS(3, 7)
  CS(2, 4) CS(3, 5)
  CS(1, 2) CS(3, 4) CS(5, 6)
  p[0] = v0; p[1] = v1; p[2] = v2; p[3] = v3; p[4] = v4; p[5] = v5; p[6] = v6; p[7] = v7;
  __syncthreads();
  for (int k = 0; k < 8; k++) d[k * 256 + threadIdx.x] = s[k * 256 + threadIdx.x];
}

// ---- inclusive scan with shuffles (CUDA samples' shfl_scan)
K scan_shfl(const int *in, int *out, int *block_sums) {
  __shared__ int sums[32];
  int id = WL_TID, lane = threadIdx.x & 31, w = threadIdx.x >> 5;
  int v = in[id];
#pragma unroll
  for (int o = 1; o < 32; o <<= 1) {
    int n = __shfl_up_sync(0xffffffffu, v, o);
    if (lane >= o) v += n;
  }
  if (lane == 31) sums[w] = v;
  __syncthreads();
  if (w == 0) {
    int nw = blockDim.x >> 5;
    int s = lane < nw ? sums[lane] : 0;
#pragma unroll
    for (int o = 1; o < 32; o <<= 1) {
      int n = __shfl_up_sync(0xffffffffu, s, o);
      if (lane >= o) s += n;
    }
    if (lane < nw) sums[lane] = s;
  }
  __syncthreads();
  if (w > 0) v += sums[w - 1];
  out[id] = v;
  if (threadIdx.x == blockDim.x - 1) block_sums[blockIdx.x] = v;
}

// ---- 256-bin histogram with shared atomics (CUDA samples' histogram256, one
// sub-histogram per block), merged into global memory with atomics whose
// result is unused
K histogram256(const unsigned *data, unsigned *hist, int n) {
  __shared__ unsigned h[256];
  for (int i = threadIdx.x; i < 256; i += blockDim.x) h[i] = 0;
  __syncthreads();
  for (int i = WL_TID; i < n; i += blockDim.x * gridDim.x) {
    unsigned x = data[i];
    atomicAdd(&h[x & 255u], 1u);
    atomicAdd(&h[(x >> 8) & 255u], 1u);
    atomicAdd(&h[(x >> 16) & 255u], 1u);
    atomicAdd(&h[x >> 24], 1u);
  }
  __syncthreads();
  for (int i = threadIdx.x; i < 256; i += blockDim.x) atomicAdd(&hist[i], h[i]);
}

// ---- Needleman-Wunsch (Rodinia's needle): the score matrix (n+1) x (n+1),
// tiles of 16 x 16 along one anti-diagonal of tiles per launch, each tile by
// anti-diagonals in shared memory
#define BS 16
K nw_init(int *score, int n, int penalty) {
  int i = WL_TID;
  if (i <= n) {
    score[i] = -i * penalty;
    score[i * (n + 1)] = -i * penalty;
  }
}
VD int max3(int a, int b, int c) { return imax(imax(a, b), c); }
K nw_diag(const int *ref, int *score, int n, int penalty, int diag) {
  __shared__ int temp[BS + 1][BS + 1];
  __shared__ int r[BS][BS];
  int tiles = n / BS, bx = blockIdx.x, by = diag - bx;
  if (by < 0 || by >= tiles) return;
  int tx = threadIdx.x, w = n + 1;
  int base = by * BS * w + bx * BS;
  for (int k = 0; k < BS; k++) r[k][tx] = ref[(by * BS + k) * n + bx * BS + tx];
  temp[tx + 1][0] = score[base + (tx + 1) * w];
  temp[0][tx + 1] = score[base + tx + 1];
  if (tx == 0) temp[0][0] = score[base];
  __syncthreads();
  for (int m = 0; m < BS; m++) {
    if (tx <= m) {
      int x = tx + 1, y = m - tx + 1;
      temp[y][x] = max3(temp[y - 1][x - 1] + r[y - 1][x - 1], temp[y][x - 1] - penalty, temp[y - 1][x] - penalty);
    }
    __syncthreads();
  }
  for (int m = BS - 2; m >= 0; m--) {
    if (tx <= m) {
      int x = tx + BS - m, y = BS - tx;
      temp[y][x] = max3(temp[y - 1][x - 1] + r[y - 1][x - 1], temp[y][x - 1] - penalty, temp[y - 1][x] - penalty);
    }
    __syncthreads();
  }
  for (int k = 0; k < BS; k++) score[base + (k + 1) * w + tx + 1] = temp[k + 1][tx + 1];
}

// ---- 1-D stencil with a shared halo (radius 3), as in NVIDIA's CUDA introduction
#define RADIUS 3
#define SBLOCK 256
K stencil_1d(const float *in, float *out) {
  __shared__ float temp[SBLOCK + 2 * RADIUS];
  int g = WL_TID, l = threadIdx.x + RADIUS;
  temp[l] = in[g + RADIUS];
  if (threadIdx.x < RADIUS) {
    temp[l - RADIUS] = in[g];
    temp[l + SBLOCK] = in[g + SBLOCK + RADIUS];
  }
  __syncthreads();
  const float wgt[2 * RADIUS + 1] = {0.0625f, 0.125f, 0.1875f, 0.25f, 0.1875f, 0.125f, 0.0625f};
  float r = 0.0f;
#pragma unroll
  for (int o = -RADIUS; o <= RADIUS; o++) r += wgt[o + RADIUS] * temp[l + o];
  out[g] = r;
}

// ---- breadth-first search, level-synchronous (Rodinia's bfs: two kernels per level)
K bfs_expand(const int *row, const int *col, int *mask, int *updating, const int *visited, int *cost, int n) {
  int v = WL_TID;
  if (v < n && mask[v]) {
    mask[v] = 0;
    for (int e = row[v]; e < row[v + 1]; e++) {
      int u = col[e];
      if (!visited[u]) {
        cost[u] = cost[v] + 1;
        updating[u] = 1;
      }
    }
  }
}
K bfs_update(int *mask, int *updating, int *visited, int *over, int n) {
  int v = WL_TID;
  if (v < n && updating[v]) {
    mask[v] = 1;
    visited[v] = 1;
    *over = 1;
    updating[v] = 0;
  }
}

// ---- single-warp probes of the hopper rules (issue 20 items 5 and 7)
// 16- and 8-byte shared loads where lanes share addresses: the lane -> element
// map of each mode (see docs/validation.md).
VD int probe_index(int l, int mode) {
  switch (mode) {
  case 0: return (l >> 4) * 2;                  // each half-warp one element
  case 1: return (l & 15) * 2;                  // lanes l and l+16 share, 2 elements apart
  case 2: return 5;                             // all lanes one element
  case 3: return l >> 1;                        // lanes n and n^1 share
  case 4: return (l & 1) | ((l >> 2) << 1);     // lanes n and n^2 share
  case 5: return (l >> 3) * 4;                  // each quarter-warp one element
  default: return l;                            // all different, contiguous
  }
}
K lds128_probe(float *out, int mode) {
  __shared__ float4 s[64];
  int l = threadIdx.x;
  s[l] = make_float4((float)l, 1.0f, 2.0f, 3.0f);
  s[l + 32] = make_float4((float)(l + 32), 1.0f, 2.0f, 3.0f);
  __syncthreads();
  float4 v = s[probe_index(l, mode)];
  out[l] = v.x + v.y + v.z + v.w;
}
K lds64_probe(float *out, int mode) {
  __shared__ float2 s[64];
  int l = threadIdx.x;
  s[l] = make_float2((float)l, 1.0f);
  s[l + 32] = make_float2((float)(l + 32), 1.0f);
  __syncthreads();
  float2 v = s[probe_index(l, mode)];
  out[l] = v.x + v.y;
}
// Global atomics: lane l adds 1 at buf[(l * stride) % span]; with `ret` the old value is stored.
K atom_probe(int *buf, int *out, int stride, int span, int ret) {
  int l = threadIdx.x;
  int *p = buf + (l * stride) % span;
  if (ret) {
    out[l] = atomicAdd(p, 1);
  } else {
    atomicAdd(p, 1);
  }
}
