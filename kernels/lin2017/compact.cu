// Thesis 003 (Lin 2017), §6.3: thread compaction between two levels of the
// inner loop (003:L501-536). The thesis calls thrust::remove_if on the array
// of per-path states with the predicate !active (003:L534); this is the same
// stream compaction written out as its three kernels, flag - scan - scatter:
//
//   compact_flag      flags[j] = state j is active (bit PATH_ACTIVE of its last word)
//   compact_scan      per CTA of COMPACT_THREADS: the exclusive scan of the
//                     flags (Hillis-Steele in shared memory, kernels/cta_scan.h)
//                     and the CTA's total
//   compact_scan_sums one CTA: the exclusive scan of the CTA totals, and the
//                     grand total (the active paths) in sums[blocks]
//   compact_scatter   the active states, in order, to their scanned places
//
// A state is 4 float4 (64 bytes, kernels/lin2017/path.cu's layout). The
// compaction is stable: the active states keep their order.
#include "../prelude.h"
#include "cta_scan.h"

#define COMPACT_THREADS 256
#define PATH_ACTIVE 2u   // as kernels/lin2017/path.cu

extern "C" __global__ void compact_flag(const float4 *states, unsigned n, unsigned *flags) {
  unsigned j = WL_TID;
  if (j >= n) return;
  flags[j] = (__float_as_uint(states[4 * j + 3].w) & PATH_ACTIVE) != 0u ? 1u : 0u;
}

extern "C" __global__ void compact_scan(const unsigned *flags, unsigned n, unsigned *offsets, unsigned *sums) {
  __shared__ unsigned buf[COMPACT_THREADS];
  unsigned j = WL_TID;
  cta_scan_block<COMPACT_THREADS>(buf, j < n ? flags[j] : 0u, j, n, offsets, sums);
}

extern "C" __global__ void compact_scan_sums(unsigned *sums, unsigned blocks) {
  __shared__ unsigned buf[COMPACT_THREADS];
  cta_scan_sums<COMPACT_THREADS>(buf, sums, blocks);
}

extern "C" __global__ void compact_scatter(const float4 *in, const unsigned *flags, const unsigned *offsets,
                                           const unsigned *sums, unsigned n, float4 *out) {
  unsigned j = WL_TID;
  if (j >= n || flags[j] == 0u) return;
  unsigned k = sums[blockIdx.x] + offsets[j];
  const float4 *src = in + 4 * j;
  float4 *dst = out + 4 * k;
  dst[0] = src[0];
  dst[1] = src[1];
  dst[2] = src[2];
  dst[3] = src[3];
}

// The 3-way Fresnel regroup (003:L536, kernels/lin2017/path.cu's regroup_*):
// states of REGROUP_STATE float4, the next hit's branch in the fifth's z.
// regroup_flag flags the active states of one branch (REGROUP_ANY: every
// active state, plain compaction); regroup_scatter appends them, in order,
// at out's state `base` (the states the earlier compactions of the level
// placed).
#define REGROUP_STATE 5
#define REGROUP_ANY 0xffffffffu

extern "C" __global__ void regroup_flag(const float4 *states, unsigned n, unsigned branch, unsigned *flags) {
  unsigned j = WL_TID;
  if (j >= n) return;
  const float4 *st = states + REGROUP_STATE * j;
  bool active = (__float_as_uint(st[3].w) & PATH_ACTIVE) != 0u;
  flags[j] = active && (branch == REGROUP_ANY || __float_as_uint(st[4].z) == branch) ? 1u : 0u;
}

extern "C" __global__ void regroup_scatter(const float4 *in, const unsigned *flags, const unsigned *offsets,
                                           const unsigned *sums, unsigned n, unsigned base, float4 *out) {
  unsigned j = WL_TID;
  if (j >= n || flags[j] == 0u) return;
  unsigned k = base + sums[blockIdx.x] + offsets[j];
  const float4 *src = in + REGROUP_STATE * j;
  float4 *dst = out + REGROUP_STATE * k;
  for (int w = 0; w < REGROUP_STATE; w++) dst[w] = src[w];
}
