// Measures the special-function-unit approximations of an NVIDIA GPU over ALL
// 2^32 f32 inputs (for div: every divisor b, with the dividend a = a_of(b)),
// against a reference computed in f64 on the GPU, and prints one JSON object:
// per instruction the error histogram, per input sign/exponent the worst error
// (with its input), hit rates of simple candidate algorithms, and the exact
// result bits of a sample of inputs. tools/device/sfu_to_fixture.py turns the
// output into tests/fixtures/gpu_sfu_approx.json.
//
// Build and run (sm_90):
//   nvcc -O3 -arch=sm_90 -o /tmp/sfu_sweep tools/device/sfu_sweep.cu
//   /tmp/sfu_sweep > sfu_raw.json
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cmath>
#include <string>
#include <vector>
#include <algorithm>
#include <cuda_runtime.h>

#define CHECK(x) do { cudaError_t e_ = (x); if (e_ != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e_)); exit(1); } } while (0)

enum Op {
  RCP, RCP_FTZ, RSQRT, RSQRT_FTZ, SQRT, SQRT_FTZ, LG2, LG2_FTZ, EX2, EX2_FTZ,
  SIN, SIN_FTZ, COS, COS_FTZ, TANH,
  DIV_APPROX, DIV_APPROX_FTZ, DIV_FULL, DIV_FULL_FTZ, DIV_APPROX_WIDE, NOPS
};
static const char *OP_NAMES[NOPS] = {
  "rcp.approx.f32", "rcp.approx.ftz.f32", "rsqrt.approx.f32", "rsqrt.approx.ftz.f32",
  "sqrt.approx.f32", "sqrt.approx.ftz.f32", "lg2.approx.f32", "lg2.approx.ftz.f32",
  "ex2.approx.f32", "ex2.approx.ftz.f32", "sin.approx.f32", "sin.approx.ftz.f32",
  "cos.approx.f32", "cos.approx.ftz.f32", "tanh.approx.f32",
  "div.approx.f32", "div.approx.ftz.f32", "div.full.f32", "div.full.ftz.f32", "div.approx.f32"};
// For the div rows: how the dividend a is made from the divisor b.
static const char *A_MODE[NOPS] = {
  "", "", "", "", "", "", "", "", "", "", "", "", "", "", "",
  "a = 0x3f800000 | (mix32(b) & 0x7fffff)", "a = 0x3f800000 | (mix32(b) & 0x7fffff)",
  "a = 0x3f800000 | (mix32(b) & 0x7fffff)", "a = 0x3f800000 | (mix32(b) & 0x7fffff)", "a = mix32(b)"};

__host__ __device__ constexpr bool is_binary(int op) { return op >= DIV_APPROX; }
__host__ __device__ constexpr bool is_ftz(int op) {
  return op == RCP_FTZ || op == RSQRT_FTZ || op == SQRT_FTZ || op == LG2_FTZ || op == EX2_FTZ || op == SIN_FTZ ||
         op == COS_FTZ || op == DIV_APPROX_FTZ || op == DIV_FULL_FTZ;
}

// A bijective 32-bit mixer (lowbias32); the host script has the same function.
__host__ __device__ inline uint32_t mix32(uint32_t x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16; return x;
}
__host__ __device__ inline uint32_t a_of(int op, uint32_t b) {
  return op == DIV_APPROX_WIDE ? mix32(b) : (0x3f800000u | (mix32(b) & 0x7fffffu));
}

template <int OP> __device__ __forceinline__ float approx(float x, float a) {
  float y;
  if (OP == RCP) asm volatile("rcp.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == RCP_FTZ) asm volatile("rcp.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == RSQRT) asm volatile("rsqrt.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == RSQRT_FTZ) asm volatile("rsqrt.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == SQRT) asm volatile("sqrt.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == SQRT_FTZ) asm volatile("sqrt.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == LG2) asm volatile("lg2.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == LG2_FTZ) asm volatile("lg2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == EX2) asm volatile("ex2.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == EX2_FTZ) asm volatile("ex2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == SIN) asm volatile("sin.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == SIN_FTZ) asm volatile("sin.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == COS) asm volatile("cos.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == COS_FTZ) asm volatile("cos.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == TANH) asm volatile("tanh.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == DIV_APPROX || OP == DIV_APPROX_WIDE) asm volatile("div.approx.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  if (OP == DIV_APPROX_FTZ) asm volatile("div.approx.ftz.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  if (OP == DIV_FULL) asm volatile("div.full.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  if (OP == DIV_FULL_FTZ) asm volatile("div.full.ftz.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  return y;
}

__device__ __forceinline__ float flush(float x) {
  return (fabsf(x) < 1.17549435e-38f) ? copysignf(0.0f, x) : x;
}

// The exact function in f64 (x already flushed for .ftz).
template <int OP> __device__ __forceinline__ double reference(float x, float a) {
  double d = x;
  switch (OP) {
    case RCP: case RCP_FTZ: return 1.0 / d;
    case RSQRT: case RSQRT_FTZ: return (x == 0.0f) ? 1.0 / d : 1.0 / sqrt(d);
    case SQRT: case SQRT_FTZ: return sqrt(d);
    case LG2: case LG2_FTZ: return log2(d);
    case EX2: case EX2_FTZ: return exp2(d);
    case SIN: case SIN_FTZ: return sin(d);
    case COS: case COS_FTZ: return cos(d);
    case TANH: return tanh(d);
    default: return (double)a / d;
  }
}

// Candidate algorithms (hit counted when a candidate's bits equal the unit's).
// 0..3: the exact result rounded RN, RZ, RU, RD.
// 4..11: op-specific (see CAND_NAMES).
#define NCAND 12
static const char *CAND_NAMES[NOPS][NCAND - 4] = {
  /*RCP*/ {"scale: y(m*2^e) == y(m)*2^-e (normal x and y)", "RN(1/x) with x's mantissa truncated to 16 bits", "to 18 bits", "to 20 bits", "to 22 bits", "", "", ""},
  /*RCP_FTZ*/ {"scale: y(m*2^e) == y(m)*2^-e (normal x and y)", "", "", "", "", "", "", ""},
  /*RSQRT*/ {"scale: y(m*4^k) == y(m)*2^-k (normal x and y)", "RN(1/sqrt(x)) with x's mantissa truncated to 16 bits", "to 18 bits", "to 20 bits", "to 22 bits", "", "", ""},
  /*RSQRT_FTZ*/ {"scale: y(m*4^k) == y(m)*2^-k (normal x and y)", "", "", "", "", "", "", ""},
  /*SQRT*/ {"scale: y(m*4^k) == y(m)*2^k (normal x and y)", "RN(x * rsqrt.approx(x))", "RN(1/rsqrt.approx(x))", "rcp.approx(rsqrt.approx(x))", "", "", "", ""},
  /*SQRT_FTZ*/ {"scale: y(m*4^k) == y(m)*2^k (normal x and y)", "RN(x * rsqrt.approx.ftz(x))", "RN(1/rsqrt.approx.ftz(x))", "rcp.approx.ftz(rsqrt.approx.ftz(x))", "", "", "", ""},
  /*LG2*/ {"y(x) == e + lg2.approx(m) rounded (normal x)", "RN(log2(x)) with x's mantissa truncated to 16 bits", "to 18 bits", "to 20 bits", "to 22 bits", "", "", ""},
  /*LG2_FTZ*/ {"y(x) == e + lg2.approx(m) rounded (normal x)", "", "", "", "", "", "", ""},
  /*EX2*/ {"RN(2^x) with x rounded to fixed point, 12 fraction bits", "14 bits", "16 bits", "18 bits", "20 bits", "22 bits", "23 bits", "24 bits"},
  /*EX2_FTZ*/ {"RN(2^x) with x rounded to fixed point, 12 fraction bits", "14 bits", "16 bits", "18 bits", "20 bits", "22 bits", "23 bits", "24 bits"},
  /*SIN*/ {"RN(sin(2*pi*t)), t = RZ(x * 0x3e22f983) (the reduced argument)", "", "", "", "", "", "", ""},
  /*SIN_FTZ*/ {"RN(sin(2*pi*t)), t = RZ(x * 0x3e22f983) (the reduced argument)", "", "", "", "", "", "", ""},
  /*COS*/ {"RN(cos(2*pi*t)), t = RZ(x * 0x3e22f983) (the reduced argument)", "", "", "", "", "", "", ""},
  /*COS_FTZ*/ {"RN(cos(2*pi*t)), t = RZ(x * 0x3e22f983) (the reduced argument)", "", "", "", "", "", "", ""},
  /*TANH*/ {"", "", "", "", "", "", "", ""},
  /*DIV_APPROX*/ {"RN(a * rcp.approx(b))", "RN(a * rcp.approx.ftz(b))", "", "", "", "", "", ""},
  /*DIV_APPROX_FTZ*/ {"RN(a * rcp.approx(b))", "RN(a * rcp.approx.ftz(b))", "", "", "", "", "", ""},
  /*DIV_FULL*/ {"RN(a * rcp.approx(b))", "div.approx.f32", "", "", "", "", "", ""},
  /*DIV_FULL_FTZ*/ {"RN(a * rcp.approx.ftz(b))", "div.approx.ftz.f32", "", "", "", "", "", ""},
  /*DIV_APPROX_WIDE*/ {"RN(a * rcp.approx(b))", "RN(a * rcp.approx.ftz(b))", "", "", "", "", "", ""},
};

__host__ __device__ constexpr bool cand_active(int op, int c) {
  return (op == RCP || op == RSQRT || op == LG2) ? c <= 4
       : (op == SQRT || op == SQRT_FTZ) ? c <= 3
       : (op == EX2 || op == EX2_FTZ) ? true
       : (op == TANH) ? false
       : (op >= DIV_APPROX) ? c <= 1
       : c == 0;
}

__device__ __forceinline__ float trunc_mant(float x, int bits) {
  uint32_t u = __float_as_uint(x);
  return __uint_as_float(u & ~((1u << (23 - bits)) - 1u));
}
__device__ __forceinline__ bool is_normal_f(float x) {
  float ax = fabsf(x); return ax >= 1.17549435e-38f && ax <= 3.40282347e38f;
}
__device__ __forceinline__ float rn(double d) { return __double2float_rn(d); }

template <int OP> __device__ __forceinline__ bool candidate(int c, float x, float a, float y) {
  uint32_t yb = __float_as_uint(y);
  switch (OP) {
    case RCP: case RCP_FTZ: {
      if (c == 0) {
        if (!is_normal_f(x) || !is_normal_f(y)) return false;
        int e = ((__float_as_uint(x) >> 23) & 255) - 127;
        float m = __uint_as_float((__float_as_uint(x) & 0x807fffffu) | 0x3f800000u);
        float ym = approx<OP>(m, a);
        return __float_as_uint(ldexpf(ym, -e)) == yb;
      }
      if (OP == RCP_FTZ || c > 4) return false;
      return __float_as_uint(rn(1.0 / (double)trunc_mant(x, 14 + 2 * c))) == yb;
    }
    case RSQRT: case RSQRT_FTZ: case SQRT: case SQRT_FTZ: {
      if (c == 0) {
        if (!is_normal_f(x) || !is_normal_f(y)) return false;
        int e = ((__float_as_uint(x) >> 23) & 255) - 127;
        int k = (e >= 0) ? e / 2 : -((1 - e) / 2);  // floor(e/2)
        float m = ldexpf(x, -2 * k);
        float ym = approx<OP>(m, a);
        int s = (OP == SQRT || OP == SQRT_FTZ) ? k : -k;
        return __float_as_uint(ldexpf(ym, s)) == yb;
      }
      if (OP == RSQRT) { if (c > 4) return false; return __float_as_uint(rn(1.0 / sqrt((double)trunc_mant(x, 14 + 2 * c)))) == yb; }
      if (OP == SQRT || OP == SQRT_FTZ) {
        float r = (OP == SQRT) ? approx<RSQRT>(x, a) : approx<RSQRT_FTZ>(x, a);
        if (c == 1) return __float_as_uint(__fmul_rn(x, r)) == yb;
        if (c == 2) return __float_as_uint(rn(1.0 / (double)r)) == yb;
        if (c == 3) return __float_as_uint((OP == SQRT) ? approx<RCP>(r, a) : approx<RCP_FTZ>(r, a)) == yb;
      }
      return false;
    }
    case LG2: case LG2_FTZ: {
      if (c == 0) {
        if (!is_normal_f(x) || x < 0) return false;
        int e = ((__float_as_uint(x) >> 23) & 255) - 127;
        float m = __uint_as_float((__float_as_uint(x) & 0x007fffffu) | 0x3f800000u);
        return __float_as_uint(__fadd_rn((float)e, approx<OP>(m, a))) == yb;
      }
      if (OP == LG2_FTZ || c > 4) return false;
      return __float_as_uint(rn(log2((double)trunc_mant(x, 14 + 2 * c)))) == yb;
    }
    case EX2: case EX2_FTZ: {
      const int fb[8] = {12, 14, 16, 18, 20, 22, 23, 24};
      double q = ldexp(rint(ldexp((double)x, fb[c])), -fb[c]);
      float r = rn(exp2(q));
      if (OP == EX2_FTZ) r = flush(r);
      return __float_as_uint(r) == yb;
    }
    case SIN: case SIN_FTZ: case COS: case COS_FTZ: {
      if (c != 0) return false;
      float t = __fmul_rz(x, 0.15915494309189535f);
      double r = (OP == SIN || OP == SIN_FTZ) ? sinpi(2.0 * (double)t) : cospi(2.0 * (double)t);
      return __float_as_uint(rn(r)) == yb;
    }
    case DIV_APPROX: case DIV_APPROX_FTZ: case DIV_APPROX_WIDE:
      if (c == 0) return __float_as_uint(__fmul_rn(a, approx<RCP>(x, a))) == yb;
      if (c == 1) return __float_as_uint(__fmul_rn(a, approx<RCP_FTZ>(x, a))) == yb;
      return false;
    case DIV_FULL:
      if (c == 0) return __float_as_uint(__fmul_rn(a, approx<RCP>(x, a))) == yb;
      if (c == 1) return __float_as_uint(approx<DIV_APPROX>(x, a)) == yb;
      return false;
    case DIV_FULL_FTZ:
      if (c == 0) return __float_as_uint(__fmul_rn(a, approx<RCP_FTZ>(x, a))) == yb;
      if (c == 1) return __float_as_uint(approx<DIV_APPROX_FTZ>(x, a)) == yb;
      return false;
  }
  return false;
}

__host__ __device__ inline int64_t ord(uint32_t b) {
  return (b & 0x80000000u) ? -(int64_t)(b & 0x7fffffffu) : (int64_t)b;
}

// Histogram bins of d = ord(y) - ord(RN(reference)).
#define NBIN 92
__device__ __forceinline__ int bin_of(int64_t d) {
  if (d >= -16 && d <= 16) return (int)(d + 16);
  int64_t m = d > 0 ? d : -d;
  int l = 63 - __clzll(m);  // >= 4
  l = min(l - 4, 27);
  return d > 0 ? 33 + l : 61 + l;
}
#define BIN_NAN_OK 89
#define BIN_NAN_MISSING 90
#define BIN_NAN_SPURIOUS 91

struct Acc {
  unsigned long long hist[NBIN];
  unsigned long long cand[NCAND];
  unsigned long long cand_eligible[NCAND];
  unsigned long long zero_sign_mismatch;
  unsigned long long worst_ulp[512];   // (float bits of fractional ulp error) << 32 | input bits, per sign/exponent of x
  unsigned long long worst_abs[512];   // (float bits of absolute error) << 32 | input bits
  unsigned long long worst_ulp_red[512];  // sin/cos: ulp error against the reduced-argument reference
  unsigned long long inexact[512];     // inputs whose result differs from RN(reference), per bin
};

__device__ __forceinline__ double ulp_of(float r) {
  uint32_t e = (__float_as_uint(r) >> 23) & 255;
  if (e == 0) e = 1;
  if (e == 255) e = 254;
  return ldexp(1.0, (int)e - 150);
}

__device__ __forceinline__ unsigned long long warp_max64(unsigned long long v) {
  for (int o = 16; o > 0; o >>= 1) { unsigned long long w = __shfl_xor_sync(0xffffffffu, v, o); v = v > w ? v : w; }
  return v;
}

#define CHUNK 4096ull  // consecutive inputs per warp (all in one sign/exponent bin)

template <int OP> __global__ void __launch_bounds__(256) sweep(Acc *acc) {
  __shared__ unsigned long long sh[NBIN + 2 * NCAND + 1];
  for (int i = threadIdx.x; i < NBIN + 2 * NCAND + 1; i += blockDim.x) sh[i] = 0;
  __syncthreads();
  const int lane = threadIdx.x & 31;
  const unsigned long long nwarps = (unsigned long long)gridDim.x * (blockDim.x / 32);
  unsigned long long warp = (unsigned long long)blockIdx.x * (blockDim.x / 32) + threadIdx.x / 32;
  unsigned long long exact_local = 0, nonnan = 0, c_rz = 0, c_ru = 0, c_rd = 0;
  unsigned long long c_el[NCAND - 4] = {0}, c_hit[NCAND - 4] = {0};
  for (unsigned long long base = warp * CHUNK; base < (1ull << 32); base += nwarps * CHUNK) {
    unsigned long long wu = 0, wa = 0, wr = 0, inex = 0;
    for (unsigned long long k = lane; k < CHUNK; k += 32) {
      uint32_t xb = (uint32_t)(base + k);
      float x = __uint_as_float(xb);
      float a = __uint_as_float(a_of(OP, xb));
      float y = approx<OP>(x, a);
      float xf = is_ftz(OP) ? flush(x) : x;
      float af = is_ftz(OP) ? flush(a) : a;
      double ref = reference<OP>(xf, af);
      float r32 = rn(ref);
      if (is_ftz(OP)) r32 = flush(r32);
      bool ynan = isnan(y), rnan = isnan(r32);
      if (ynan || rnan) {
        atomicAdd(&sh[ynan && rnan ? BIN_NAN_OK : (rnan ? BIN_NAN_MISSING : BIN_NAN_SPURIOUS)], 1ull);
        if (ynan != rnan) inex++;
        if (ynan != rnan) {
          unsigned long long key = ((unsigned long long)0x7f800000u << 32) | xb;
          wu = max(wu, key); wa = max(wa, key);
        }
        continue;
      }
      uint32_t yb = __float_as_uint(y), rb = __float_as_uint(r32);
      int64_t d = ord(yb) - ord(rb);
      if (d == 0) exact_local++; else { atomicAdd(&sh[bin_of(d)], 1ull); inex++; }
      if (d == 0 && yb != rb) atomicAdd(&sh[NBIN + 2 * NCAND], 1ull);
      float eu, ea;
      if (isinf(y) || isinf(r32) || isinf(ref)) {
        bool same = (yb == rb);
        eu = same ? 0.0f : __int_as_float(0x7f800000); ea = eu;
      } else {
        double refc = is_ftz(OP) && r32 == 0.0f ? 0.0 : ref;
        double ad = fabs((double)y - refc);
        ea = (float)ad;
        eu = (float)(ad / ulp_of(r32));
      }
      wu = max(wu, ((unsigned long long)__float_as_uint(eu) << 32) | xb);
      wa = max(wa, ((unsigned long long)__float_as_uint(ea) << 32) | xb);
      if (OP == SIN || OP == SIN_FTZ || OP == COS || OP == COS_FTZ) {
        float t = __fmul_rz(x, 0.15915494309189535f);
        double r2 = (OP == SIN || OP == SIN_FTZ) ? sinpi(2.0 * (double)t) : cospi(2.0 * (double)t);
        float r2f = rn(r2);
        float e2 = isinf(x) ? 0.0f : (float)(fabs((double)y - r2) / ulp_of(r2f));
        wr = max(wr, ((unsigned long long)__float_as_uint(e2) << 32) | xb);
      }
      // candidates
      nonnan++;
      float rz = __double2float_rz(ref), ru = __double2float_ru(ref), rd = __double2float_rd(ref);
      if (is_ftz(OP)) { rz = flush(rz); ru = flush(ru); rd = flush(rd); }
      c_rz += __float_as_uint(rz) == yb; c_ru += __float_as_uint(ru) == yb; c_rd += __float_as_uint(rd) == yb;
#pragma unroll
      for (int c = 0; c < NCAND - 4; c++) {
        if (cand_active(OP, c)) {
          bool elig = true;
          if (c == 0 && (OP <= SQRT_FTZ)) elig = is_normal_f(x) && is_normal_f(y);
          if (c == 0 && (OP == LG2 || OP == LG2_FTZ)) elig = is_normal_f(x) && x > 0;
          if (elig) {
            c_el[c]++;
            if (candidate<OP>(c, x, a, y)) c_hit[c]++;
          }
        }
      }
    }
    wu = warp_max64(wu); wa = warp_max64(wa); wr = warp_max64(wr);
    for (int o = 16; o > 0; o >>= 1) inex += __shfl_xor_sync(0xffffffffu, inex, o);
    if (lane == 0) {
      int b = (int)(base >> 23);
      atomicMax(&acc->worst_ulp[b], wu); atomicMax(&acc->worst_abs[b], wa);
      if (wr) atomicMax(&acc->worst_ulp_red[b], wr);
      if (inex) atomicAdd(&acc->inexact[b], inex);
    }
  }
  atomicAdd(&sh[16], exact_local);
  atomicAdd(&sh[NBIN + 1], c_rz); atomicAdd(&sh[NBIN + 2], c_ru); atomicAdd(&sh[NBIN + 3], c_rd);
  for (int c = 1; c < 4; c++) atomicAdd(&sh[NBIN + NCAND + c], nonnan);
#pragma unroll
  for (int c = 0; c < NCAND - 4; c++) if (cand_active(OP, c)) {
    atomicAdd(&sh[NBIN + 4 + c], c_hit[c]); atomicAdd(&sh[NBIN + NCAND + 4 + c], c_el[c]);
  }
  __syncthreads();
  for (int i = threadIdx.x; i < NBIN; i += blockDim.x) if (sh[i]) atomicAdd(&acc->hist[i], sh[i]);
  for (int i = threadIdx.x; i < NCAND; i += blockDim.x) {
    if (sh[NBIN + i]) atomicAdd(&acc->cand[i], sh[NBIN + i]);
    if (sh[NBIN + NCAND + i]) atomicAdd(&acc->cand_eligible[i], sh[NBIN + NCAND + i]);
  }
  if (threadIdx.x == 0) atomicAdd(&acc->zero_sign_mismatch, sh[NBIN + 2 * NCAND]);
}

template <int OP> __global__ void apply(const uint32_t *xs, uint32_t *ys, int n) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) {
    uint32_t xb = xs[i];
    ys[i] = __float_as_uint(approx<OP>(__uint_as_float(xb), __uint_as_float(a_of(OP, xb))));
  }
}

// ---------------------------------------------------------------- host
static std::vector<uint32_t> sample_inputs() {
  std::vector<uint32_t> v;
  for (uint32_t s = 0; s < 2; s++)
    for (uint32_t e = 0; e < 256; e++)
      for (uint32_t k = 0; k < 8; k++) {
        uint32_t m = k == 0 ? 0 : (k == 1 ? 0x7fffffu : (k == 2 ? 1u : mix32((s << 16) | (e << 8) | k) & 0x7fffffu));
        v.push_back((s << 31) | (e << 23) | m);
      }
  const float specials[] = {1.0f, 0.5f, 2.0f, 3.0f, 0.1f, 1.5f, 0.75f, 3.14159265f, 1.57079633f, 6.28318531f,
                            100.0f, 1000.0f, 1e5f, 1e6f, 126.0f, 127.0f, 127.99999f, 128.0f, -126.0f, -127.0f,
                            -149.0f, -150.0f, -125.5f, 0.693147f, 1.0e-3f, 1e-7f, 9.0f, 10.0f, 16.0f, 20.0f, 88.0f};
  for (float f : specials) { uint32_t u; memcpy(&u, &f, 4); v.push_back(u); v.push_back(u ^ 0x80000000u); }
  const uint32_t bits[] = {0x7fc00000u, 0xffc00000u, 0x7f800001u, 0x7fffffffu, 0x00000001u, 0x80000001u, 0x007fffffu,
                           0x807fffffu, 0x00800000u, 0x80800000u, 0x00400000u, 0x3f7fffffu, 0x3f800001u, 0x40490fdbu};
  for (uint32_t b : bits) v.push_back(b);
  return v;
}

template <int OP> static void run_op(Acc *dacc, const uint32_t *dxs, uint32_t *dys, int n, float *ms) {
  CHECK(cudaMemset(dacc, 0, sizeof(Acc)));
  cudaEvent_t e0, e1; cudaEventCreate(&e0); cudaEventCreate(&e1);
  cudaEventRecord(e0);
  sweep<OP><<<132 * 8, 256>>>(dacc);
  cudaEventRecord(e1);
  CHECK(cudaGetLastError());
  CHECK(cudaDeviceSynchronize());
  cudaEventElapsedTime(ms, e0, e1);
  apply<OP><<<(n + 255) / 256, 256>>>(dxs, dys, n);
  CHECK(cudaGetLastError());
  CHECK(cudaDeviceSynchronize());
}

static void print_u64s(const char *name, const unsigned long long *v, int n, bool last = false) {
  printf("\"%s\":[", name);
  for (int i = 0; i < n; i++) printf("%s%llu", i ? "," : "", v[i]);
  printf("]%s", last ? "" : ",");
}

int main(int argc, char **argv) {
  int only = argc > 1 ? atoi(argv[1]) : -1;
  cudaDeviceProp p; CHECK(cudaGetDeviceProperties(&p, 0));
  int drv = 0, rt = 0; cudaDriverGetVersion(&drv); cudaRuntimeGetVersion(&rt);
  std::vector<uint32_t> xs = sample_inputs();
  int n = (int)xs.size();
  Acc *dacc; uint32_t *dxs, *dys;
  CHECK(cudaMalloc(&dacc, sizeof(Acc))); CHECK(cudaMalloc(&dxs, n * 4)); CHECK(cudaMalloc(&dys, n * 4));
  CHECK(cudaMemcpy(dxs, xs.data(), n * 4, cudaMemcpyHostToDevice));
  printf("{\"device\":\"%s\",\"compute_capability\":\"%d.%d\",\"driver_version\":%d,\"runtime_version\":%d,\n",
         p.name, p.major, p.minor, drv, rt);
  printf("\"hist_bins\":\"0..32: d=-16..16; 33+l: d in [2^(l+4), 2^(l+5)) (l=27: >= 2^31); 61+l: the same for -d; 89: both NaN; 90: reference NaN, result not; 91: result NaN, reference not\",\n");
  printf("\"ops\":[\n");
  std::vector<uint32_t> ys(n);
  Acc h;
  bool first = true;
  for (int op = 0; op < NOPS; op++) {
    if (only >= 0 && op != only) continue;
    float ms = 0;
    switch (op) {
#define CASE(o) case o: run_op<o>(dacc, dxs, dys, n, &ms); break;
      CASE(RCP) CASE(RCP_FTZ) CASE(RSQRT) CASE(RSQRT_FTZ) CASE(SQRT) CASE(SQRT_FTZ) CASE(LG2) CASE(LG2_FTZ)
      CASE(EX2) CASE(EX2_FTZ) CASE(SIN) CASE(SIN_FTZ) CASE(COS) CASE(COS_FTZ) CASE(TANH)
      CASE(DIV_APPROX) CASE(DIV_APPROX_FTZ) CASE(DIV_FULL) CASE(DIV_FULL_FTZ) CASE(DIV_APPROX_WIDE)
#undef CASE
    }
    CHECK(cudaMemcpy(&h, dacc, sizeof(Acc), cudaMemcpyDeviceToHost));
    CHECK(cudaMemcpy(ys.data(), dys, n * 4, cudaMemcpyDeviceToHost));
    fprintf(stderr, "%s: %.1f ms\n", OP_NAMES[op], ms);
    printf("%s{\"name\":\"%s\",\"binary\":%s,\"a_mode\":\"%s\",\"sweep_ms\":%.1f,\n", first ? "" : ",\n", OP_NAMES[op],
           is_binary(op) ? "true" : "false", A_MODE[op], ms);
    first = false;
    printf("\"candidates\":[\"RN(exact)\",\"RZ(exact)\",\"RU(exact)\",\"RD(exact)\"");
    for (int c = 0; c < NCAND - 4; c++) printf(",\"%s\"", CAND_NAMES[op][c]);
    printf("],\n");
    h.cand[0] = h.hist[16];
    h.cand_eligible[0] = h.cand_eligible[1];
    print_u64s("cand_hits", h.cand, NCAND); printf("\n");
    print_u64s("cand_eligible", h.cand_eligible, NCAND); printf("\n");
    print_u64s("hist", h.hist, NBIN); printf("\n");
    printf("\"zero_sign_mismatch\":%llu,\n", h.zero_sign_mismatch);
    print_u64s("worst_ulp", h.worst_ulp, 512); printf("\n");
    print_u64s("worst_abs", h.worst_abs, 512); printf("\n");
    print_u64s("worst_ulp_reduced", h.worst_ulp_red, 512); printf("\n");
    print_u64s("inexact", h.inexact, 512); printf("\n");
    // sample: the fixed inputs plus the worst input of every bin
    std::vector<uint32_t> extra;
    for (int b = 0; b < 512; b++) if ((h.worst_ulp[b] >> 32) != 0) extra.push_back((uint32_t)h.worst_ulp[b]);
    uint32_t *dex, *dey; int ne = (int)extra.size();
    std::vector<uint32_t> ey(ne);
    if (ne) {
      CHECK(cudaMalloc(&dex, ne * 4)); CHECK(cudaMalloc(&dey, ne * 4));
      CHECK(cudaMemcpy(dex, extra.data(), ne * 4, cudaMemcpyHostToDevice));
      switch (op) {
#define CASE(o) case o: apply<o><<<(ne + 255) / 256, 256>>>(dex, dey, ne); break;
        CASE(RCP) CASE(RCP_FTZ) CASE(RSQRT) CASE(RSQRT_FTZ) CASE(SQRT) CASE(SQRT_FTZ) CASE(LG2) CASE(LG2_FTZ)
        CASE(EX2) CASE(EX2_FTZ) CASE(SIN) CASE(SIN_FTZ) CASE(COS) CASE(COS_FTZ) CASE(TANH)
        CASE(DIV_APPROX) CASE(DIV_APPROX_FTZ) CASE(DIV_FULL) CASE(DIV_FULL_FTZ) CASE(DIV_APPROX_WIDE)
#undef CASE
      }
      CHECK(cudaGetLastError());
      CHECK(cudaMemcpy(ey.data(), dey, ne * 4, cudaMemcpyDeviceToHost));
      cudaFree(dex); cudaFree(dey);
    }
    printf("\"sample_x\":[");
    for (int i = 0; i < n; i++) printf("%s%u", i ? "," : "", xs[i]);
    for (int i = 0; i < ne; i++) printf(",%u", extra[i]);
    printf("],\n\"sample_y\":[");
    for (int i = 0; i < n; i++) printf("%s%u", i ? "," : "", ys[i]);
    for (int i = 0; i < ne; i++) printf(",%u", ey[i]);
    printf("]}");
    fflush(stdout);
  }
  printf("\n]}\n");
  return 0;
}
