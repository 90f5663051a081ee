// CUDA's math library over a dense input sample, one output row per function:
// out[k * n + i] = F_k(x[i], y[i]). The same source runs in warplight (clang-16
// with libdevice, `warplight compile`) and on a GPU (nvcc, and the clang PTX
// loaded by the driver) through tools/device/mathlib.sh; tests/math_library.rs
// compares the emulator with the GPU's bits (tests/fixtures/mathlib/).
// Keep the order of the rows in step with MATHLIB_F32 / MATHLIB_F64 in the test.
extern "C" __global__ void mathlib(const float *x, const float *y, float *out, double *outd, int n) {
  int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float a = x[i], b = y[i];
  int ia = __float_as_int(a), ib = __float_as_int(b);
  int k = 0;
#define F(e) out[(k++) * n + i] = (e);
#define I(e) out[(k++) * n + i] = __int_as_float(e);
  F(expf(a)) F(exp2f(a)) F(exp10f(a)) F(expm1f(a)) F(logf(a)) F(log2f(a)) F(log10f(a)) F(log1pf(a))
  F(sinf(a)) F(cosf(a)) F(tanf(a)) F(asinf(a)) F(acosf(a)) F(atanf(a)) F(atan2f(a, b))
  F(sinhf(a)) F(coshf(a)) F(tanhf(a)) F(powf(a, b)) F(sqrtf(a)) F(rsqrtf(a)) F(cbrtf(a))
  F(floorf(a)) F(ceilf(a)) F(roundf(a)) F(truncf(a)) F(fabsf(a)) F(fminf(a, b)) F(fmaxf(a, b))
  F(fmodf(a, b)) F(hypotf(a, b)) F(erff(a)) F(a / b) F(min(a, b)) F(max(a, b)) F(abs(a))
  F(__expf(a)) F(__logf(a)) F(__sinf(a)) F(__cosf(a)) F(__powf(a, b)) F(__fdividef(a, b))
  I(min(ia, ib)) I(max(ia, ib)) I(abs(ia))
#undef F
#undef I
  double da = a, db = b;
  int kd = 0;
#define D(e) outd[(kd++) * n + i] = (e);
  D(exp(da)) D(log(da)) D(atan2(da, db)) D(pow(da, db)) D(sqrt(da))
#undef D
}
