// Half-precision special functions (ex2.approx, tanh.approx on .f16, .f16x2,
// .bf16, .bf16x2), tanh.approx.f32, and comparisons of packed halves
// (setp.f16x2 with two predicates). Inline PTX, as CUDA's cuda_fp16.h writes
// them. The 16-bit kernels take every input: element i is the half with bits i.
#include "prelude.h"

#define WL_HALF_UNARY(name, op)                                                                 \
  extern "C" __global__ void name(unsigned short *out, int n) {                               \
    int i = WL_TID;                                                                           \
    if (i < n) {                                                                              \
      unsigned short x = (unsigned short)i, y;                                                \
      asm(op " %0, %1;" : "=h"(y) : "h"(x));                                                  \
      out[i] = y;                                                                             \
    }                                                                                         \
  }
WL_HALF_UNARY(ex2_f16, "ex2.approx.f16")
WL_HALF_UNARY(tanh_f16, "tanh.approx.f16")
WL_HALF_UNARY(ex2_bf16, "ex2.approx.ftz.bf16")
WL_HALF_UNARY(tanh_bf16, "tanh.approx.bf16")

// packed: the low half is i, the high half 65535 - i
#define WL_HALF2_UNARY(name, op)                                                                \
  extern "C" __global__ void name(unsigned *out, int n) {                                     \
    int i = WL_TID;                                                                           \
    if (i < n) {                                                                              \
      unsigned x = (unsigned)i | (unsigned)(65535 - i) << 16, y;                              \
      asm(op " %0, %1;" : "=r"(y) : "r"(x));                                                  \
      out[i] = y;                                                                             \
    }                                                                                         \
  }
WL_HALF2_UNARY(ex2_f16x2, "ex2.approx.f16x2")
WL_HALF2_UNARY(tanh_f16x2, "tanh.approx.f16x2")
WL_HALF2_UNARY(ex2_bf16x2, "ex2.approx.ftz.bf16x2")
WL_HALF2_UNARY(tanh_bf16x2, "tanh.approx.bf16x2")

extern "C" __global__ void tanh_f32(const float *x, float *out, int n) {
  int i = WL_TID;
  if (i < n) {
    float y;
    asm("tanh.approx.f32 %0, %1;" : "=f"(y) : "f"(x[i]));
    out[i] = y;
  }
}

// setp.CMP.f16x2 p|q, a, b (p: the low halves, q: the high halves), and
// .bf16x2: bit 2k of out[i] is p and bit 2k+1 is q of comparison k
#define WL_SETP2(k, cmp, ty)                                                                    \
  asm("{\n\t.reg .pred p, q;\n\t.reg .b32 t;\n\tsetp." cmp "." ty " p|q, %1, %2;\n\t"          \
      "selp.u32 %0, 1, 0, p;\n\tselp.u32 t, 2, 0, q;\n\tor.b32 %0, %0, t;\n\t}"                 \
      : "=r"(r) : "r"(a), "r"(b));                                                            \
  bits |= r << (2 * k)
#define WL_SETP2_KERNEL(name, ty)                                                               \
  extern "C" __global__ void name(const unsigned *as, const unsigned *bs, unsigned *out, int n) { \
    int i = WL_TID;                                                                           \
    if (i < n) {                                                                              \
      unsigned a = as[i], b = bs[i], r, bits = 0;                                             \
      WL_SETP2(0, "eq", ty);                                                                  \
      WL_SETP2(1, "ne", ty);                                                                  \
      WL_SETP2(2, "lt", ty);                                                                  \
      WL_SETP2(3, "le", ty);                                                                  \
      WL_SETP2(4, "gt", ty);                                                                  \
      WL_SETP2(5, "ge", ty);                                                                  \
      WL_SETP2(6, "equ", ty);                                                                 \
      WL_SETP2(7, "neu", ty);                                                                 \
      WL_SETP2(8, "ltu", ty);                                                                 \
      WL_SETP2(9, "leu", ty);                                                                 \
      WL_SETP2(10, "gtu", ty);                                                                \
      WL_SETP2(11, "geu", ty);                                                                \
      WL_SETP2(12, "nan", ty);                                                                \
      WL_SETP2(13, "num", ty);                                                                \
      out[i] = bits;                                                                          \
    }                                                                                         \
  }
WL_SETP2_KERNEL(setp_f16x2, "f16x2")
WL_SETP2_KERNEL(setp_bf16x2, "bf16x2")
