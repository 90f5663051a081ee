// Planted bug (memcheck, out of bounds): one thread per element reads its right
// neighbour, so the last thread reads data[n], one past the end.
#include "../prelude.h"

extern "C" __global__ void shift_left(int *out, const int *data) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  out[i] = data[i + 1];
}
