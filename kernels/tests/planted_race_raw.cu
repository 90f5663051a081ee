// Planted bug (racecheck, read-after-write and write-after-read across warps):
// lesson 5's interleaved reduction (kernels/lessons/reduction.cu) without the
// __syncthreads() between rounds. Under warplight's lockstep schedule the sums
// come out right anyway; `--check racecheck` reports the hazards and
// `--schedule random --seed N` shows the sums change.
#include "../prelude.h"

extern "C" __global__ void block_sum_nosync(int *sums, const int *in) {
  __shared__ int part[256];
  int t = threadIdx.x;
  part[t] = in[256 * blockIdx.x + t];
  __syncthreads();
  for (int d = 1; d < 256; d *= 2) {
    if (t % (2 * d) == 0) part[t] += part[t + d];
  }
  __syncthreads();
  if (t == 0) sums[blockIdx.x] = part[0];
}
