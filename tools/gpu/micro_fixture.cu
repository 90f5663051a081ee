// Launches the memory microbenchmarks of kernels/micro/micro.cu, one launch per
// configuration, for Nsight Compute to measure (tools/gpu/measure_micro.sh).
// Writes the launch list (id kernel a b) to argv[1].
#include <cstdio>
#include <cuda_runtime.h>
#include "../../kernels/micro/micro.cu"

#define CHECK(x) do { cudaError_t e = (x); if (e != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e)); return 1; } } while (0)

struct L { const char *name; const void *fn; int a, b; };

int main(int argc, char **argv) {
  L ls[] = {
    {"ld_stride", (const void *)ld_stride, 1, 0}, {"ld_stride", (const void *)ld_stride, 1, 1},
    {"ld_stride", (const void *)ld_stride, 2, 0}, {"ld_stride", (const void *)ld_stride, 4, 0},
    {"ld_stride", (const void *)ld_stride, 8, 0}, {"ld_stride", (const void *)ld_stride, 32, 0},
    {"ld_stride", (const void *)ld_stride, 0, 0},
    {"st_stride", (const void *)st_stride, 1, 0}, {"st_stride", (const void *)st_stride, 2, 0},
    {"st_stride", (const void *)st_stride, 8, 0}, {"st_stride", (const void *)st_stride, 32, 0},
    {"ld_v2", (const void *)ld_v2, 1, 0}, {"ld_v2", (const void *)ld_v2, 2, 0}, {"ld_v2", (const void *)ld_v2, 4, 0},
    {"ld_v4", (const void *)ld_v4, 1, 0}, {"ld_v4", (const void *)ld_v4, 2, 0},
    {"ld_divergent", (const void *)ld_divergent, 2, 0}, {"ld_divergent", (const void *)ld_divergent, 3, 0},
    {"ld_divergent", (const void *)ld_divergent, 32, 0},
    {"ld_gather", (const void *)ld_gather, 7, 0}, {"ld_gather", (const void *)ld_gather, 1021, 0},
    {"ldg_gather", (const void *)ldg_gather, 7, 0}, {"ldg_gather", (const void *)ldg_gather, 1021, 0},
    {"sh_stride", (const void *)sh_stride, 1, 0}, {"sh_stride", (const void *)sh_stride, 2, 0},
    {"sh_stride", (const void *)sh_stride, 4, 0}, {"sh_stride", (const void *)sh_stride, 8, 0},
    {"sh_stride", (const void *)sh_stride, 16, 0}, {"sh_stride", (const void *)sh_stride, 32, 0},
    {"sh_stride", (const void *)sh_stride, 33, 0},
    {"sh_v2", (const void *)sh_v2, 1, 0}, {"sh_v2", (const void *)sh_v2, 2, 0}, {"sh_v2", (const void *)sh_v2, 4, 0},
    {"sh_v2", (const void *)sh_v2, 17, 0},
    {"sh_v4", (const void *)sh_v4, 1, 0}, {"sh_v4", (const void *)sh_v4, 2, 0}, {"sh_v4", (const void *)sh_v4, 3, 0},
    {"sh_v4", (const void *)sh_v4, 9, 0},
    {"atom_one", (const void *)atom_one, 0, 0}, {"atom_spread", (const void *)atom_spread, 32, 0},
    {"atom_spread", (const void *)atom_spread, 1024, 0}, {"atom_ret", (const void *)atom_ret, 1, 0},
    {"atom_ret", (const void *)atom_ret, 64, 0},
    {"local_array", (const void *)local_array, 1, 0}, {"local_array", (const void *)local_array, 0, 0},
    {"local_array", (const void *)local_array, 7, 0},
    {"local_big", (const void *)local_big, 0, 0}, {"local_big", (const void *)local_big, 1, 0},
    {"local_big", (const void *)local_big, 8, 0},
    {"votes", (const void *)votes, 3, 0}, {"votes", (const void *)votes, 100, 0},
  };
  const int N = 1 << 20;
  float *in, *out;
  CHECK(cudaMalloc(&in, N * sizeof(float)));
  CHECK(cudaMalloc(&out, N * sizeof(float)));
  CHECK(cudaMemset(in, 0, N * sizeof(float)));
  FILE *f = fopen(argc > 1 ? argv[1] : "launches.txt", "w");
  int n = sizeof(ls) / sizeof(ls[0]);
  for (int i = 0; i < n; i++) {
    CHECK(cudaMemset(out, 0, N * sizeof(float)));
    void *args[] = {&out, &in, &ls[i].a, &ls[i].b};
    CHECK(cudaLaunchKernel(ls[i].fn, dim3(64), dim3(256), args, 0, 0));
    CHECK(cudaDeviceSynchronize());
    fprintf(f, "%d %s %d %d\n", i, ls[i].name, ls[i].a, ls[i].b);
  }
  fclose(f);
  return 0;
}
