// Memory spaces and widths: vector loads, constant memory, a global variable,
// double precision, partial warps, and an out-of-bounds access (a fault).
#include "../prelude.h"

struct alignas(16) F4 { float x, y, z, w; };

// out[i] = (in[i].w, in[i].z, in[i].y, in[i].x) with 128-bit loads and stores.
extern "C" __global__ void vec4_swizzle(F4 *out, const F4 *in) {
  F4 v = in[WL_TID];
  F4 r = {v.w, v.z, v.y, v.x};
  out[WL_TID] = r;
}

__constant__ int lut[8] = {1, 1, 2, 6, 24, 120, 720, 5040};
__device__ int bias = 1000;

extern "C" __global__ void const_and_global(int *out) {
  int t = WL_TID;
  out[t] = lut[t & 7] + bias;
}

extern "C" __global__ void fp64_poly(double *out, const double *x) {
  double v = x[WL_TID];
  out[WL_TID] = __fma_rn(__fma_rn(v, v, -2.0), v, 0.5) / 3.0 + sqrt(v * v + 1.0);
}

// 50 threads per CTA: the second warp has 18 lanes.
extern "C" __global__ void partial_warp(int *out) {
  out[blockIdx.x * blockDim.x + threadIdx.x] = threadIdx.x + 7;
}

// Thread 37 writes past the end of a 40-element buffer.
extern "C" __global__ void out_of_bounds(int *out) {
  int t = WL_TID;
  out[t == 37 ? 4000 : t] = t;
}

// Reads through the read-only (texture) path.
extern "C" __global__ void ldg_gather(float *out, const float *in, const int *idx) {
  int t = WL_TID;
  out[t] = __ldg(&in[__ldg(&idx[t])]);
}
