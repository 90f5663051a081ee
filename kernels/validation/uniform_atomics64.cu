// Probes of ptxas's warp-uniform atomic merge on 64-bit operands (issue 20;
// the 32-bit forms: uniform_atomics.cu): one kernel per form, the operation,
// whether the old value is used, where the address comes from. Launches,
// inputs and what Nsight Compute measured on an H200:
// tests/fixtures/validation/h200_uniform_atomics64.json
// (tools/device/validation.py with VALIDATION_SUITE=uniform_atomics64); the
// comparison: tests/validation_suite.rs, docs/validation.md.
#include "../prelude.h"

#if !defined(__NVCC__)
// the SDK's 64-bit atomics, which the prelude does not define
typedef unsigned long long ull;
WL_DEV ull atomicAdd(ull *a, ull v) { return __nvvm_atom_add_gen_ll((long long *)a, (long long)v); }
WL_DEV double atomicAdd(double *a, double v) { return __nvvm_atom_add_gen_d(a, v); }
WL_DEV long long atomicMin(long long *a, long long v) { return __nvvm_atom_min_gen_ll(a, v); }
WL_DEV ull atomicMin(ull *a, ull v) { return __nvvm_atom_min_gen_ull(a, v); }
WL_DEV ull atomicMax(ull *a, ull v) { return __nvvm_atom_max_gen_ull(a, v); }
WL_DEV ull atomicAnd(ull *a, ull v) { return __nvvm_atom_and_gen_ll((long long *)a, (long long)v); }
WL_DEV ull atomicOr(ull *a, ull v) { return __nvvm_atom_or_gen_ll((long long *)a, (long long)v); }
WL_DEV ull atomicXor(ull *a, ull v) { return __nvvm_atom_xor_gen_ll((long long *)a, (long long)v); }
WL_DEV ull atomicExch(ull *a, ull v) { return __nvvm_atom_xchg_gen_ll((long long *)a, (long long)v); }
WL_DEV ull atomicCAS(ull *a, ull c, ull v) { return __nvvm_atom_cas_gen_ll((long long *)a, (long long)c, (long long)v); }
#endif

#define K extern "C" __global__ void
#define T (blockIdx.x * blockDim.x + threadIdx.x)
#define C64 ((unsigned long long *)c)
#define S64 ((long long *)c)
#define OUT64 ((unsigned long long *)out)
// a 64-bit operand from two input words
#define V64 ((unsigned long long)(unsigned)in[2 * T] << 32 | (unsigned)in[2 * T + 1])

// ---- result unused
K ua64_inc(int *c, const int *in, int *out) { atomicAdd(C64, 1ull); }
K ua64_add_val(int *c, const int *in, int *out) { atomicAdd(C64, V64); }
K ua64_min(int *c, const int *in, int *out) { atomicMin(S64, (long long)V64); }
K ua64_max_u(int *c, const int *in, int *out) { atomicMax(C64, V64); }
K ua64_and(int *c, const int *in, int *out) { atomicAnd(C64, V64); }
K ua64_or(int *c, const int *in, int *out) { atomicOr(C64, V64); }
K ua64_xor(int *c, const int *in, int *out) { atomicXor(C64, V64); }
K ua64_f64(int *c, const int *in, int *out) { atomicAdd((double *)c, (double)(in[T] & 0xFFFF) / 65536.0 - 0.5); }
K ua64_block(int *c, const int *in, int *out) { atomicAdd(C64 + blockIdx.x, 1ull); }
K ua64_cond(int *c, const int *in, int *out) {
  if (in[T] & 1) atomicAdd(C64, 1ull);
}
K ua64_lane(int *c, const int *in, int *out) { atomicAdd(C64 + (threadIdx.x & 1), 1ull); }
K ua64_exch(int *c, const int *in, int *out) { atomicExch(C64, V64); }

// ---- result used
K ua64_inc_ret(int *c, const int *in, int *out) { OUT64[T] = atomicAdd(C64, 1ull); }
K ua64_add_val_ret(int *c, const int *in, int *out) { OUT64[T] = atomicAdd(C64, V64 & 0xFFFFFFFFFull); }
K ua64_min_ret(int *c, const int *in, int *out) { OUT64[T] = atomicMin(C64, V64); }
K ua64_cas(int *c, const int *in, int *out) { OUT64[T] = atomicCAS(C64, 0ull, V64); }
