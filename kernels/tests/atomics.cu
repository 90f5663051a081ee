// Atomics: contention on one address, every operation, and a persistent-threads
// job queue whose CTAs communicate through a global atomic counter.
#include "../prelude.h"

// Every thread adds 1 to counter[0] and records the value it saw.
extern "C" __global__ void contention(unsigned *counter, unsigned *seen) {
  seen[WL_TID] = atomicAdd(counter, 1u);
}

// Float atomic adds: the sum's rounding depends on the order, which warplight fixes.
extern "C" __global__ void float_sum(float *sum, const float *in) {
  atomicAdd(sum, in[WL_TID]);
}

// All operations on cells[0..9]; thread t uses operand t.
extern "C" __global__ void all_ops(int *cells, int *old) {
  int t = WL_TID;
  old[10 * t + 0] = atomicAdd(&cells[0], t);
  old[10 * t + 1] = atomicMin(&cells[1], 1000 - t);
  old[10 * t + 2] = atomicMax(&cells[2], t);
  old[10 * t + 3] = (int)atomicInc((unsigned *)&cells[3], 7u);
  old[10 * t + 4] = (int)atomicDec((unsigned *)&cells[4], 5u);
  old[10 * t + 5] = atomicExch(&cells[5], t);
  old[10 * t + 6] = atomicCAS(&cells[6], t - 1, t);
  old[10 * t + 7] = atomicAnd(&cells[7], ~(1 << (t & 31)));
  old[10 * t + 8] = atomicOr(&cells[8], 1 << (t & 31));
  old[10 * t + 9] = atomicXor(&cells[9], t);
}

// Persistent threads: each warp takes blocks of 32 consecutive items from a
// global queue until it is empty; item i gets out[i] = i * i + worker id bits.
extern "C" __global__ void job_queue(unsigned *next, int *out, int *owner, int items) {
  int lane = threadIdx.x & 31;
  int warp_global = (blockIdx.x * blockDim.x + threadIdx.x) >> 5;
  while (true) {
    unsigned base = 0;
    if (lane == 0) base = atomicAdd(next, 32u);
    base = __shfl_sync(0xffffffffu, (int)base, 0);
    if (base >= (unsigned)items) break;
    int i = base + lane;
    if (i < items) {
      out[i] = i * i;
      owner[i] = warp_global;
    }
  }
}
