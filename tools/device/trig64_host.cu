// Runs tools/device/trig64.cu on the GPU: the nvcc build of the source
// (included below) and PTX files given on the command line (clang-16 with
// libdevice, as `warplight compile` makes them), loaded by the driver.
// Usage: trig64_host INPUTS.bin OUT_DIR [NAME=FILE.ptx ...]
// Writes OUT_DIR/nvcc.f64.bin and NAME.f64.bin (3 rows of N doubles).
#include <string>
#include <vector>
#include "host_harness.h"
#include "trig64.cu"

static const int N = 2560, ROWS = 3;

int main(int argc, char **argv) {
  if (argc < 3) { fprintf(stderr, "usage: trig64_host INPUTS.bin OUT_DIR [NAME=FILE.ptx ...]\n"); return 2; }
  std::vector<double> in(N);
  read_inputs(argv[1], in.data(), 8, N);
  std::string out = argv[2];
  double *x, *o;
  CK(cudaMalloc(&x, N * 8));
  CK(cudaMalloc(&o, ROWS * N * 8));
  CK(cudaMemcpy(x, in.data(), N * 8, cudaMemcpyHostToDevice));
  std::vector<double> ho(ROWS * N);
  auto fetch = [&](const std::string &name) {
    CK(cudaDeviceSynchronize());
    CK(cudaMemcpy(ho.data(), o, ho.size() * 8, cudaMemcpyDeviceToHost));
    save(out + "/" + name + ".f64.bin", ho.data(), ho.size() * 8);
    CK(cudaMemset(o, 0xff, ROWS * N * 8));
  };
  CK(cudaMemset(o, 0xff, ROWS * N * 8));
  trig64<<<N / 128, 128>>>(x, o, N);
  CK(cudaGetLastError());
  fetch("nvcc");
  printf("nvcc: ran the nvcc build\n");
  int n = N;
  void *params[] = {&x, &o, &n};
  run_ptx_files(argc, argv, 3, "trig64", params, N / 128, 128, fetch);
  return 0;
}
