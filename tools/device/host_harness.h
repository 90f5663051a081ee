// Host code shared by the device-measurement tools (trig64_host.cu,
// mathlib_host.cu): error checks, reading the inputs, writing the results,
// and running a kernel of PTX files given on the command line as
// NAME=FILE.ptx (clang-16 with libdevice, as `warplight compile` makes
// them), loaded by the driver's JIT. Any failure prints what failed and
// exits with status 1.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <string>
#include <cuda.h>
#include <cuda_runtime.h>

// A CUDA runtime call that must succeed.
#define CK(x) do { cudaError_t e = (x); if (e != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e)); exit(1); } } while (0)
// A CUDA driver call that must succeed.
#define CD(x) do { CUresult e = (x); if (e != CUDA_SUCCESS) { const char *s; cuGetErrorString(e, &s); fprintf(stderr, "%s: %s\n", #x, s); exit(1); } } while (0)

// Reads exactly `count` items of `size` bytes from the file at `path`.
static void read_inputs(const char *path, void *p, size_t size, size_t count) {
  FILE *f = fopen(path, "rb");
  if (!f || fread(p, size, count, f) != count) { fprintf(stderr, "cannot read %s\n", path); exit(1); }
  fclose(f);
}

// Writes `bytes` bytes to the file at `path`.
static void save(const std::string &path, const void *p, size_t bytes) {
  FILE *f = fopen(path.c_str(), "wb");
  if (!f || fwrite(p, 1, bytes, f) != bytes) { fprintf(stderr, "cannot write %s\n", path.c_str()); exit(1); }
  fclose(f);
}

// For each argument NAME=FILE.ptx of argv[first..argc): JIT-loads the PTX,
// launches its `kernel` with `params` on `grid` CTAs of `block` threads,
// calls fetch(NAME) (which synchronises and saves the results) and prints
// "NAME: ran FILE.ptx".
template <class Fetch>
static void run_ptx_files(int argc, char **argv, int first, const char *kernel, void **params, unsigned grid,
                          unsigned block, Fetch fetch) {
  for (int a = first; a < argc; a++) {
    std::string arg = argv[a];
    size_t eq = arg.find('=');
    std::string name = arg.substr(0, eq), path = arg.substr(eq + 1);
    FILE *pf = fopen(path.c_str(), "rb");
    if (!pf) { fprintf(stderr, "cannot read %s\n", path.c_str()); exit(1); }
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
    if (r != CUDA_SUCCESS) { fprintf(stderr, "%s: JIT failed: %s\n", path.c_str(), log); exit(1); }
    CUfunction fn;
    CD(cuModuleGetFunction(&fn, m, kernel));
    CD(cuLaunchKernel(fn, grid, 1, 1, block, 1, 1, 0, 0, params, 0));
    fetch(name);
    printf("%s: ran %s\n", name.c_str(), path.c_str());
  }
}
