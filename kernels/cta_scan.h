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

// The two CTA-level steps of a scan over many CTAs of N threads.
// cta_scan_block: element j (v, 0 beyond n) gets its exclusive offset within
// its CTA in out[j]; the CTA's total goes to sums[blockIdx.x].
template <unsigned N>
static __device__ __forceinline__ void cta_scan_block(unsigned *buf, unsigned v, unsigned j, unsigned n,
                                                      unsigned *out, unsigned *sums) {
  unsigned total;
  unsigned ex = cta_scan<N>(buf, v, &total);
  if (j < n) out[j] = ex;
  if (threadIdx.x == 0) sums[blockIdx.x] = total;
}

// cta_scan_sums, run by one CTA: the exclusive scan of the blocks CTA totals
// in place, and the grand total in sums[blocks].
template <unsigned N>
static __device__ __forceinline__ void cta_scan_sums(unsigned *buf, unsigned *sums, unsigned blocks) {
  unsigned carry = 0;
  for (unsigned base = 0; base < blocks; base += N) {
    unsigned k = base + threadIdx.x;
    unsigned v = k < blocks ? sums[k] : 0u;
    unsigned total;
    unsigned ex = cta_scan<N>(buf, v, &total);
    if (k < blocks) sums[k] = carry + ex;
    carry += total;
  }
  if (threadIdx.x == 0) sums[blocks] = carry;
}
