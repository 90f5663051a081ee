// CUDA intrinsics that become the newer PTX instructions: warp reductions
// (redux.sync), matches (match.sync), CTA barrier reductions (bar.red),
// byte permutes (prmt) and 64-bit bit counts, written as ordinary CUDA.
// out[i * 14 + k] is value k of thread i.
#include "../prelude.h"

extern "C" __global__ void intrinsics(unsigned *out, const unsigned *in, int n) {
  int i = WL_TID;
  unsigned x = i < n ? in[i] : 0;
  unsigned long long w = ((unsigned long long)x << 32) | (x * 2654435761u);
  int cnt = __syncthreads_count(x & 1);
  int any = __syncthreads_or(x % 97 == 0);
  int all = __syncthreads_and(x != 12345);
  if (i < n) {
    unsigned *o = out + i * 14;
    int pred = 0;
    o[0] = __reduce_add_sync(0xffffffffu, x);
    o[1] = __reduce_min_sync(0xffffffffu, x);
    o[2] = (unsigned)__reduce_max_sync(0xffffffffu, (int)x);
    o[3] = __reduce_xor_sync(0xffffffffu, x) | __reduce_and_sync(0xffffffffu, x | 0xff00u);
    o[4] = __match_any_sync(0xffffffffu, x & 3);
    o[5] = __match_all_sync(0xffffffffu, i < 128 ? 7u : x & 1, &pred) ^ (unsigned)pred;
    o[6] = (unsigned)cnt;
    o[7] = (unsigned)(any | all << 1);
    o[8] = __byte_perm(x, ~x, (x >> 16) & 0x7777);
    o[9] = (unsigned)__popcll(w);
    o[10] = (unsigned)__clzll((long long)(w >> (x & 63)));
    unsigned long long r = __brevll(w);
    o[11] = (unsigned)r;
    o[12] = (unsigned)(r >> 32);
    o[13] = (x & 1) ? __activemask() : 0;
  }
}
