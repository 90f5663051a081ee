// Probes of ptxas's warp-uniform atomic merge (issue 20): a global atomic
// whose address ptxas proves the same for every lane of a warp is done once
// per warp, by one lane, with the warp's combined operand (VOTEU.ANY, POPC or
// REDUX, then one lane's RED or ATOM). Each kernel is one form: the operation,
// whether the old value is used, where the address comes from. Launches,
// inputs and what Nsight Compute measured on an H200:
// tests/fixtures/validation/h200_uniform_atomics.json
// (tools/device/validation.py with VALIDATION_SUITE=uniform_atomics); the
// comparison: tests/validation_suite.rs, docs/validation.md.
// Also: `set` on packed halves (bit for bit).
#include "../prelude.h"

#define K extern "C" __global__ void
#define T (blockIdx.x * blockDim.x + threadIdx.x)

// ---- result unused: a reduction
K ua_inc(int *c, const int *in, int *out) { atomicAdd(c, 1); }
K ua_add_val(int *c, const int *in, int *out) { atomicAdd(c, in[T]); }
K ua_min(int *c, const int *in, int *out) { atomicMin(c, in[T]); }
K ua_max_u(int *c, const int *in, int *out) { atomicMax((unsigned *)c, (unsigned)in[T]); }
K ua_or(int *c, const int *in, int *out) { atomicOr(c, in[T]); }
K ua_xor(int *c, const int *in, int *out) { atomicXor(c, in[T]); }
K ua_f32(int *c, const int *in, int *out) { atomicAdd((float *)c, __int_as_float(in[T])); }
K ua_inc_wrap(int *c, const int *in, int *out) { atomicInc((unsigned *)c, 1000u); }
K ua_exch(int *c, const int *in, int *out) { atomicExch(c, in[T]); }
// the address from the block index, a loop counter, a loaded value
K ua_block(int *c, const int *in, int *out) { atomicAdd(c + blockIdx.x, 1); }
K ua_loop(int *c, const int *in, int *out) {
  for (int i = 0; i < 4; i++) atomicAdd(c + i, in[T] & 7);
}
K ua_loaded(int *c, const int *in, int *out) { atomicAdd(c + (in[0] & 3), 1); }
// divergent: only lanes whose input is odd
K ua_cond(int *c, const int *in, int *out) {
  if (in[T] & 1) atomicAdd(c, 1);
}
// not uniform: lane-dependent addresses
K ua_lane(int *c, const int *in, int *out) { atomicAdd(c + (threadIdx.x & 1), 1); }
K ua_warp(int *c, const int *in, int *out) { atomicAdd(c + threadIdx.x / 32, 1); }

// ---- result used
K ua_inc_ret(int *c, const int *in, int *out) { out[T] = atomicAdd(c, 1); }
K ua_add_val_ret(int *c, const int *in, int *out) { out[T] = atomicAdd(c, in[T] & 0xFFFF); }
K ua_min_ret(int *c, const int *in, int *out) { out[T] = atomicMin(c, in[T]); }
K ua_cond_ret(int *c, const int *in, int *out) {
  if (in[T] & 1) out[T] = atomicAdd(c, 1);
}

// ---- set on packed halves: every comparison of the halves of in[2t] and in[2t+1]
#define SETX2(name, x)                                                                       \
  K name(int *c, const int *in, int *out) {                                                   \
    unsigned a = in[2 * T], b = in[2 * T + 1], r0, r1, r2, r3, r4;                            \
    asm("set.lt." x "." x " %0, %1, %2;" : "=r"(r0) : "r"(a), "r"(b));                             \
    asm("set.equ.u32." x " %0, %1, %2;" : "=r"(r1) : "r"(a), "r"(b));                        \
    asm("set.ge.s32." x " %0, %1, %2;" : "=r"(r2) : "r"(a), "r"(b));                         \
    asm("set.nan.u32." x " %0, %1, %2;" : "=r"(r3) : "r"(a), "r"(b));                            \
    asm("{.reg .pred p; setp.ne.u32 p, %3, 0; set.gt.and.u32." x " %0, %1, %2, p;}"              \
        : "=r"(r4) : "r"(a), "r"(b), "r"(a & 1));                                             \
    out[5 * T] = r0, out[5 * T + 1] = r1, out[5 * T + 2] = r2, out[5 * T + 3] = r3;           \
    out[5 * T + 4] = r4;                                                                      \
  }
SETX2(set_f16x2, "f16x2")
SETX2(set_bf16x2, "bf16x2")
