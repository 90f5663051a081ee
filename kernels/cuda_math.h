// CUDA's math library for clang-16 without the CUDA SDK: the functions of
// CUDA's math API (expf, sinf, powf, floorf, min, max, abs, ... and the
// __expf-style intrinsics) as clang's own CUDA headers define them, calling
// libdevice's __nv_* functions, which the compiler links in
// (-mlink-builtin-bitcode libdevice.10.bc; `warplight compile` does this).
//
// kernels/prelude.h includes this file at its end when WL_CUDA_MATH is
// defined; kernels/build.sh never defines it, so the project's own kernels
// compile as before. docs/prelude.md lists what each header offers.
#pragma once

#if !defined(__NVCC__)

#ifndef CUDA_VERSION
#define CUDA_VERSION 12000 // clang's headers want CUDA 9 or later
#endif
#include <limits.h>
#include <stddef.h>
#ifndef HUGE_VAL
#define HUGE_VAL __builtin_huge_val()
#endif
#ifndef HUGE_VALF
#define HUGE_VALF __builtin_huge_valf()
#endif

// The prelude defines these already (same PTX instructions); clang's
// definitions of them are renamed so that the two headers do not collide.
#define __brev __wl_clang___brev
#define __brevll __wl_clang___brevll
#define __byte_perm __wl_clang___byte_perm
#define __clz __wl_clang___clz
#define __cosf __wl_clang___cosf
#define __double2float_rd __wl_clang___double2float_rd
#define __fadd_rd __wl_clang___fadd_rd
#define __fadd_ru __wl_clang___fadd_ru
#define __float2int_rd __wl_clang___float2int_rd
#define __float2int_rn __wl_clang___float2int_rn
#define __float2int_ru __wl_clang___float2int_ru
#define __float2int_rz __wl_clang___float2int_rz
#define __float2uint_rz __wl_clang___float2uint_rz
#define __float_as_int __wl_clang___float_as_int
#define __float_as_uint __wl_clang___float_as_uint
#define __fma_rn __wl_clang___fma_rn
#define __fmaf_rn __wl_clang___fmaf_rn
#define __fmul_rz __wl_clang___fmul_rz
#define __frcp_rn __wl_clang___frcp_rn
#define __int2float_rz __wl_clang___int2float_rz
#define __int_as_float __wl_clang___int_as_float
#define __log2f __wl_clang___log2f
#define __mul24 __wl_clang___mul24
#define __mulhi __wl_clang___mulhi
#define __saturatef __wl_clang___saturatef
#define __sinf __wl_clang___sinf
#define __clzll __wl_clang___clzll
#define __syncthreads_and __wl_clang___syncthreads_and
#define __syncthreads_count __wl_clang___syncthreads_count
#define __syncthreads_or __wl_clang___syncthreads_or
#define __threadfence __wl_clang___threadfence
#define __threadfence_block __wl_clang___threadfence_block
#define __uint2float_ru __wl_clang___uint2float_ru
#define __uint_as_float __wl_clang___uint_as_float
#define __umulhi __wl_clang___umulhi
#define exp2f __wl_clang_exp2f
#define fabsf __wl_clang_fabsf
#define fmaxf __wl_clang_fmaxf
#define fminf __wl_clang_fminf
#define rsqrtf __wl_clang_rsqrtf
#define sqrt __wl_clang_sqrt
#define sqrtf __wl_clang_sqrtf

#include <__clang_cuda_libdevice_declares.h>
#include <__clang_cuda_device_functions.h>
#include <__clang_cuda_math.h>

#undef __brev
#undef __brevll
#undef __byte_perm
#undef __clz
#undef __cosf
#undef __double2float_rd
#undef __fadd_rd
#undef __fadd_ru
#undef __float2int_rd
#undef __float2int_rn
#undef __float2int_ru
#undef __float2int_rz
#undef __float2uint_rz
#undef __float_as_int
#undef __float_as_uint
#undef __fma_rn
#undef __fmaf_rn
#undef __fmul_rz
#undef __frcp_rn
#undef __int2float_rz
#undef __int_as_float
#undef __log2f
#undef __mul24
#undef __mulhi
#undef __saturatef
#undef __sinf
#undef __clzll
#undef __syncthreads_and
#undef __syncthreads_count
#undef __syncthreads_or
#undef __threadfence
#undef __threadfence_block
#undef __uint2float_ru
#undef __uint_as_float
#undef __umulhi
#undef exp2f
#undef fabsf
#undef fmaxf
#undef fminf
#undef rsqrtf
#undef sqrt
#undef sqrtf

// min, max and abs for the other types, as the CUDA SDK offers them
// (clang's header has the int versions only).
static __device__ __forceinline__ unsigned min(unsigned a, unsigned b) { return __nv_umin(a, b); }
static __device__ __forceinline__ unsigned max(unsigned a, unsigned b) { return __nv_umax(a, b); }
static __device__ __forceinline__ unsigned min(int a, unsigned b) { return __nv_umin(a, b); }
static __device__ __forceinline__ unsigned min(unsigned a, int b) { return __nv_umin(a, b); }
static __device__ __forceinline__ unsigned max(int a, unsigned b) { return __nv_umax(a, b); }
static __device__ __forceinline__ unsigned max(unsigned a, int b) { return __nv_umax(a, b); }
static __device__ __forceinline__ long long min(long long a, long long b) { return __nv_llmin(a, b); }
static __device__ __forceinline__ long long max(long long a, long long b) { return __nv_llmax(a, b); }
static __device__ __forceinline__ unsigned long long min(unsigned long long a, unsigned long long b) {
  return __nv_ullmin(a, b);
}
static __device__ __forceinline__ unsigned long long max(unsigned long long a, unsigned long long b) {
  return __nv_ullmax(a, b);
}
static __device__ __forceinline__ float min(float a, float b) { return fminf(a, b); }
static __device__ __forceinline__ float max(float a, float b) { return fmaxf(a, b); }
static __device__ __forceinline__ double min(double a, double b) { return fmin(a, b); }
static __device__ __forceinline__ double max(double a, double b) { return fmax(a, b); }
static __device__ __forceinline__ float abs(float a) { return fabsf(a); }
static __device__ __forceinline__ double abs(double a) { return fabs(a); }
static __device__ __forceinline__ long long abs(long long a) { return llabs(a); }

#endif // !__NVCC__
