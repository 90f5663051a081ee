// Lesson 2: coalescing. Thread t reads in[t * stride]: with stride 1 a warp
// reads 128 consecutive bytes, with stride 32 every lane its own 128 bytes.
#include "../prelude.h"

extern "C" __global__ void strided_read(float *out, const float *in, int stride) {
  int t = WL_TID;
  out[t] = in[t * stride];
}
