// Lesson 3: shared-memory bank conflicts and padding. A 32 x 32 tile is
// transposed through shared memory: rows are written, columns read. With a
// row pitch of 32 words a column lies in one bank; a pitch of 33 (one word
// of padding per row) spreads it over all banks.
#include "../prelude.h"

extern "C" __global__ void transpose(float *out, const float *in, int pad) {
  __shared__ float tile[32 * 33];
  int x = threadIdx.x, y = threadIdx.y;
  int pitch = 32 + pad;
  tile[y * pitch + x] = in[32 * y + x];   // a row: consecutive words
  __syncthreads();
  out[32 * y + x] = tile[x * pitch + y];  // a column: lanes `pitch` words apart
}
