// Kernels that measure the emulator's speed (benches/emulator.rs).
#include "../prelude.h"

// ALU-bound: a dependent chain of fma, xor and shifts per thread.
extern "C" __global__ void alu_loop(float *out, int iters) {
  unsigned x = WL_TID * 2654435761u;
  float f = (float)threadIdx.x;
  for (int k = 0; k < iters; k++) {
    f = __fmaf_rn(f, 1.0001f, 0.5f);
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
  }
  out[WL_TID] = f + (float)(x & 0xff);
}

// Memory-bound: strided reads and a write per iteration.
extern "C" __global__ void memory_stride(float *out, const float *in, int n, int stride, int iters) {
  int t = WL_TID;
  float acc = 0.0f;
  for (int k = 0; k < iters; k++) acc += in[(t * stride + k * 97) % n];
  out[t] = acc;
}

// Divergent: data-dependent trip counts and branches.
extern "C" __global__ void divergent(int *out, int iters) {
  int t = WL_TID;
  int x = t, s = 0;
  for (int k = 0; k < iters + (t % 7); k++) {
    if (x & 1) {
      x = 3 * x + 1;
      s += 2;
    } else {
      x >>= 1;
      s -= 1;
    }
  }
  out[t] = s + x;
}
