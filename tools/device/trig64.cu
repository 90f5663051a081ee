// CUDA's double-precision sin, cos and tan over tests/fixtures/mathlib/trig64_inputs.bin
// (tools/device/trig64_inputs.py): out[k * n + i] = F_k(x[i]). The same source
// runs in warplight (clang-16 with libdevice, `warplight compile`) and on a GPU
// (nvcc, and the clang PTX loaded by the driver) through tools/device/trig64.sh;
// tests/math_library.rs compares the emulator with the GPU's bits.
extern "C" __global__ void trig64(const double *x, double *out, int n) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  double a = x[i];
  out[i] = sin(a);
  out[n + i] = cos(a);
  out[2 * n + i] = tan(a);
}
