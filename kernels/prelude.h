// warplight's CUDA prelude: the CUDA keywords and device intrinsics that
// kernels use, for clang-16 without the CUDA SDK. Under nvcc the SDK headers
// provide the same names, and this file defines nothing.
//
// Every intrinsic keeps its CUDA name so one kernel source compiles with both
// compilers. Each maps to a clang builtin that lowers to the named PTX.
#pragma once

#if !defined(__NVCC__)

#define __device__ __attribute__((device))
#define __global__ __attribute__((global))
#define __host__ __attribute__((host))
#define __shared__ __attribute__((shared))
#define __constant__ __attribute__((constant))
#define __forceinline__ __inline__ __attribute__((always_inline))
#define __noinline__ __attribute__((noinline))

// threadIdx, blockIdx, blockDim, gridDim, warpSize
#include <__clang_cuda_builtin_vars.h>

#define WL_DEV static __device__ __forceinline__

// ---- vector types (as the SDK lays them out) ----
struct alignas(8) float2 { float x, y; };
struct alignas(16) float4 { float x, y, z, w; };
struct alignas(8) int2 { int x, y; };
struct alignas(16) int4 { int x, y, z, w; };
struct alignas(8) uint2 { unsigned x, y; };
struct alignas(16) uint4 { unsigned x, y, z, w; };
WL_DEV float2 make_float2(float x, float y) { return {x, y}; }
WL_DEV uint2 make_uint2(unsigned x, unsigned y) { return {x, y}; }
WL_DEV float4 make_float4(float x, float y, float z, float w) { return {x, y, z, w}; }

// ---- warp votes and shuffles (vote.sync.*, shfl.sync.*) ----
WL_DEV unsigned __ballot_sync(unsigned mask, int p) { return __nvvm_vote_ballot_sync(mask, p); }
WL_DEV int __all_sync(unsigned mask, int p) { return __nvvm_vote_all_sync(mask, p); }
WL_DEV int __any_sync(unsigned mask, int p) { return __nvvm_vote_any_sync(mask, p); }
WL_DEV int __uni_sync(unsigned mask, int p) { return __nvvm_vote_uni_sync(mask, p); }
WL_DEV unsigned __activemask() { unsigned m; asm volatile("activemask.b32 %0;" : "=r"(m)); return m; }
// c operand: clamp value in bits 0-4, segment mask in bits 8-12 (as CUDA computes it).
WL_DEV int __shfl_sync(unsigned mask, int v, int lane, int width = 32) {
  return __nvvm_shfl_sync_idx_i32(mask, v, lane, ((32 - width) << 8) | 0x1f);
}
WL_DEV int __shfl_up_sync(unsigned mask, int v, unsigned d, int width = 32) {
  return __nvvm_shfl_sync_up_i32(mask, v, d, (32 - width) << 8);
}
WL_DEV int __shfl_down_sync(unsigned mask, int v, unsigned d, int width = 32) {
  return __nvvm_shfl_sync_down_i32(mask, v, d, ((32 - width) << 8) | 0x1f);
}
WL_DEV int __shfl_xor_sync(unsigned mask, int v, int m, int width = 32) {
  return __nvvm_shfl_sync_bfly_i32(mask, v, m, ((32 - width) << 8) | 0x1f);
}
WL_DEV float __shfl_sync(unsigned mask, float v, int lane, int width = 32) {
  return __nvvm_shfl_sync_idx_f32(mask, v, lane, ((32 - width) << 8) | 0x1f);
}
WL_DEV float __shfl_down_sync(unsigned mask, float v, unsigned d, int width = 32) {
  return __nvvm_shfl_sync_down_f32(mask, v, d, ((32 - width) << 8) | 0x1f);
}
WL_DEV float __shfl_xor_sync(unsigned mask, float v, int m, int width = 32) {
  return __nvvm_shfl_sync_bfly_f32(mask, v, m, ((32 - width) << 8) | 0x1f);
}

// ---- atomics (atom.*) ----
WL_DEV int atomicAdd(int *a, int v) { return __nvvm_atom_add_gen_i(a, v); }
WL_DEV unsigned atomicAdd(unsigned *a, unsigned v) { return (unsigned)__nvvm_atom_add_gen_i((int *)a, (int)v); }
WL_DEV float atomicAdd(float *a, float v) { return __nvvm_atom_add_gen_f(a, v); }
WL_DEV int atomicMin(int *a, int v) { return __nvvm_atom_min_gen_i(a, v); }
WL_DEV unsigned atomicMin(unsigned *a, unsigned v) { return __nvvm_atom_min_gen_ui(a, v); }
WL_DEV int atomicMax(int *a, int v) { return __nvvm_atom_max_gen_i(a, v); }
WL_DEV unsigned atomicMax(unsigned *a, unsigned v) { return __nvvm_atom_max_gen_ui(a, v); }
WL_DEV unsigned atomicInc(unsigned *a, unsigned v) { return __nvvm_atom_inc_gen_ui(a, v); }
WL_DEV unsigned atomicDec(unsigned *a, unsigned v) { return __nvvm_atom_dec_gen_ui(a, v); }
WL_DEV int atomicExch(int *a, int v) { return __nvvm_atom_xchg_gen_i(a, v); }
WL_DEV int atomicCAS(int *a, int c, int v) { return __nvvm_atom_cas_gen_i(a, c, v); }
WL_DEV int atomicAnd(int *a, int v) { return __nvvm_atom_and_gen_i(a, v); }
WL_DEV int atomicOr(int *a, int v) { return __nvvm_atom_or_gen_i(a, v); }
WL_DEV int atomicXor(int *a, int v) { return __nvvm_atom_xor_gen_i(a, v); }

// ---- memory ----
WL_DEV float __ldg(const float *p) { return __nvvm_ldg_f(p); }
WL_DEV int __ldg(const int *p) { return __nvvm_ldg_i(p); }
WL_DEV unsigned __ldg(const unsigned *p) { return __nvvm_ldg_ui(p); }
WL_DEV void __threadfence() { __nvvm_membar_gl(); }
WL_DEV void __threadfence_block() { __nvvm_membar_cta(); }

// ---- integer intrinsics ----
WL_DEV int __popc(unsigned x) { return __builtin_popcount(x); }
WL_DEV int __clz(int x) { return x == 0 ? 32 : __builtin_clz((unsigned)x); }
WL_DEV unsigned __brev(unsigned x) { return __builtin_bitreverse32(x); }
WL_DEV unsigned __umulhi(unsigned a, unsigned b) { return __nvvm_mulhi_ui(a, b); }
WL_DEV int __mulhi(int a, int b) { return __nvvm_mulhi_i(a, b); }
WL_DEV int __mul24(int a, int b) { return __nvvm_mul24_i(a, b); }
WL_DEV unsigned __byte_perm(unsigned a, unsigned b, unsigned s) { return __nvvm_prmt(a, b, s); }

// ---- float intrinsics ----
WL_DEV float sqrtf(float x) { return __nvvm_sqrt_rn_f(x); }
WL_DEV float rsqrtf(float x) { return __nvvm_rsqrt_approx_f(x); }
WL_DEV float fminf(float a, float b) { return __nvvm_fmin_f(a, b); }
WL_DEV float fmaxf(float a, float b) { return __nvvm_fmax_f(a, b); }
WL_DEV float fabsf(float a) { return __nvvm_fabs_f(a); }
WL_DEV float __fmaf_rn(float a, float b, float c) { return __nvvm_fma_rn_f(a, b, c); }
WL_DEV float __fmul_rz(float a, float b) { return __nvvm_mul_rz_f(a, b); }
WL_DEV float __fadd_rd(float a, float b) { return __nvvm_add_rm_f(a, b); }
WL_DEV float __fadd_ru(float a, float b) { return __nvvm_add_rp_f(a, b); }
WL_DEV float __frcp_rn(float a) { return __nvvm_rcp_rn_f(a); }
WL_DEV float __sinf(float x) { return __nvvm_sin_approx_f(x); }
WL_DEV float __cosf(float x) { return __nvvm_cos_approx_f(x); }
WL_DEV float exp2f(float x) { return __nvvm_ex2_approx_f(x); }
WL_DEV float __log2f(float x) { return __nvvm_lg2_approx_f(x); }
WL_DEV float __saturatef(float x) { return __nvvm_saturate_f(x); }
WL_DEV int __float2int_rn(float x) { return __nvvm_f2i_rn(x); }
WL_DEV int __float2int_rz(float x) { return __nvvm_f2i_rz(x); }
WL_DEV int __float2int_rd(float x) { return __nvvm_f2i_rm(x); }
WL_DEV int __float2int_ru(float x) { return __nvvm_f2i_rp(x); }
WL_DEV unsigned __float2uint_rz(float x) { return __nvvm_f2ui_rz(x); }
WL_DEV float __int2float_rz(int x) { return __nvvm_i2f_rz(x); }
WL_DEV float __uint2float_ru(unsigned x) { return __nvvm_ui2f_rp(x); }
WL_DEV float __double2float_rd(double x) { return __nvvm_d2f_rm(x); }
WL_DEV float __int_as_float(int x) { return __builtin_bit_cast(float, x); }
WL_DEV int __float_as_int(float x) { return __builtin_bit_cast(int, x); }
WL_DEV unsigned __float_as_uint(float x) { return __builtin_bit_cast(unsigned, x); }
WL_DEV float __uint_as_float(unsigned x) { return __builtin_bit_cast(float, x); }
WL_DEV double __fma_rn(double a, double b, double c) { return __nvvm_fma_rn_d(a, b, c); }
WL_DEV double sqrt(double x) { return __nvvm_sqrt_rn_d(x); }

// ---- warp and CTA reductions, matches (sm_80+: redux.sync) ----
WL_DEV unsigned __reduce_add_sync(unsigned m, unsigned v) { return (unsigned)__nvvm_redux_sync_add((int)v, m); }
WL_DEV unsigned __reduce_min_sync(unsigned m, unsigned v) { return __nvvm_redux_sync_umin(v, m); }
WL_DEV int __reduce_min_sync(unsigned m, int v) { return __nvvm_redux_sync_min(v, m); }
WL_DEV unsigned __reduce_max_sync(unsigned m, unsigned v) { return __nvvm_redux_sync_umax(v, m); }
WL_DEV int __reduce_max_sync(unsigned m, int v) { return __nvvm_redux_sync_max(v, m); }
WL_DEV unsigned __reduce_and_sync(unsigned m, unsigned v) { return (unsigned)__nvvm_redux_sync_and((int)v, m); }
WL_DEV unsigned __reduce_or_sync(unsigned m, unsigned v) { return (unsigned)__nvvm_redux_sync_or((int)v, m); }
WL_DEV unsigned __reduce_xor_sync(unsigned m, unsigned v) { return (unsigned)__nvvm_redux_sync_xor((int)v, m); }
WL_DEV unsigned __match_any_sync(unsigned m, unsigned v) { return __nvvm_match_any_sync_i32(m, v); }
WL_DEV unsigned __match_all_sync(unsigned m, unsigned v, int *pred) { return __nvvm_match_all_sync_i32p(m, v, pred); }
WL_DEV int __syncthreads_count(int p) { return __nvvm_bar0_popc(p); }
WL_DEV int __syncthreads_and(int p) { return __nvvm_bar0_and(p); }
WL_DEV int __syncthreads_or(int p) { return __nvvm_bar0_or(p); }
WL_DEV void __syncwarp(unsigned mask = 0xffffffffu) { __nvvm_bar_warp_sync(mask); }
WL_DEV int __popcll(unsigned long long x) { return __builtin_popcountll(x); }
WL_DEV int __clzll(long long x) { return x == 0 ? 64 : __builtin_clzll((unsigned long long)x); }
WL_DEV unsigned long long __brevll(unsigned long long x) { return __builtin_bitreverse64(x); }


// ---- texture and surface objects (tex.*, tld4, suld.b, sust.b) ----
// The SDK's cudaTextureObject_t / cudaSurfaceObject_t and the fetch
// functions, as inline PTX in the forms nvcc writes for them.
typedef unsigned long long cudaTextureObject_t;
typedef unsigned long long cudaSurfaceObject_t;
enum cudaSurfaceBoundaryMode { cudaBoundaryModeZero = 0, cudaBoundaryModeClamp = 1, cudaBoundaryModeTrap = 2 };
struct alignas(4) uchar4 { unsigned char x, y, z, w; };
WL_DEV float4 __wl_tex1d(cudaTextureObject_t t, float x) {
  float4 r;
  asm("tex.1d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(x));
  return r;
}
WL_DEV float4 __wl_tex1dfetch(cudaTextureObject_t t, int x) {
  float4 r;
  asm("tex.1d.v4.f32.s32 {%0, %1, %2, %3}, [%4, {%5}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "r"(x));
  return r;
}
WL_DEV float4 __wl_tex2d(cudaTextureObject_t t, float x, float y) {
  float4 r;
  asm("tex.2d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5, %6}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(x), "f"(y));
  return r;
}
WL_DEV uint4 __wl_tex2d_u(cudaTextureObject_t t, float x, float y) {
  uint4 r;
  asm("tex.2d.v4.u32.f32 {%0, %1, %2, %3}, [%4, {%5, %6}];"
      : "=r"(r.x), "=r"(r.y), "=r"(r.z), "=r"(r.w) : "l"(t), "f"(x), "f"(y));
  return r;
}
WL_DEV float4 __wl_tex3d(cudaTextureObject_t t, float x, float y, float z) {
  float4 r;
  asm("tex.3d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5, %6, %7, %7}];"
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(x), "f"(y), "f"(z));
  return r;
}
template <class T> __device__ __forceinline__ T tex1D(cudaTextureObject_t t, float x);
template <> __device__ __forceinline__ float tex1D<float>(cudaTextureObject_t t, float x) { return __wl_tex1d(t, x).x; }
template <> __device__ __forceinline__ float4 tex1D<float4>(cudaTextureObject_t t, float x) { return __wl_tex1d(t, x); }
template <class T> __device__ __forceinline__ T tex1Dfetch(cudaTextureObject_t t, int x);
template <> __device__ __forceinline__ float tex1Dfetch<float>(cudaTextureObject_t t, int x) { return __wl_tex1dfetch(t, x).x; }
template <class T> __device__ __forceinline__ T tex2D(cudaTextureObject_t t, float x, float y);
template <> __device__ __forceinline__ float tex2D<float>(cudaTextureObject_t t, float x, float y) { return __wl_tex2d(t, x, y).x; }
template <> __device__ __forceinline__ float4 tex2D<float4>(cudaTextureObject_t t, float x, float y) { return __wl_tex2d(t, x, y); }
template <> __device__ __forceinline__ uchar4 tex2D<uchar4>(cudaTextureObject_t t, float x, float y) {
  uint4 v = __wl_tex2d_u(t, x, y);
  return {(unsigned char)v.x, (unsigned char)v.y, (unsigned char)v.z, (unsigned char)v.w};
}
template <class T> __device__ __forceinline__ T tex3D(cudaTextureObject_t t, float x, float y, float z);
template <> __device__ __forceinline__ float tex3D<float>(cudaTextureObject_t t, float x, float y, float z) { return __wl_tex3d(t, x, y, z).x; }
// tex2Dgather: the component `comp` of the four texels bilinear filtering would use (tld4)
#define WL_TLD4(c)                                                                 \
  asm("tld4." #c ".2d.v4.f32.f32 {%0, %1, %2, %3}, [%4, {%5, %6}];"                \
      : "=f"(r.x), "=f"(r.y), "=f"(r.z), "=f"(r.w) : "l"(t), "f"(x), "f"(y))
template <class T> __device__ __forceinline__ T tex2Dgather(cudaTextureObject_t t, float x, float y, int comp = 0);
template <> __device__ __forceinline__ float4 tex2Dgather<float4>(cudaTextureObject_t t, float x, float y, int comp) {
  float4 r;
  switch (comp) {
  case 1: WL_TLD4(g); break;
  case 2: WL_TLD4(b); break;
  case 3: WL_TLD4(a); break;
  default: WL_TLD4(r); break;
  }
  return r;
}
#undef WL_TLD4
// surf2Dread / surf2Dwrite of 32-bit elements; x is in bytes, as in CUDA
#define WL_SULD(mode)                                                              \
  asm volatile("suld.b.2d.b32." #mode " {%0}, [%1, {%2, %3}];" : "=r"(v) : "l"(s), "r"(x), "r"(y))
#define WL_SUST(mode)                                                              \
  asm volatile("sust.b.2d.b32." #mode " [%0, {%1, %2}], {%3};" ::"l"(s), "r"(x), "r"(y), "r"(v) : "memory")
WL_DEV int __wl_suld2d(cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m) {
  int v;
  switch (m) {
  case cudaBoundaryModeZero: WL_SULD(zero); break;
  case cudaBoundaryModeClamp: WL_SULD(clamp); break;
  default: WL_SULD(trap); break;
  }
  return v;
}
WL_DEV void __wl_sust2d(cudaSurfaceObject_t s, int x, int y, int v, cudaSurfaceBoundaryMode m) {
  switch (m) {
  case cudaBoundaryModeZero: WL_SUST(zero); break;
  case cudaBoundaryModeClamp: WL_SUST(clamp); break;
  default: WL_SUST(trap); break;
  }
}
#undef WL_SULD
#undef WL_SUST
template <class T> __device__ __forceinline__ T surf2Dread(cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m = cudaBoundaryModeTrap);
template <> __device__ __forceinline__ int surf2Dread<int>(cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m) { return __wl_suld2d(s, x, y, m); }
template <> __device__ __forceinline__ float surf2Dread<float>(cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m) {
  return __int_as_float(__wl_suld2d(s, x, y, m));
}
WL_DEV void surf2Dread(int *out, cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m = cudaBoundaryModeTrap) { *out = __wl_suld2d(s, x, y, m); }
WL_DEV void surf2Dwrite(int v, cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m = cudaBoundaryModeTrap) { __wl_sust2d(s, x, y, v, m); }
WL_DEV void surf2Dwrite(float v, cudaSurfaceObject_t s, int x, int y, cudaSurfaceBoundaryMode m = cudaBoundaryModeTrap) { __wl_sust2d(s, x, y, __float_as_int(v), m); }

#endif // !__NVCC__

// ---- warplight helpers, for both compilers ----
// Global thread index of a 1-D launch.
#define WL_TID (blockIdx.x * blockDim.x + threadIdx.x)

#if !defined(__NVCC__)
// printf: clang lowers a call to `vprintf(format, args)` with the arguments
// in a local buffer, as nvcc does; warplight prints per lane (docs/prelude.md).
extern "C" __device__ int printf(const char *, ...);
#endif

// CUDA's math library (kernels/cuda_math.h), when `warplight compile` found libdevice.
#if defined(WL_CUDA_MATH) && !defined(__NVCC__)
#include "cuda_math.h"
#endif
