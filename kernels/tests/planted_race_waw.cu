// Planted bug (racecheck, write-after-write across warps): every thread writes
// the one shared word, so which value thread 0 reads depends on the order.
#include "../prelude.h"

extern "C" __global__ void last_writer(int *out) {
  __shared__ int winner;
  winner = threadIdx.x;
  __syncthreads();
  if (threadIdx.x == 0) out[blockIdx.x] = winner;
}
