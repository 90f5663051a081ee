// Runs tools/device/mathlib.cu on the GPU: the nvcc build of the source
// (included below) and PTX files given on the command line (clang-16 with
// libdevice, as `warplight compile` makes them), loaded by the driver.
// Usage: mathlib_host INPUTS.bin OUT_DIR [NAME=FILE.ptx ...]
// Writes OUT_DIR/nvcc.f32.bin, nvcc.f64.bin and NAME.f32.bin, NAME.f64.bin.
#include <string>
#include <vector>
#include "host_harness.h"
#include "mathlib.cu"

static const int N = 2048, F32_ROWS = 45, F64_ROWS = 5;

int main(int argc, char **argv) {
  if (argc < 3) { fprintf(stderr, "usage: mathlib_host INPUTS.bin OUT_DIR [NAME=FILE.ptx ...]\n"); return 2; }
  std::vector<float> in(2 * N);
  read_inputs(argv[1], in.data(), 4, 2 * N);
  std::string out = argv[2];
  float *x, *y, *o;
  double *od;
  CK(cudaMalloc(&x, N * 4)); CK(cudaMalloc(&y, N * 4));
  CK(cudaMalloc(&o, F32_ROWS * N * 4)); CK(cudaMalloc(&od, F64_ROWS * N * 8));
  CK(cudaMemcpy(x, in.data(), N * 4, cudaMemcpyHostToDevice));
  CK(cudaMemcpy(y, in.data() + N, N * 4, cudaMemcpyHostToDevice));
  std::vector<float> ho(F32_ROWS * N);
  std::vector<double> hod(F64_ROWS * N);
  auto fetch = [&](const std::string &name) {
    CK(cudaDeviceSynchronize());
    CK(cudaMemcpy(ho.data(), o, ho.size() * 4, cudaMemcpyDeviceToHost));
    CK(cudaMemcpy(hod.data(), od, hod.size() * 8, cudaMemcpyDeviceToHost));
    save(out + "/" + name + ".f32.bin", ho.data(), ho.size() * 4);
    save(out + "/" + name + ".f64.bin", hod.data(), hod.size() * 8);
    CK(cudaMemset(o, 0xff, F32_ROWS * N * 4)); CK(cudaMemset(od, 0xff, F64_ROWS * N * 8));
  };
  CK(cudaMemset(o, 0xff, F32_ROWS * N * 4)); CK(cudaMemset(od, 0xff, F64_ROWS * N * 8));
  mathlib<<<N / 128, 128>>>(x, y, o, od, N);
  CK(cudaGetLastError());
  fetch("nvcc");
  int n = N;
  void *params[] = {&x, &y, &o, &od, &n};
  run_ptx_files(argc, argv, 3, "mathlib", params, N / 128, 128, fetch);
  printf("nvcc: ran the nvcc build\n");
  return 0;
}
