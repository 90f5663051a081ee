// Linear texture filtering, bit for bit (issue 20): one fetch per thread at
// the coordinates the host gives, all four channels written. The textures,
// texels and coordinates: tools/device/tex_filter_host.cu (which runs these
// kernels on an H200) and tests/tex_filter.rs (which runs them on warplight);
// the GPU's results: tests/fixtures/validation/h200_tex_filter.bin.z.
#include "../prelude.h"

#define K extern "C" __global__ void
#define T (blockIdx.x * blockDim.x + threadIdx.x)

K tf_1d(cudaTextureObject_t t, const float *c, float4 *out, int n) {
  int i = T;
  if (i >= n) return;
  float4 r;
  asm("tex.1d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(c[i]));
  out[i] = r;
}

K tf_2d(cudaTextureObject_t t, const float *c, float4 *out, int n) {
  int i = T;
  if (i >= n) return;
  float4 r;
  asm("tex.2d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5, %6}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(c[2 * i]), "f"(c[2 * i + 1]));
  out[i] = r;
}

K tf_3d(cudaTextureObject_t t, const float *c, float4 *out, int n) {
  int i = T;
  if (i >= n) return;
  float4 r;
  asm("tex.3d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5, %6, %7, %7}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(c[3 * i]), "f"(c[3 * i + 1]), "f"(c[3 * i + 2]));
  out[i] = r;
}
