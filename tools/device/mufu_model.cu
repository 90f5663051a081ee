// Checks, over all 2^32 inputs, that a table model reproduces rcp/rsqrt/sqrt
// (.approx, with and without .ftz) and div.approx/div.full bit for bit:
//
//   MUFU.RCP(x), normal x = m * 2^e, m in [1, 2):
//       y = bits(RN(1/m)) + RCP[bits(m) - 0x3f800000], scaled by 2^-e; a result
//       below 2^-126 is a signed zero; +-0 and subnormal x give +-inf, +-inf gives +-0
//   MUFU.RSQ(x), normal x > 0, x = m * 4^k, m in [1, 4):
//       y = bits(RN(1/sqrt(m))) + RSQ[bits(m) - 0x3f800000], scaled by 2^-k;
//       +-0 and subnormal x give +-inf, +inf gives +0, x < 0 gives NaN
//   MUFU.SQRT(x), the same with sqrt(m), 2^k and SQRT[]; +-0 and subnormal give +-0
//   NaN results are 0x7fffffff. RN(...) is the f64 expression rounded once to f32
//   (exactly how the tables were measured: tools/device/sfu_extra.cu).
// and the non-ftz instructions and divisions are the SASS sequences ptxas emits
// around them (docs/gpu-measurements.md), with IEEE FMUL/FADD.
//
//   nvcc -O3 -arch=sm_90 -o /tmp/mufu_model tools/device/mufu_model.cu
//   /tmp/mufu_model rcp_1_2.i8 rsqrt_1_4.i8 sqrt_1_4.i8 > mufu_model.json
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>
#include <cuda_runtime.h>

#define CHECK(x) do { cudaError_t e_ = (x); if (e_ != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e_)); exit(1); } } while (0)

__device__ const int8_t *T_RCP, *T_RSQ, *T_SQRT;

__device__ __forceinline__ float u2f(uint32_t u) { return __uint_as_float(u); }
__device__ __forceinline__ uint32_t f2u(float f) { return __float_as_uint(f); }
__device__ __forceinline__ float fmul_ftz(float a, float b) { float y; asm("mul.rn.ftz.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(b)); return y; }

#define QNAN 0x7fffffffu

__device__ uint32_t mufu_rcp(uint32_t x) {
  uint32_t s = x & 0x80000000u, e = (x >> 23) & 255;
  if (e == 255) return (x & 0x7fffffu) ? QNAN : s;  // inf -> 0
  if (e == 0) return s | 0x7f800000u;              // 0, subnormal -> inf
  uint32_t mb = 0x3f800000u | (x & 0x7fffffu);
  float ym = __double2float_rn(1.0 / (double)u2f(mb));
  uint32_t yb = f2u(ym) + (int32_t)T_RCP[mb - 0x3f800000u];
  int ye = (int)((yb >> 23) & 255) - (int)(e - 127);
  if (ye <= 0) return s;
  return s | ((uint32_t)ye << 23) | (yb & 0x7fffffu);
}

template <bool SQ> __device__ uint32_t mufu_rsq_sqrt(uint32_t x) {
  uint32_t s = x & 0x80000000u, e = (x >> 23) & 255;
  if (e == 0) return SQ ? s : (s | 0x7f800000u);
  if (s) return QNAN;
  if (e == 255) return (x & 0x7fffffu) ? QNAN : (SQ ? 0x7f800000u : 0u);
  int ue = (int)e - 127;
  int k = ue >= 0 ? ue / 2 : -((1 - ue) / 2);
  uint32_t mb = ((uint32_t)(ue - 2 * k + 127) << 23) | (x & 0x7fffffu);
  double md = (double)u2f(mb);
  float ym = __double2float_rn(SQ ? sqrt(md) : 1.0 / sqrt(md));
  uint32_t yb = f2u(ym) + (int32_t)(SQ ? T_SQRT : T_RSQ)[mb - 0x3f800000u];
  int ye = (int)((yb >> 23) & 255) + (SQ ? k : -k);
  return ((uint32_t)ye << 23) | (yb & 0x7fffffu);
}

enum { RCP, RCP_FTZ, RSQ, RSQ_FTZ, SQRT, SQRT_FTZ, DIVA, DIVA_FTZ, DIVF, DIVF_FTZ, DIVA_WIDE, NOPS };
static const char *NAMES[NOPS] = {"rcp.approx.f32", "rcp.approx.ftz.f32", "rsqrt.approx.f32", "rsqrt.approx.ftz.f32",
                                  "sqrt.approx.f32", "sqrt.approx.ftz.f32", "div.approx.f32", "div.approx.ftz.f32",
                                  "div.full.f32", "div.full.ftz.f32", "div.approx.f32 (a = mix32(b))"};

__host__ __device__ inline uint32_t mix32(uint32_t x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16; return x;
}

// The model: the SASS ptxas emits for each PTX instruction (sm_90, CUDA 13.0), MUFU by the tables.
template <int OP> __device__ uint32_t model(uint32_t xb, uint32_t ab) {
  float x = u2f(xb), a = u2f(ab);
  const float TINY = 1.175494350822287508e-38f, BIG = 8.50705917302346158658e+37f;
  switch (OP) {
    case RCP_FTZ: return mufu_rcp(xb);
    case RSQ_FTZ: return mufu_rsq_sqrt<false>(xb);
    case SQRT_FTZ: return mufu_rsq_sqrt<true>(xb);
    case RCP: {
      float s = fabsf(x) >= TINY ? 1.0f : 16777216.0f;
      s = fabsf(x) > BIG ? 0.25f : s;
      return f2u(__fmul_rn(s, u2f(mufu_rcp(f2u(__fmul_rn(x, s))))));
    }
    case RSQ: case SQRT: {
      bool p = fabsf(x) >= TINY;  // FSETP.GEU: true for NaN
      if (isnan(x)) p = true;
      float xs = p ? x : __fmul_rn(x, 16777216.0f);
      float y = u2f(OP == RSQ ? mufu_rsq_sqrt<false>(f2u(xs)) : mufu_rsq_sqrt<true>(f2u(xs)));
      return f2u(p ? y : __fmul_rn(y, OP == RSQ ? 4096.0f : 0.000244140625f));
    }
    case DIVA_FTZ: return f2u(fmul_ftz(a, u2f(mufu_rcp(xb))));
    case DIVA: case DIVA_WIDE: {
      bool p = fabsf(x) >= TINY || isnan(x);
      float b = p ? x : __fmul_rn(x, 16777216.0f);
      float r = u2f(mufu_rcp(f2u(b)));
      float aa = p ? a : __fmul_rn(a, 16777216.0f);
      return f2u(__fmul_rn(r, aa));
    }
    case DIVF: {
      bool big = fabsf(x) > BIG, p1 = fabsf(x) >= TINY || isnan(x);
      float b = big ? __fmul_rn(x, 0.25f) : x;
      b = p1 ? b : __fmul_rn(b, 16777216.0f);
      float r = u2f(mufu_rcp(f2u(b)));
      float aa = big ? __fmul_rn(a, 0.25f) : a;
      aa = p1 ? aa : __fmul_rn(aa, 16777216.0f);
      return f2u(__fmul_rn(r, aa));
    }
    case DIVF_FTZ: {
      bool big = fabsf(x) > BIG;
      float b = big ? fmul_ftz(x, 0.25f) : x;
      float r = u2f(mufu_rcp(f2u(b)));
      float aa = big ? fmul_ftz(a, 0.25f) : a;
      return f2u(fmul_ftz(r, aa));
    }
  }
  return 0;
}

template <int OP> __device__ __forceinline__ uint32_t gpu(uint32_t xb, uint32_t ab) {
  float x = u2f(xb), a = u2f(ab), y;
  if (OP == RCP) asm volatile("rcp.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == RCP_FTZ) asm volatile("rcp.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == RSQ) asm volatile("rsqrt.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == RSQ_FTZ) asm volatile("rsqrt.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == SQRT) asm volatile("sqrt.approx.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == SQRT_FTZ) asm volatile("sqrt.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x));
  if (OP == DIVA || OP == DIVA_WIDE) asm volatile("div.approx.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  if (OP == DIVA_FTZ) asm volatile("div.approx.ftz.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  if (OP == DIVF) asm volatile("div.full.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  if (OP == DIVF_FTZ) asm volatile("div.full.ftz.f32 %0, %1, %2;" : "=f"(y) : "f"(a), "f"(x));
  return f2u(y);
}

template <int OP> __global__ void check(unsigned long long *count, uint32_t *first) {
  unsigned long long bad = 0;
  for (unsigned long long i = blockIdx.x * (unsigned long long)blockDim.x + threadIdx.x; i < (1ull << 32);
       i += (unsigned long long)gridDim.x * blockDim.x) {
    uint32_t xb = (uint32_t)i;
    uint32_t ab = OP == DIVA_WIDE ? mix32(xb) : (0x3f800000u | (mix32(xb) & 0x7fffffu));
    uint32_t g = gpu<OP>(xb, ab), m = model<OP>(xb, ab);
    bool gn = (g & 0x7fffffffu) > 0x7f800000u, mn = (m & 0x7fffffffu) > 0x7f800000u;
    if (g != m && !(gn && mn && g == QNAN)) {
      bad++;
      unsigned long long k = atomicAdd(count + 1, 1ull);
      if (k < 8) { first[3 * k] = xb; first[3 * k + 1] = g; first[3 * k + 2] = m; }
    }
  }
  if (bad) atomicAdd(count, bad);
}

static std::vector<int8_t> load(const char *p, size_t n) {
  std::vector<int8_t> v(n);
  FILE *f = fopen(p, "rb");
  if (!f || fread(v.data(), 1, n, f) != n) { fprintf(stderr, "cannot read %s\n", p); exit(1); }
  fclose(f);
  return v;
}

int main(int argc, char **argv) {
  if (argc < 4) { fprintf(stderr, "usage: mufu_model RCP.i8 RSQ.i8 SQRT.i8\n"); return 2; }
  auto rcp = load(argv[1], 1u << 23), rsq = load(argv[2], 1u << 24), sq = load(argv[3], 1u << 24);
  int8_t *d1, *d2, *d3;
  CHECK(cudaMalloc(&d1, 1u << 23)); CHECK(cudaMalloc(&d2, 1u << 24)); CHECK(cudaMalloc(&d3, 1u << 24));
  CHECK(cudaMemcpy(d1, rcp.data(), 1u << 23, cudaMemcpyHostToDevice));
  CHECK(cudaMemcpy(d2, rsq.data(), 1u << 24, cudaMemcpyHostToDevice));
  CHECK(cudaMemcpy(d3, sq.data(), 1u << 24, cudaMemcpyHostToDevice));
  CHECK(cudaMemcpyToSymbol(T_RCP, &d1, sizeof(d1)));
  CHECK(cudaMemcpyToSymbol(T_RSQ, &d2, sizeof(d2)));
  CHECK(cudaMemcpyToSymbol(T_SQRT, &d3, sizeof(d3)));
  unsigned long long *dc; uint32_t *df;
  CHECK(cudaMalloc(&dc, 16)); CHECK(cudaMalloc(&df, 24 * 4));
  printf("{\"ops\":[");
  for (int op = 0; op < NOPS; op++) {
    CHECK(cudaMemset(dc, 0, 16)); CHECK(cudaMemset(df, 0, 96));
    switch (op) {
#define C(o) case o: check<o><<<132 * 16, 256>>>(dc, df); break;
      C(RCP) C(RCP_FTZ) C(RSQ) C(RSQ_FTZ) C(SQRT) C(SQRT_FTZ) C(DIVA) C(DIVA_FTZ) C(DIVF) C(DIVF_FTZ) C(DIVA_WIDE)
#undef C
    }
    CHECK(cudaGetLastError()); CHECK(cudaDeviceSynchronize());
    unsigned long long c[2]; uint32_t f[24];
    CHECK(cudaMemcpy(c, dc, 16, cudaMemcpyDeviceToHost)); CHECK(cudaMemcpy(f, df, 96, cudaMemcpyDeviceToHost));
    printf("%s\n{\"name\":\"%s\",\"inputs\":4294967296,\"mismatches\":%llu,\"first\":[", op ? "," : "", NAMES[op], c[0]);
    for (int k = 0; k < 8 && k < (int)c[0]; k++) printf("%s[%u,%u,%u]", k ? "," : "", f[3 * k], f[3 * k + 1], f[3 * k + 2]);
    printf("]}");
    fprintf(stderr, "%s: %llu mismatches\n", NAMES[op], c[0]);
  }
  printf("\n],\"first_format\":\"[x (divisor for div), gpu bits, model bits]\",\"nan_rule\":\"a NaN result counts as equal only if the GPU's is 0x7fffffff and the model's is a NaN\"}\n");
  return 0;
}
