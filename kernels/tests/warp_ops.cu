// Warp-level operations: votes and shuffles act per warp, never per CTA.
#include "../prelude.h"

// Each thread writes its warp's ballot of (t % 3 == 0), all(t < limit), any(t == probe).
extern "C" __global__ void votes(unsigned *out, int limit, int probe) {
  int t = threadIdx.x;
  unsigned b = __ballot_sync(0xffffffffu, t % 3 == 0);
  int all = __all_sync(0xffffffffu, t < limit);
  int any = __any_sync(0xffffffffu, t == probe);
  out[3 * t] = b;
  out[3 * t + 1] = all;
  out[3 * t + 2] = any;
}

// Shuffles: idx (broadcast lane 5), up by 1, down by 2, xor 1, and a warp sum.
extern "C" __global__ void shuffles(int *out, const int *in) {
  int t = threadIdx.x;
  int v = in[t];
  int a = __shfl_sync(0xffffffffu, v, 5);
  int b = __shfl_up_sync(0xffffffffu, v, 1);
  int c = __shfl_down_sync(0xffffffffu, v, 2);
  int d = __shfl_xor_sync(0xffffffffu, v, 1);
  int s = v;
  for (int o = 16; o > 0; o >>= 1) s += __shfl_xor_sync(0xffffffffu, s, o);
  out[5 * t] = a;
  out[5 * t + 1] = b;
  out[5 * t + 2] = c;
  out[5 * t + 3] = d;
  out[5 * t + 4] = s;
}

// Ballot inside a divergent branch covers only the active lanes.
extern "C" __global__ void ballot_divergent(unsigned *out) {
  int t = threadIdx.x;
  unsigned b = 0;
  if (t & 1) b = __activemask();
  out[t] = b;
}
