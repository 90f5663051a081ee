// Planted bug (synccheck, mismatched barriers): the two warps of the CTA wait
// at two different __syncthreads() calls; the hardware barrier counts them as
// one, so the code "works", but the barriers do not match.
#include "../prelude.h"

extern "C" __global__ void two_barriers(int *out) {
  __shared__ int s[64];
  int t = threadIdx.x;
  if (t < 32) {
    s[t] = t;
    __syncthreads();
  } else {
    __syncthreads();
    s[t] = t;
  }
  out[t] = s[63 - t];
}
