// Lesson 5: a block reduction with barriers, in two orders. Each round adds
// pairs `d` apart and halves the partial sums; a barrier separates rounds.
//   interleaved = 1: thread t adds if t is a multiple of 2d: in every warp
//                    some lanes work and some idle (divergence);
//   interleaved = 0: the first 128/d threads add, at word 2dt: whole warps
//                    idle instead, but the lanes' words are 2d apart (bank conflicts).
#include "../prelude.h"

extern "C" __global__ void block_sum(int *sums, const int *in, int interleaved) {
  __shared__ int part[256];
  int t = threadIdx.x;
  part[t] = in[256 * blockIdx.x + t];
  __syncthreads();
  for (int d = 1; d < 256; d *= 2) {
    if (interleaved) {
      if (t % (2 * d) == 0) part[t] += part[t + d];
    } else {
      int k = 2 * d * t;
      if (k < 256) part[k] += part[k + d];
    }
    __syncthreads();
  }
  if (t == 0) sums[blockIdx.x] = part[0];
}
