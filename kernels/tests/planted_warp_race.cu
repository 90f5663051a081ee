// Planted bug (racecheck, within one warp): the lanes of a warp swap values
// with their neighbour (lane ^ 1) through shared memory. `warp_swap_synced`
// separates the steps with __syncwarp() and is race-free;
// `warp_swap_nosync` is the same without it: lanes of one warp need not run
// in lockstep (Volta and later), so its reads and writes race.
#include "../prelude.h"

extern "C" __global__ void warp_swap_synced(int *out) {
  __shared__ int s[64];
  int t = threadIdx.x;
  s[t] = 3 * t + blockIdx.x;
  __syncwarp();
  int v = s[t ^ 1];
  __syncwarp();
  s[t] = v + t;
  __syncwarp();
  out[64 * blockIdx.x + t] = s[t ^ 1];
}

extern "C" __global__ void warp_swap_nosync(int *out) {
  __shared__ int s[64];
  int t = threadIdx.x;
  s[t] = 3 * t + blockIdx.x;
  int v = s[t ^ 1];
  s[t] = v + t;
  out[64 * blockIdx.x + t] = s[t ^ 1];
}
