// Planted bug (a global-memory race within one launch): thread 0 of every CTA
// adds its index to out[0] with a plain load and store, not atomicAdd.
#include "../prelude.h"

extern "C" __global__ void global_total(int *out) {
  if (threadIdx.x == 0) out[0] = out[0] + (int)blockIdx.x + 1;
}
