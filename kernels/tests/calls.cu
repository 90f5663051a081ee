// Device-function calls: a non-inlined call in divergent code, and recursion.
#include "../prelude.h"

__device__ __noinline__ int collatz_steps(int x) {
  int n = 0;
  while (x != 1) {
    x = (x & 1) ? 3 * x + 1 : x / 2;
    n++;
  }
  return n;
}

extern "C" __global__ void call_divergent(int *out) {
  int t = WL_TID;
  int v = -1;
  if (t % 3 == 0) v = collatz_steps(t + 1);
  out[t] = v;
}

__device__ __noinline__ int fib(int n) { return n < 2 ? n : fib(n - 1) + fib(n - 2); }

extern "C" __global__ void recursive_fib(int *out) {
  int t = WL_TID;
  out[t] = fib(t % 12);
}

// A local array indexed by a thread-dependent value (lives in local memory).
extern "C" __global__ void local_array(int *out, const int *idx) {
  int buf[16];
  int t = WL_TID;
  for (int k = 0; k < 16; k++) buf[k] = t * k;
  out[t] = buf[idx[t] & 15] + buf[(idx[t] + 5) & 15];
}
