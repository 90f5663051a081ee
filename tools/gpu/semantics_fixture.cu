// Runs the instruction-semantics test kernels (kernels/tests/semantics_*.cu) on a
// real GPU and prints their inputs and outputs as JSON: the fixture
// tests/fixtures/gpu_semantics.json that warplight's results are compared with.
//
// Build and run on a machine with a GPU and the CUDA toolkit:
//   nvcc -O2 -arch=sm_90 -Ikernels -o /tmp/semfix tools/gpu/semantics_fixture.cu
//   /tmp/semfix > tests/fixtures/gpu_semantics.json
#include <cstdio>
#include <cstring>
#include <cstdint>
#include <vector>
#include <string>
#include <cuda_runtime.h>

#include "../../kernels/tests/semantics_int.cu"
#include "../../kernels/tests/semantics_float.cu"
#include "../../kernels/tests/semantics_ext.cu"

static const int N = 256;
static const uint32_t INT_EDGES[16] = {0u, 1u, 2u, 3u, 7u, 31u, 32u, 33u, 0x7fffffffu, 0x80000000u,
                                       0xffffffffu, 0xfffffff9u, 100u, 0xffu, 0x12345678u, 0x80000001u};
static uint32_t fbits(float f) { uint32_t u; memcpy(&u, &f, 4); return u; }
static uint64_t dbits(double f) { uint64_t u; memcpy(&u, &f, 8); return u; }

#define CHECK(x) do { cudaError_t e = (x); if (e != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e)); exit(1); } } while (0)

enum Kind { INT_PAIRS, BFE_PAIRS, FLOAT_PAIRS, INT_LIST, DOUBLE_PAIRS };

struct Case { const char *name; const void *fn; Kind kind; int out_words; };

static std::vector<uint64_t> inputs(Kind k, int which) {
  std::vector<uint32_t> fe = {fbits(0.0f), fbits(-0.0f), fbits(1.0f), fbits(-1.0f), fbits(1.5f),
                              fbits(9.313225746154785e-10f), fbits(3e38f), fbits(-3e38f), 0x7f800000u, 0xff800000u,
                              0x7fc00000u, fbits(1e-40f), fbits(1.0000001192092896f), fbits(0.1f), fbits(2.5f),
                              fbits(-3.5f)};
  std::vector<double> de = {1.0 + 9.313225746154785e-10, -(1.0 + 9.313225746154785e-10), 1e300, -1e300, 0.1,
                            1.0 / 3.0, 1.401298464324817e-45, 1e-320, 0.0 / 0.0 * 0.0, 1.0 / 0.0,
                            3.4028235677973366e38, 16777217.0, -0.0, 0.0, 1.5, 1.2676506002282294e30};
  std::vector<uint64_t> v(N);
  for (int i = 0; i < N; i++) {
    int j = which == 0 ? i / 16 : i % 16;
    switch (k) {
      case INT_PAIRS: v[i] = INT_EDGES[j]; break;
      case BFE_PAIRS: v[i] = which == 0 ? INT_EDGES[i / 16] ^ (uint32_t)(i * 0x9E3779B9u)
                                        : (uint32_t)((i * 7) % 40) | (uint32_t)(((i * 13) % 40) << 8); break;
      case FLOAT_PAIRS: v[i] = fe[j]; break;
      case INT_LIST: {
        static const int32_t l[16] = {0, 1, -1, 16777217, -16777217, 0x7fffffff, (int32_t)0x80000000, 33554435,
                                      123456789, -123456789, 3, -7, 100, 255, 0x12345678, (int32_t)0x80000001};
        v[i] = (uint32_t)(i < 16 ? l[i] : (int32_t)(i * 2654435761u));
        break;
      }
      case DOUBLE_PAIRS: v[i] = dbits(de[j]); break;
    }
  }
  return v;
}

int main() {
  Case cases[] = {
      {"sem_shl_b32", (const void *)sem_shl_b32, INT_PAIRS, 1}, {"sem_shr_u32", (const void *)sem_shr_u32, INT_PAIRS, 1},
      {"sem_shr_s32", (const void *)sem_shr_s32, INT_PAIRS, 1}, {"sem_div_u32", (const void *)sem_div_u32, INT_PAIRS, 1},
      {"sem_rem_u32", (const void *)sem_rem_u32, INT_PAIRS, 1}, {"sem_div_s32", (const void *)sem_div_s32, INT_PAIRS, 1},
      {"sem_rem_s32", (const void *)sem_rem_s32, INT_PAIRS, 1},
      {"sem_mul_hi_u32", (const void *)sem_mul_hi_u32, INT_PAIRS, 1},
      {"sem_mul_hi_s32", (const void *)sem_mul_hi_s32, INT_PAIRS, 1},
      {"sem_mul24_lo_s32", (const void *)sem_mul24_lo_s32, INT_PAIRS, 1},
      {"sem_mul24_hi_u32", (const void *)sem_mul24_hi_u32, INT_PAIRS, 1},
      {"sem_min_s32", (const void *)sem_min_s32, INT_PAIRS, 1}, {"sem_max_u32", (const void *)sem_max_u32, INT_PAIRS, 1},
      {"sem_add_sat_s32", (const void *)sem_add_sat_s32, INT_PAIRS, 1},
      {"sem_sub_sat_s32", (const void *)sem_sub_sat_s32, INT_PAIRS, 1},
      {"sem_popc_b32", (const void *)sem_popc_b32, INT_PAIRS, 1}, {"sem_clz_b32", (const void *)sem_clz_b32, INT_PAIRS, 1},
      {"sem_brev_b32", (const void *)sem_brev_b32, INT_PAIRS, 1}, {"sem_abs_s32", (const void *)sem_abs_s32, INT_PAIRS, 1},
      {"sem_neg_s32", (const void *)sem_neg_s32, INT_PAIRS, 1}, {"sem_cnot_b32", (const void *)sem_cnot_b32, INT_PAIRS, 1},
      {"sem_bfe_s32", (const void *)sem_bfe_s32, BFE_PAIRS, 1}, {"sem_bfi_b32", (const void *)sem_bfi_b32, INT_PAIRS, 1},
      {"sem_prmt_b32", (const void *)sem_prmt_b32, INT_PAIRS, 1}, {"sem_wide", (const void *)sem_wide, INT_PAIRS, 4},
      {"sem_add_rn_f32", (const void *)sem_add_rn_f32, FLOAT_PAIRS, 1},
      {"sem_add_rz_f32", (const void *)sem_add_rz_f32, FLOAT_PAIRS, 1},
      {"sem_add_rm_f32", (const void *)sem_add_rm_f32, FLOAT_PAIRS, 1},
      {"sem_add_rp_f32", (const void *)sem_add_rp_f32, FLOAT_PAIRS, 1},
      {"sem_mul_rn_f32", (const void *)sem_mul_rn_f32, FLOAT_PAIRS, 1},
      {"sem_mul_rz_f32", (const void *)sem_mul_rz_f32, FLOAT_PAIRS, 1},
      {"sem_div_rn_f32", (const void *)sem_div_rn_f32, FLOAT_PAIRS, 1},
      {"sem_min_f32", (const void *)sem_min_f32, FLOAT_PAIRS, 1}, {"sem_max_f32", (const void *)sem_max_f32, FLOAT_PAIRS, 1},
      {"sem_add_ftz_f32", (const void *)sem_add_ftz_f32, FLOAT_PAIRS, 1},
      {"sem_sqrt_rn_f32", (const void *)sem_sqrt_rn_f32, FLOAT_PAIRS, 1},
      {"sem_rcp_rn_f32", (const void *)sem_rcp_rn_f32, FLOAT_PAIRS, 1},
      {"sem_abs_f32", (const void *)sem_abs_f32, FLOAT_PAIRS, 1}, {"sem_neg_f32", (const void *)sem_neg_f32, FLOAT_PAIRS, 1},
      {"sem_cvt_sat_f32", (const void *)sem_cvt_sat_f32, FLOAT_PAIRS, 1},
      {"sem_cvt_rni_f32", (const void *)sem_cvt_rni_f32, FLOAT_PAIRS, 1},
      {"sem_cvt_rni_s32", (const void *)sem_cvt_rni_s32, FLOAT_PAIRS, 1},
      {"sem_cvt_rzi_s32", (const void *)sem_cvt_rzi_s32, FLOAT_PAIRS, 1},
      {"sem_cvt_rmi_s32", (const void *)sem_cvt_rmi_s32, FLOAT_PAIRS, 1},
      {"sem_cvt_rpi_s32", (const void *)sem_cvt_rpi_s32, FLOAT_PAIRS, 1},
      {"sem_cvt_rzi_u32", (const void *)sem_cvt_rzi_u32, FLOAT_PAIRS, 1},
      {"sem_fma_rn_f32", (const void *)sem_fma_rn_f32, FLOAT_PAIRS, 1},
      {"sem_cvt_i2f", (const void *)sem_cvt_i2f, INT_LIST, 4},
      {"sem_cvt_sat_int", (const void *)sem_cvt_sat_int, INT_LIST, 2},
      {"sem_f64", (const void *)sem_f64, DOUBLE_PAIRS, 4}, {"sem_setp", (const void *)sem_setp, FLOAT_PAIRS, 1},
      // semantics_ext.cu (issue 20, "Also")
      {"sem_redux", (const void *)sem_redux, INT_PAIRS, 8}, {"sem_match", (const void *)sem_match, INT_PAIRS, 7},
      {"sem_bar_red", (const void *)sem_bar_red, INT_PAIRS, 3},
      {"sem_prmt_modes", (const void *)sem_prmt_modes, INT_PAIRS, 7}, {"sem_bits", (const void *)sem_bits, INT_PAIRS, 10},
      {"sem_dp", (const void *)sem_dp, INT_PAIRS, 6}, {"sem_carry", (const void *)sem_carry, INT_PAIRS, 8},
      {"sem_half", (const void *)sem_half, FLOAT_PAIRS, 18},
  };
  cudaDeviceProp prop;
  CHECK(cudaGetDeviceProperties(&prop, 0));
  printf("{\n  \"device\": \"%s\",\n  \"compute_capability\": \"%d.%d\",\n  \"n\": %d,\n  \"kernels\": {\n", prop.name,
         prop.major, prop.minor, N);
  int nc = sizeof(cases) / sizeof(cases[0]);
  for (int c = 0; c < nc; c++) {
    Case &cs = cases[c];
    bool wide_in = cs.kind == DOUBLE_PAIRS;
    int in_bytes = wide_in ? 8 : 4;
    std::vector<uint64_t> a = inputs(cs.kind, 0), b = inputs(cs.kind, 1);
    std::vector<unsigned char> ha(N * in_bytes), hb(N * in_bytes);
    for (int i = 0; i < N; i++) {
      memcpy(&ha[i * in_bytes], &a[i], in_bytes);
      memcpy(&hb[i * in_bytes], &b[i], in_bytes);
    }
    void *da, *db, *dout;
    int out_bytes = N * 4 * cs.out_words;
    CHECK(cudaMalloc(&da, N * in_bytes));
    CHECK(cudaMalloc(&db, N * in_bytes));
    CHECK(cudaMalloc(&dout, out_bytes));
    CHECK(cudaMemcpy(da, ha.data(), N * in_bytes, cudaMemcpyHostToDevice));
    CHECK(cudaMemcpy(db, hb.data(), N * in_bytes, cudaMemcpyHostToDevice));
    CHECK(cudaMemset(dout, 0, out_bytes));
    int n = N;
    void *args[] = {&dout, &da, &db, &n};
    CHECK(cudaLaunchKernel(cs.fn, dim3(1), dim3(N), args, 0, 0));
    CHECK(cudaDeviceSynchronize());
    std::vector<uint32_t> out(N * cs.out_words);
    CHECK(cudaMemcpy(out.data(), dout, out_bytes, cudaMemcpyDeviceToHost));
    printf("    \"%s\": {\n      \"in_bytes\": %d,\n      \"a\": [", cs.name, in_bytes);
    for (int i = 0; i < N; i++) printf("%s%llu", i ? "," : "", (unsigned long long)a[i]);
    printf("],\n      \"b\": [");
    for (int i = 0; i < N; i++) printf("%s%llu", i ? "," : "", (unsigned long long)b[i]);
    printf("],\n      \"out_words\": [");
    for (int i = 0; i < N * cs.out_words; i++) printf("%s%u", i ? "," : "", out[i]);
    printf("]\n    }%s\n", c + 1 < nc ? "," : "");
    cudaFree(da);
    cudaFree(db);
    cudaFree(dout);
  }
  printf("  }\n}\n");
  return 0;
}
