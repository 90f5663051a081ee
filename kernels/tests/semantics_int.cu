// Integer instruction semantics at edge values: one PTX instruction per kernel,
// written as inline PTX so that neither compiler folds or rewrites it.
// out[i] = OP(a[i], b[i]) for i < n.
#include "../prelude.h"

#define BIN(name, op)                                                              \
  extern "C" __global__ void name(unsigned *out, const unsigned *a,               \
                                  const unsigned *b, int n) {                      \
    int i = WL_TID;                                                                \
    if (i < n) {                                                                   \
      unsigned d;                                                                  \
      asm volatile(op " %0, %1, %2;" : "=r"(d) : "r"(a[i]), "r"(b[i]));            \
      out[i] = d;                                                                  \
    }                                                                              \
  }
#define UN(name, op)                                                               \
  extern "C" __global__ void name(unsigned *out, const unsigned *a,               \
                                  const unsigned *b, int n) {                      \
    int i = WL_TID;                                                                \
    if (i < n) {                                                                   \
      unsigned d;                                                                  \
      asm volatile(op " %0, %1;" : "=r"(d) : "r"(a[i]));                           \
      out[i] = d;                                                                  \
    }                                                                              \
  }

BIN(sem_shl_b32, "shl.b32")
BIN(sem_shr_u32, "shr.u32")
BIN(sem_shr_s32, "shr.s32")
BIN(sem_div_u32, "div.u32")
BIN(sem_rem_u32, "rem.u32")
BIN(sem_div_s32, "div.s32")
BIN(sem_rem_s32, "rem.s32")
BIN(sem_mul_hi_u32, "mul.hi.u32")
BIN(sem_mul_hi_s32, "mul.hi.s32")
BIN(sem_mul24_lo_s32, "mul24.lo.s32")
BIN(sem_mul24_hi_u32, "mul24.hi.u32")
BIN(sem_min_s32, "min.s32")
BIN(sem_max_u32, "max.u32")
BIN(sem_add_sat_s32, "add.sat.s32")
BIN(sem_sub_sat_s32, "sub.sat.s32")
UN(sem_popc_b32, "popc.b32")
UN(sem_clz_b32, "clz.b32")
UN(sem_brev_b32, "brev.b32")
UN(sem_abs_s32, "abs.s32")
UN(sem_neg_s32, "neg.s32")
UN(sem_cnot_b32, "cnot.b32")

// bfe.u32 / bfe.s32 d, a, pos, len with pos = b & 0xff, len = b >> 8
extern "C" __global__ void sem_bfe_s32(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned d, pos = b[i] & 0xff, len = (b[i] >> 8) & 0xff;
    asm volatile("bfe.s32 %0, %1, %2, %3;" : "=r"(d) : "r"(a[i]), "r"(pos), "r"(len));
    out[i] = d;
  }
}
// bfi.b32 d, a, b, pos, len: insert a into b
extern "C" __global__ void sem_bfi_b32(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned d, pos = i & 31, len = (i * 7) & 63;
    asm volatile("bfi.b32 %0, %1, %2, %3, %4;" : "=r"(d) : "r"(a[i]), "r"(b[i]), "r"(pos), "r"(len));
    out[i] = d;
  }
}
// prmt.b32 d, a, b, selector
extern "C" __global__ void sem_prmt_b32(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned d, s = (unsigned)i * 0x9E3779B9u;
    asm volatile("prmt.b32 %0, %1, %2, %3;" : "=r"(d) : "r"(a[i]), "r"(b[i]), "r"(s));
    out[i] = d;
  }
}
// 64-bit: mul.wide.s32 and mul.hi.u64 (low and high words written)
extern "C" __global__ void sem_wide(unsigned long long *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    long long w;
    unsigned long long h;
    asm volatile("mul.wide.s32 %0, %1, %2;" : "=l"(w) : "r"(a[i]), "r"(b[i]));
    unsigned long long x = ((unsigned long long)a[i] << 32) | b[i];
    asm volatile("mul.hi.u64 %0, %1, %2;" : "=l"(h) : "l"(x), "l"(x ^ 0x5555555555555555ull));
    out[2 * i] = (unsigned long long)w;
    out[2 * i + 1] = h;
  }
}
