// An exclusive scan over one CTA of N threads, all present: Hillis-Steele in
// the shared array buf (N words). Returns the sum of v over the threads
// before this one, and the CTA's total through *total. Shared by
// kernels/lin2017/compact.cu (stream compaction) and
// kernels/fabianowski2011/lbvh.cu (the radix sort's scan of digit counts).
#pragma once

template <unsigned N>
static __device__ __forceinline__ unsigned cta_scan(unsigned *buf, unsigned v, unsigned *total) {
  unsigned t = threadIdx.x;
  buf[t] = v;
  __syncthreads();
  for (unsigned off = 1; off < N; off <<= 1) {
    unsigned x = t >= off ? buf[t - off] : 0u;
    __syncthreads();
    buf[t] += x;
    __syncthreads();
  }
  unsigned inclusive = buf[t];
  *total = buf[N - 1];
  __syncthreads();
  return inclusive - v;
}
