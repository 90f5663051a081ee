// Planted bug (synccheck, divergent barrier): __syncthreads() reached by half
// of a warp.
#include "../prelude.h"

extern "C" __global__ void half_barrier(int *out) {
  __shared__ int s[32];
  int t = threadIdx.x;
  s[t] = t;
  if (t < 16) __syncthreads();
  out[t] = s[31 - t];
}
