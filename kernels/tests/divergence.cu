// Divergence and reconvergence: if/else, nested ifs, loops with break and
// continue, early return. Each thread writes one value; the counters are what
// the tests check against hand-derived numbers.
#include "../prelude.h"

// if/else on threadIdx.x % 2: both sides issue once per warp. The sides store
// to different arrays so that neither compiler turns the branch into a select.
extern "C" __global__ void if_else(int *odd, int *even) {
  int t = threadIdx.x, i = WL_TID;
  if (t % 2) {
    odd[i] = t * 3;
    odd[i + 1024] = t;
  } else {
    even[i] = t + 100;
    even[i + 1024] = -t;
  }
}

// Nested: half the lanes take the outer branch, a quarter each inner side.
extern "C" __global__ void nested_if(int *a, int *b, int *c) {
  int t = threadIdx.x, i = WL_TID;
  if (t & 1) {
    a[i] = 1;
    a[i + 1024] = t;
    if (t & 2) {
      b[i] = 3;
      b[i + 1024] = t;
    } else {
      c[i] = 5;
      c[i + 1024] = t;
    }
  }
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
extern "C" __global__ void uniform_branch(int *yes, int *no, int flag) {
  int t = WL_TID;
  if (flag) {
    yes[t] = 1;
    yes[t + 1024] = t;
  } else {
    no[t] = 2;
    no[t + 1024] = t;
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
