// Shared loads at a base stepped round a loop (issue 20, item 6): does ptxas
// merge adjacent words read through an address that is a loop induction
// variable? The vectorisation pass (src/model/vectorize.rs) assumes not, from
// needleman_wunsch alone; these kernels are a second, independent check
// (tools/device/issue20_s8_stepped.sh: their SASS on the H200's ptxas).
//   stepped_pairs: p[0], p[1] with p = s + 2 tid stepped by 2 words (8-aligned)
//   stepped_quads: p[0..3] with p = s + 4 tid stepped by 4 words (16-aligned)
//   fixed_pairs:   the same pairs at a base defined once, offsets unrolled (control)
#include "../prelude.h"

#define N 256

extern "C" __global__ void stepped_pairs(const float *in, float *out, int n) {
  __shared__ float s[2 * N + 64] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 64; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 2 * t;
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    acc += p[0] * p[1];
    p += 2;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}

extern "C" __global__ void stepped_quads(const float *in, float *out, int n) {
  __shared__ float s[4 * N + 128] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 4 * N + 128; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 4 * t;
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    acc += (p[0] - p[1]) * (p[2] + p[3]);
    p += 4;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}

extern "C" __global__ void fixed_pairs(const float *in, float *out) {
  __shared__ float s[2 * N + 64] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 64; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 2 * t;
  float acc = 0.0f;
#pragma unroll
  for (int k = 0; k < 8; k++) acc += p[2 * k] * p[2 * k + 1];
  out[blockIdx.x * blockDim.x + t] = acc;
}

// What sets needleman_wunsch's loop apart, one difference at a time (each
// with p stepped round a `#pragma unroll 1` loop, pairs 8-byte aligned):
//   stepped_sub:     p = s + 2 (N - 1 - tid), a base that subtracts the thread index
//   stepped_guarded: the pair read under `if (tid <= k)`, a barrier each iteration
//   stepped_wide:    p stepped by 34 words (136 bytes, as needleman_wunsch's 17 x 4)
//   stepped_split:   another shared load between the pair's two words
//   stepped_odd:     the pair at p - 1, p with p = s + 2 tid + 1 (a base 4 mod 8)
extern "C" __global__ void stepped_sub(const float *in, float *out, int n) {
  __shared__ float s[2 * N + 64] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 64; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 2 * (N - 1 - t);
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    acc += p[0] * p[1];
    p += 2;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}

extern "C" __global__ void stepped_guarded(const float *in, float *out, int n) {
  __shared__ float s[2 * N + 64] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 64; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 2 * t;
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    if (t <= k) acc += p[0] * p[1];
    __syncthreads();
    p += 2;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}

extern "C" __global__ void stepped_wide(const float *in, float *out, int n) {
  __shared__ float s[2 * N + 34 * 32] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 34 * 32; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 2 * t;
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    acc += p[0] * p[1];
    p += 34;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}

extern "C" __global__ void stepped_split(const float *in, float *out, int n) {
  __shared__ float s[2 * N + 64] __attribute__((aligned(16)));
  __shared__ float q[N + 64];
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 64; i += blockDim.x) s[i] = in[i];
  for (int i = t; i < N + 64; i += blockDim.x) q[i] = in[i + 1];
  __syncthreads();
  const float *p = s + 2 * t;
  const float *o = q + t;
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    float a = p[0];
    float b = o[0];
    acc += (a + b) * p[1];
    p += 2;
    o += 1;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}

extern "C" __global__ void stepped_odd(const float *in, float *out, int n) {
  __shared__ float s[2 * N + 64] __attribute__((aligned(16)));
  int t = threadIdx.x;
  for (int i = t; i < 2 * N + 64; i += blockDim.x) s[i] = in[i];
  __syncthreads();
  const float *p = s + 2 * t + 1;
  float acc = 0.0f;
#pragma unroll 1
  for (int k = 0; k < n; k++) {
    acc += p[-1] * p[0];
    p += 2;
  }
  out[blockIdx.x * blockDim.x + t] = acc;
}
