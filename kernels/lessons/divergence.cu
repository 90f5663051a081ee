// Lesson 1: divergence and reconvergence.
#include "../prelude.h"

// Odd lanes take the `if` side, even lanes the `else` side: the warp runs
// both sides, one after the other, each with half its lanes. The sides
// store different numbers of values, so the compiler keeps a branch (with
// one store each it would merge them into one store through a select).
extern "C" __global__ void odd_even(int *odd, int *even, int *all) {
  int t = threadIdx.x;
  if (t % 2) {
    odd[t] = t * 3;
    odd[t + 32] = t;
  } else {
    even[t] = t + 100;
  }
  all[t] = t;  // every lane again: the warp has reconverged
}

// Lane t runs the loop t % 4 + 1 times: the warp keeps looping until its
// slowest lane is done, with fewer lanes each time round.
extern "C" __global__ void uneven_loop(int *out, const int *in) {
  int t = threadIdx.x, sum = 0;
  for (int k = 0; k <= t % 4; k++) sum += in[32 * k + t];
  out[t] = sum;
}
