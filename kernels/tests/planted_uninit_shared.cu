// Planted bug (initcheck, shared): only the first warp fills the tile, and
// every thread reads the mirrored word, so the first warp reads words nobody wrote.
#include "../prelude.h"

extern "C" __global__ void mirror(int *out) {
  __shared__ int tile[64];
  int t = threadIdx.x;
  if (t < 32) tile[t] = t;
  __syncthreads();
  out[t] = tile[63 - t];
}
