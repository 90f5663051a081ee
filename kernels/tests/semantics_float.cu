// Float instruction semantics at edge values (NaN, infinities, signed zeros,
// subnormals, rounding ties): one PTX instruction per kernel via inline PTX.
#include "../prelude.h"

#define FBIN(name, op)                                                             \
  extern "C" __global__ void name(float *out, const float *a, const float *b,     \
                                  int n) {                                         \
    int i = WL_TID;                                                                \
    if (i < n) {                                                                   \
      float d;                                                                     \
      asm volatile(op " %0, %1, %2;" : "=f"(d) : "f"(a[i]), "f"(b[i]));            \
      out[i] = d;                                                                  \
    }                                                                              \
  }
#define FUN(name, op)                                                              \
  extern "C" __global__ void name(float *out, const float *a, const float *b,     \
                                  int n) {                                         \
    int i = WL_TID;                                                                \
    if (i < n) {                                                                   \
      float d;                                                                     \
      asm volatile(op " %0, %1;" : "=f"(d) : "f"(a[i]));                           \
      out[i] = d;                                                                  \
    }                                                                              \
  }
// float in, int out
#define F2I(name, op)                                                              \
  extern "C" __global__ void name(int *out, const float *a, const float *b,       \
                                  int n) {                                         \
    int i = WL_TID;                                                                \
    if (i < n) {                                                                   \
      int d;                                                                       \
      asm volatile(op " %0, %1;" : "=r"(d) : "f"(a[i]));                           \
      out[i] = d;                                                                  \
    }                                                                              \
  }

FBIN(sem_add_rn_f32, "add.rn.f32")
FBIN(sem_add_rz_f32, "add.rz.f32")
FBIN(sem_add_rm_f32, "add.rm.f32")
FBIN(sem_add_rp_f32, "add.rp.f32")
FBIN(sem_mul_rn_f32, "mul.rn.f32")
FBIN(sem_mul_rz_f32, "mul.rz.f32")
FBIN(sem_div_rn_f32, "div.rn.f32")
FBIN(sem_min_f32, "min.f32")
FBIN(sem_max_f32, "max.f32")
FBIN(sem_add_ftz_f32, "add.ftz.f32")
FUN(sem_sqrt_rn_f32, "sqrt.rn.f32")
FUN(sem_rcp_rn_f32, "rcp.rn.f32")
FUN(sem_abs_f32, "abs.f32")
FUN(sem_neg_f32, "neg.f32")
FUN(sem_cvt_sat_f32, "cvt.sat.f32.f32")
FUN(sem_cvt_rni_f32, "cvt.rni.f32.f32")
F2I(sem_cvt_rni_s32, "cvt.rni.s32.f32")
F2I(sem_cvt_rzi_s32, "cvt.rzi.s32.f32")
F2I(sem_cvt_rmi_s32, "cvt.rmi.s32.f32")
F2I(sem_cvt_rpi_s32, "cvt.rpi.s32.f32")
F2I(sem_cvt_rzi_u32, "cvt.rzi.u32.f32")

// fma.rn: a * b + c with c = -(a*b rounded): exposes the single rounding.
extern "C" __global__ void sem_fma_rn_f32(float *out, const float *a, const float *b, int n) {
  int i = WL_TID;
  if (i < n) {
    float p = a[i] * b[i], d;
    asm volatile("fma.rn.f32 %0, %1, %2, %3;" : "=f"(d) : "f"(a[i]), "f"(b[i]), "f"(-p));
    out[i] = d;
  }
}
// int -> float with directed rounding
extern "C" __global__ void sem_cvt_i2f(float *out, const int *a, const int *b, int n) {
  int i = WL_TID;
  if (i < n) {
    float rn, rz, rm, rp;
    asm volatile("cvt.rn.f32.s32 %0, %1;" : "=f"(rn) : "r"(a[i]));
    asm volatile("cvt.rz.f32.s32 %0, %1;" : "=f"(rz) : "r"(a[i]));
    asm volatile("cvt.rm.f32.u32 %0, %1;" : "=f"(rm) : "r"(a[i]));
    asm volatile("cvt.rp.f32.u32 %0, %1;" : "=f"(rp) : "r"(a[i]));
    out[4 * i] = rn;
    out[4 * i + 1] = rz;
    out[4 * i + 2] = rm;
    out[4 * i + 3] = rp;
  }
}
// saturating integer narrowing: cvt.sat.s8.s32 and cvt.sat.u16.s32
extern "C" __global__ void sem_cvt_sat_int(int *out, const int *a, const int *b, int n) {
  int i = WL_TID;
  if (i < n) {
    short s8, u16;
    asm volatile("cvt.sat.s8.s32 %0, %1;" : "=h"(s8) : "r"(a[i]));
    asm volatile("cvt.sat.u16.s32 %0, %1;" : "=h"(u16) : "r"(a[i]));
    out[2 * i] = s8;
    out[2 * i + 1] = (unsigned short)u16;
  }
}
// f64 -> f32 directed and f64 arithmetic
extern "C" __global__ void sem_f64(float *out, const double *a, const double *b, int n) {
  int i = WL_TID;
  if (i < n) {
    float rn, rz, rp;
    double s;
    asm volatile("cvt.rn.f32.f64 %0, %1;" : "=f"(rn) : "d"(a[i]));
    asm volatile("cvt.rz.f32.f64 %0, %1;" : "=f"(rz) : "d"(a[i]));
    asm volatile("cvt.rp.f32.f64 %0, %1;" : "=f"(rp) : "d"(a[i]));
    asm volatile("fma.rn.f64 %0, %1, %2, %1;" : "=d"(s) : "d"(a[i]), "d"(b[i]));
    out[4 * i] = rn;
    out[4 * i + 1] = rz;
    out[4 * i + 2] = rp;
    out[4 * i + 3] = (float)s;
  }
}
// setp with unordered comparisons; selp
extern "C" __global__ void sem_setp(unsigned *out, const float *a, const float *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned r;
    asm volatile(
        "{ .reg .pred p<8>; .reg .b32 t;\n"
        "setp.lt.f32 p0, %1, %2;\n setp.ltu.f32 p1, %1, %2;\n"
        "setp.ne.f32 p2, %1, %2;\n setp.neu.f32 p3, %1, %2;\n"
        "setp.nan.f32 p4, %1, %2;\n setp.num.f32 p5, %1, %2;\n"
        "setp.ge.and.f32 p6|p7, %1, %2, p5;\n"
        "selp.b32 %0, 1, 0, p0;\n"
        "selp.b32 t, 2, 0, p1; or.b32 %0, %0, t;\n"
        "selp.b32 t, 4, 0, p2; or.b32 %0, %0, t;\n"
        "selp.b32 t, 8, 0, p3; or.b32 %0, %0, t;\n"
        "selp.b32 t, 16, 0, p4; or.b32 %0, %0, t;\n"
        "selp.b32 t, 32, 0, p5; or.b32 %0, %0, t;\n"
        "selp.b32 t, 64, 0, p6; or.b32 %0, %0, t;\n"
        "selp.b32 t, 128, 0, p7; or.b32 %0, %0, t; }"
        : "=r"(r)
        : "f"(a[i]), "f"(b[i]));
    out[i] = r;
  }
}
