// Lesson 4: warp votes and shuffles act on the 32 lanes of one warp, never
// on the whole CTA.
#include "../prelude.h"

// Per warp: which lanes hold a value above 50 (a ballot), and the warp's sum
// by a shuffle tree (lane 0 ends with it).
extern "C" __global__ void vote_and_sum(unsigned *ballots, int *sums, const int *in) {
  int t = threadIdx.x;
  int v = in[t];
  unsigned above = __ballot_sync(0xffffffffu, v > 50);
  int s = v;
  for (int d = 16; d > 0; d /= 2) s += __shfl_down_sync(0xffffffffu, s, d);
  if (t % 32 == 0) {
    ballots[t / 32] = above;
    sums[t / 32] = s;
  }
}
