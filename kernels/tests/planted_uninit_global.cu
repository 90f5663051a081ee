// Planted bug (initcheck, global): `in` is allocated and never written before
// the launch (cudaMalloc without cudaMemcpy; `--uninit in` in warplight).
#include "../prelude.h"

extern "C" __global__ void add_one(int *out, const int *in) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  out[i] = in[i] + 1;
}
