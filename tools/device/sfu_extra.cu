// Structure of the bare MUFU units (the .ftz forms, which ptxas maps to one
// MUFU instruction each): whether ex2's result depends on its input only
// through a fixed-point value, and the complete result tables of rcp, rsqrt and
// sqrt over the binades that (by the scale invariance sfu_sweep.cu found) fix
// them everywhere. Prints JSON on stdout; writes the tables as int8 deltas
// ord(y) - ord(RN(exact)) to DIR/{rcp_1_2,rsqrt_1_4,sqrt_1_4}.i8.
//
//   nvcc -O3 -arch=sm_90 -o /tmp/sfu_extra tools/device/sfu_extra.cu && /tmp/sfu_extra DIR > sfu_extra.json
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <string>
#include <vector>
#include <cuda_runtime.h>

#define CHECK(x) do { cudaError_t e_ = (x); if (e_ != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e_)); exit(1); } } while (0)

__device__ __forceinline__ float ex2f(float x) { float y; asm volatile("ex2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x)); return y; }
__device__ __forceinline__ float rcpf(float x) { float y; asm volatile("rcp.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x)); return y; }
__device__ __forceinline__ float rsqf(float x) { float y; asm volatile("rsqrt.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x)); return y; }
__device__ __forceinline__ float sqrf(float x) { float y; asm volatile("sqrt.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x)); return y; }
__device__ __forceinline__ float lg2f(float x) { float y; asm volatile("lg2.approx.ftz.f32 %0, %1;" : "=f"(y) : "f"(x)); return y; }

__device__ __forceinline__ long long ord(uint32_t b) {
  return (b & 0x80000000u) ? -(long long)(b & 0x7fffffffu) : (long long)b;
}

#define NC 16
// 0: shift  y(x) == y(x - k) * 2^k, k = floor(x), for x in [-100, 100] with x - k exact and y normal
// 1..6: y(x) == y(floor(x * 2^F) / 2^F) for F = 16, 18, 20, 21, 22, 23 (|x| < 128)
// 7..12: y(x) == y(rint(x * 2^F) / 2^F) for the same F
// 13: lg2: y(x) == RN(e + L) where L = y(m) exactly representable... (only counted where y(m) * 2^k exact) -- see host
__global__ void ex2_structure(unsigned long long *hits, unsigned long long *elig) {
  unsigned long long h[NC] = {0}, e[NC] = {0};
  const int F[6] = {16, 18, 20, 21, 22, 23};
  for (unsigned long long i = blockIdx.x * (unsigned long long)blockDim.x + threadIdx.x; i < (1ull << 32);
       i += (unsigned long long)gridDim.x * blockDim.x) {
    uint32_t xb = (uint32_t)i;
    float x = __uint_as_float(xb);
    if (!(fabsf(x) < 128.0f)) continue;
    float y = ex2f(x);
    uint32_t yb = __float_as_uint(y);
    if (fabsf(x) < 100.0f && fabsf(y) >= 1.17549435e-38f && !isinf(y)) {
      double k = floor((double)x);
      double f = (double)x - k;
      if ((double)(float)f == f) {
        e[0]++;
        if (__float_as_uint(ldexpf(ex2f((float)f), (int)k)) == yb) h[0]++;
      }
    }
#pragma unroll
    for (int j = 0; j < 6; j++) {
      double s = ldexp(1.0, F[j]);
      float qt = (float)(floor((double)x * s) / s), qr = (float)(rint((double)x * s) / s);
      e[1 + j]++; e[7 + j]++;
      if (__float_as_uint(ex2f(qt)) == yb) h[1 + j]++;
      if (__float_as_uint(ex2f(qr)) == yb) h[7 + j]++;
    }
  }
  for (int j = 0; j < NC; j++) { if (h[j]) atomicAdd(&hits[j], h[j]); if (e[j]) atomicAdd(&elig[j], e[j]); }
}

// Tables over [lo, lo + n ulps): delta = ord(y) - ord(RN(exact)).
template <int K> __global__ void table(uint32_t lo, uint32_t n, int8_t *out, unsigned long long *hist) {
  uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float x = __uint_as_float(lo + i);
  float y; double r;
  if (K == 0) { y = rcpf(x); r = 1.0 / (double)x; }
  else if (K == 1) { y = rsqf(x); r = 1.0 / sqrt((double)x); }
  else if (K == 2) { y = sqrf(x); r = sqrt((double)x); }
  else { y = lg2f(x); r = log2((double)x); }
  long long d = ord(__float_as_uint(y)) - ord(__float_as_uint(__double2float_rn(r)));
  int c = d < -8 ? -8 : (d > 8 ? 8 : (int)d);
  out[i] = (int8_t)c;
  atomicAdd(&hist[c + 8], 1ull);
}

int main(int argc, char **argv) {
  std::string dir = argc > 1 ? argv[1] : ".";
  unsigned long long *dh, *de;
  CHECK(cudaMalloc(&dh, NC * 8)); CHECK(cudaMalloc(&de, NC * 8));
  CHECK(cudaMemset(dh, 0, NC * 8)); CHECK(cudaMemset(de, 0, NC * 8));
  ex2_structure<<<132 * 16, 256>>>(dh, de);
  CHECK(cudaGetLastError()); CHECK(cudaDeviceSynchronize());
  unsigned long long h[NC], e[NC];
  CHECK(cudaMemcpy(h, dh, NC * 8, cudaMemcpyDeviceToHost)); CHECK(cudaMemcpy(e, de, NC * 8, cudaMemcpyDeviceToHost));
  printf("{\"ex2_ftz_structure\":{\"names\":[\"shift: y(x) == y(x-k)*2^k, k=floor(x)\"");
  const int F[6] = {16, 18, 20, 21, 22, 23};
  for (int j = 0; j < 6; j++) printf(",\"y(x) == y(floor(x*2^%d)/2^%d)\"", F[j], F[j]);
  for (int j = 0; j < 6; j++) printf(",\"y(x) == y(rint(x*2^%d)/2^%d)\"", F[j], F[j]);
  printf("],\"hits\":[");
  for (int j = 0; j < 13; j++) printf("%s%llu", j ? "," : "", h[j]);
  printf("],\"eligible\":[");
  for (int j = 0; j < 13; j++) printf("%s%llu", j ? "," : "", e[j]);
  printf("]},\n\"tables\":[");
  const char *names[4] = {"rcp_1_2", "rsqrt_1_4", "sqrt_1_4", "lg2_1_2"};
  const char *ops[4] = {"rcp.approx.ftz.f32", "rsqrt.approx.ftz.f32", "sqrt.approx.ftz.f32", "lg2.approx.ftz.f32"};
  uint32_t ns[4] = {1u << 23, 1u << 24, 1u << 24, 1u << 23};
  int8_t *dout; unsigned long long *dhist;
  CHECK(cudaMalloc(&dout, 1u << 24)); CHECK(cudaMalloc(&dhist, 17 * 8));
  std::vector<int8_t> buf(1u << 24);
  for (int k = 0; k < 4; k++) {
    CHECK(cudaMemset(dhist, 0, 17 * 8));
    uint32_t n = ns[k];
    if (k == 0) table<0><<<(n + 255) / 256, 256>>>(0x3f800000u, n, dout, dhist);
    if (k == 1) table<1><<<(n + 255) / 256, 256>>>(0x3f800000u, n, dout, dhist);
    if (k == 2) table<2><<<(n + 255) / 256, 256>>>(0x3f800000u, n, dout, dhist);
    if (k == 3) table<3><<<(n + 255) / 256, 256>>>(0x3f800000u, n, dout, dhist);
    CHECK(cudaGetLastError()); CHECK(cudaDeviceSynchronize());
    unsigned long long hh[17];
    CHECK(cudaMemcpy(hh, dhist, 17 * 8, cudaMemcpyDeviceToHost));
    CHECK(cudaMemcpy(buf.data(), dout, n, cudaMemcpyDeviceToHost));
    std::string path = dir + "/" + names[k] + ".i8";
    FILE *f = fopen(path.c_str(), "wb"); fwrite(buf.data(), 1, n, f); fclose(f);
    printf("%s{\"name\":\"%s\",\"op\":\"%s\",\"first_input\":%u,\"count\":%u,\"delta_hist_-8_to_8\":[", k ? "," : "", names[k],
           ops[k], 0x3f800000u, n);
    for (int j = 0; j < 17; j++) printf("%s%llu", j ? "," : "", hh[j]);
    printf("]}");
  }
  printf("]}\n");
  return 0;
}
