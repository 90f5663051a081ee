// Shared memory with barriers: a tree reduction, a tiled matrix multiply, and
// a barrier in divergent code (a fault).
#include "../prelude.h"

// Sum of each CTA's 256 inputs.
extern "C" __global__ void reduce_sum(int *out, const int *in) {
  __shared__ int s[256];
  int t = threadIdx.x;
  s[t] = in[blockIdx.x * 256 + t];
  __syncthreads();
  for (int stride = 128; stride > 0; stride >>= 1) {
    if (t < stride) s[t] += s[t + stride];
    __syncthreads();
  }
  if (t == 0) out[blockIdx.x] = s[0];
}

#define TILE 16
// C = A * B for n x n matrices (n a multiple of 16), 16 x 16 blocks.
extern "C" __global__ void matmul_tiled(float *c, const float *a, const float *b, int n) {
  __shared__ float ta[TILE][TILE];
  __shared__ float tb[TILE][TILE];
  int row = blockIdx.y * TILE + threadIdx.y, col = blockIdx.x * TILE + threadIdx.x;
  float acc = 0.0f;
  for (int k0 = 0; k0 < n; k0 += TILE) {
    ta[threadIdx.y][threadIdx.x] = a[row * n + k0 + threadIdx.x];
    tb[threadIdx.y][threadIdx.x] = b[(k0 + threadIdx.y) * n + col];
    __syncthreads();
    for (int k = 0; k < TILE; k++) acc = __fmaf_rn(ta[threadIdx.y][k], tb[k][threadIdx.x], acc);
    __syncthreads();
  }
  c[row * n + col] = acc;
}

// Shared-memory histogram with shared atomics, merged into global with global atomics.
extern "C" __global__ void histogram(unsigned *bins, const unsigned *data, int n) {
  __shared__ unsigned h[16];
  int t = threadIdx.x;
  if (t < 16) h[t] = 0;
  __syncthreads();
  for (int i = WL_TID; i < n; i += blockDim.x * gridDim.x) atomicAdd(&h[data[i] & 15], 1u);
  __syncthreads();
  if (t < 16) atomicAdd(&bins[t], h[t]);
}

// Dynamic shared memory: reverse each CTA's block of the input.
extern "C" __global__ void reverse_dynamic(int *out, const int *in) {
  extern __shared__ int buf[];
  int t = threadIdx.x, n = blockDim.x;
  buf[t] = in[blockIdx.x * n + t];
  __syncthreads();
  out[blockIdx.x * n + t] = buf[n - 1 - t];
}

// __syncthreads inside a branch that splits a warp: undefined on a GPU, a fault here.
extern "C" __global__ void divergent_barrier(int *out) {
  __shared__ int s[64];
  int t = threadIdx.x;
  if (t < 8) {
    s[t] = t;
    __syncthreads();
  }
  out[t] = s[t % 8];
}
