// Runs tools/device/trig64.cu on the GPU: the nvcc build of the source
// (included below) and PTX files given on the command line (clang-16 with
// libdevice, as `warplight compile` makes them), loaded by the driver.
// Usage: trig64_host INPUTS.bin OUT_DIR [NAME=FILE.ptx ...]
// Writes OUT_DIR/nvcc.f64.bin and NAME.f64.bin (3 rows of N doubles).
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#include <cuda.h>
#include <cuda_runtime.h>
#include "trig64.cu"

static const int N = 2560, ROWS = 3;

#define CK(x) do { cudaError_t e = (x); if (e != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e)); exit(1); } } while (0)
#define CD(x) do { CUresult e = (x); if (e != CUDA_SUCCESS) { const char *s; cuGetErrorString(e, &s); fprintf(stderr, "%s: %s\n", #x, s); exit(1); } } while (0)

static void save(const std::string &path, const void *p, size_t bytes) {
  FILE *f = fopen(path.c_str(), "wb");
  if (!f || fwrite(p, 1, bytes, f) != bytes) { fprintf(stderr, "cannot write %s\n", path.c_str()); exit(1); }
  fclose(f);
}

int main(int argc, char **argv) {
  if (argc < 3) { fprintf(stderr, "usage: trig64_host INPUTS.bin OUT_DIR [NAME=FILE.ptx ...]\n"); return 2; }
  std::vector<double> in(N);
  FILE *f = fopen(argv[1], "rb");
  if (!f || fread(in.data(), 8, N, f) != (size_t)N) { fprintf(stderr, "cannot read %s\n", argv[1]); return 1; }
  fclose(f);
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
  for (int a = 3; a < argc; a++) {
    std::string arg = argv[a];
    size_t eq = arg.find('=');
    std::string name = arg.substr(0, eq), path = arg.substr(eq + 1);
    FILE *pf = fopen(path.c_str(), "rb");
    if (!pf) { fprintf(stderr, "cannot read %s\n", path.c_str()); return 1; }
    std::string ptx;
    char buf[65536];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, pf)) > 0) ptx.append(buf, k);
    fclose(pf);
    CUmodule m;
    char log[8192] = {0};
    CUjit_option opts[] = {CU_JIT_ERROR_LOG_BUFFER, CU_JIT_ERROR_LOG_BUFFER_SIZE_BYTES};
    void *vals[] = {log, (void *)(size_t)sizeof log};
    CUresult r = cuModuleLoadDataEx(&m, ptx.c_str(), 2, opts, vals);
    if (r != CUDA_SUCCESS) { fprintf(stderr, "%s: JIT failed: %s\n", path.c_str(), log); return 1; }
    CUfunction fn;
    CD(cuModuleGetFunction(&fn, m, "trig64"));
    int n = N;
    void *params[] = {&x, &o, &n};
    CD(cuLaunchKernel(fn, N / 128, 1, 1, 128, 1, 1, 0, 0, params, 0));
    fetch(name);
    printf("%s: ran %s\n", name.c_str(), path.c_str());
  }
  return 0;
}
