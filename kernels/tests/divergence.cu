// Divergence and reconvergence: if/else, nested ifs, loops with break and
// continue, early return. Each thread writes one value; the counters are what
// the tests check against hand-derived numbers.
#include "../prelude.h"

// if/else on threadIdx.x % 2: both sides issue once per warp.
extern "C" __global__ void if_else(int *out) {
  int t = threadIdx.x;
  int v;
  if (t % 2) {
    v = t * 3;
  } else {
    v = t + 100;
  }
  out[WL_TID] = v;
}

// Nested: quarter of lanes in the innermost branch.
extern "C" __global__ void nested_if(int *out) {
  int t = threadIdx.x;
  int v = 0;
  if (t & 1) {
    v = 1;
    if (t & 2) {
      v = 3;
    } else {
      v = 5;
    }
  }
  out[WL_TID] = v;
}

// Data-dependent loop with break and continue: thread t sums the odd numbers
// below t, stopping at 20.
extern "C" __global__ void loop_break_continue(int *out, const int *limit) {
  int t = threadIdx.x;
  int s = 0;
  for (int k = 0; k < limit[t]; k++) {
    if (k % 2 == 0) continue;
    if (k > 20) break;
    s += k;
  }
  out[WL_TID] = s;
}

// Early return for threads >= n; the others write.
extern "C" __global__ void early_return(int *out, int n) {
  int t = WL_TID;
  if (t >= n) return;
  out[t] = t * t;
}

// A uniform branch (on a kernel parameter) never diverges.
extern "C" __global__ void uniform_branch(int *out, int flag) {
  int t = WL_TID;
  if (flag) {
    out[t] = 1;
  } else {
    out[t] = 2;
  }
}

// A 2-D grid of 2-D blocks writes its coordinates.
extern "C" __global__ void grid_2d(int *out, int width) {
  int x = blockIdx.x * blockDim.x + threadIdx.x;
  int y = blockIdx.y * blockDim.y + threadIdx.y;
  out[y * width + x] = (y << 16) | x;
}

// Runs forever (for the runaway test).
extern "C" __global__ void spin(volatile int *flag) {
  while (flag[0] == 0) {
  }
}
