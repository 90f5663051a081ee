// Texture and surface objects: the fetches ordinary CUDA code writes
// (tex1D, tex1Dfetch, tex2D, tex3D, tex2Dgather, surf2Dread/Write, txq),
// for both compilers. The texture objects, their data and the coordinates
// come from the host (tests/textures.rs; on a GPU tools/gpu/probe_tex_calls.cu).
#include "prelude.h"

extern "C" __global__ void tex1d_f(cudaTextureObject_t t, const float *x, float *out, int n) {
  int i = WL_TID;
  if (i < n) out[i] = tex1D<float>(t, x[i]);
}

extern "C" __global__ void tex1dfetch_f(cudaTextureObject_t t, const int *x, float *out, int n) {
  int i = WL_TID;
  if (i < n) out[i] = tex1Dfetch<float>(t, x[i]);
}

extern "C" __global__ void tex2d_f4(cudaTextureObject_t t, const float *x, const float *y, float4 *out, int n) {
  int i = WL_TID;
  if (i < n) out[i] = tex2D<float4>(t, x[i], y[i]);
}

// element reads of an 8-bit texture: the four bytes packed
extern "C" __global__ void tex2d_u4(cudaTextureObject_t t, const float *x, const float *y, unsigned *out, int n) {
  int i = WL_TID;
  if (i < n) {
    uchar4 c = tex2D<uchar4>(t, x[i], y[i]);
    out[i] = c.x | (unsigned)c.y << 8 | (unsigned)c.z << 16 | (unsigned)c.w << 24;
  }
}

extern "C" __global__ void tex3d_f(cudaTextureObject_t t, const float *x, const float *y, const float *z, float *out,
                                   int n) {
  int i = WL_TID;
  if (i < n) out[i] = tex3D<float>(t, x[i], y[i], z[i]);
}

extern "C" __global__ void tld4_f4(cudaTextureObject_t t, const float *x, const float *y, float4 *out, int n) {
  int i = WL_TID;
  if (i < n) {
    out[4 * i + 0] = tex2Dgather<float4>(t, x[i], y[i], 0);
    out[4 * i + 1] = tex2Dgather<float4>(t, x[i], y[i], 1);
    out[4 * i + 2] = tex2Dgather<float4>(t, x[i], y[i], 2);
    out[4 * i + 3] = tex2Dgather<float4>(t, x[i], y[i], 3);
  }
}

// x in bytes (as surf2Dread takes it), out-of-range reads under .zero and .clamp
extern "C" __global__ void surf_read(cudaSurfaceObject_t s, const int *x, const int *y, int *zero, int *clamp, int n) {
  int i = WL_TID;
  if (i < n) {
    zero[i] = surf2Dread<int>(s, x[i], y[i], cudaBoundaryModeZero);
    clamp[i] = surf2Dread<int>(s, x[i], y[i], cudaBoundaryModeClamp);
  }
}

// writes under .zero (out of range: ignored) and .clamp (out of range: the clamped element)
extern "C" __global__ void surf_write(cudaSurfaceObject_t s, const int *x, const int *y, const int *v, int clamp, int n) {
  int i = WL_TID;
  if (i < n) surf2Dwrite(v[i], s, x[i], y[i], clamp ? cudaBoundaryModeClamp : cudaBoundaryModeZero);
}

// txq: width, height, depth, channel data type, channel order, normalized coordinates
extern "C" __global__ void tex_query(cudaTextureObject_t t, int *out) {
  int w, h, d, ct, co, nc;
  asm("txq.width.b32 %0, [%1];" : "=r"(w) : "l"(t));
  asm("txq.height.b32 %0, [%1];" : "=r"(h) : "l"(t));
  asm("txq.depth.b32 %0, [%1];" : "=r"(d) : "l"(t));
  asm("txq.channel_data_type.b32 %0, [%1];" : "=r"(ct) : "l"(t));
  asm("txq.channel_order.b32 %0, [%1];" : "=r"(co) : "l"(t));
  asm("txq.normalized_coords.b32 %0, [%1];" : "=r"(nc) : "l"(t));
  if (threadIdx.x == 0) {
    out[0] = w;
    out[1] = h;
    out[2] = d;
    out[3] = ct;
    out[4] = co;
    out[5] = nc;
  }
}
