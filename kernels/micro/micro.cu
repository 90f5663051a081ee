// Memory microbenchmarks measured with Nsight Compute on an H100
// (tools/gpu/micro_fixture.cu, tests/fixtures/h100_micro.json) and checked
// against warplight's hopper profile (tests/validation.rs). Every kernel has
// the same parameters: out, in, and two integers a and b.
#include "../prelude.h"


#define K extern "C" __global__ void

// out[t] = in[t * a + b]: strided, offset loads.
K ld_stride(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  out[t] = in[t * a + b];
}
// out[t * a] = t: strided stores.
K st_stride(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  out[t * a] = (float)t;
}
// 64- and 128-bit loads with a stride in elements.
K ld_v2(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  float2 v = ((const float2 *)in)[t * a];
  out[t] = v.x + v.y;
}
K ld_v4(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  float4 v = ((const float4 *)in)[t * a];
  out[t] = v.x + v.y + v.z + v.w;
}
// Only threads with t % a == 0 load: partially active warps.
K ld_divergent(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  if (t % a == 0) out[t] = in[t];
}
// Gathered loads: in[(t * a) % 65536], through the normal and the read-only path.
K ld_gather(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  out[t] = in[(t * a) & 65535];
}
K ldg_gather(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  out[t] = __ldg(&in[(t * a) & 65535]);
}
// Shared store then load at (threadIdx.x * a) % 1056, 4, 8 and 16 bytes wide.
K sh_stride(float *out, const float *in, int a, int b) {
  __shared__ float s[1056];
  int t = threadIdx.x, i = (t * a) % 1056;
  s[i] = (float)t;
  __syncthreads();
  out[WL_TID] = s[i];
}
K sh_v2(float *out, const float *in, int a, int b) {
  __shared__ float2 s[1056];
  int t = threadIdx.x, i = (t * a) % 1056;
  s[i] = make_float2((float)t, 1.0f);
  __syncthreads();
  float2 v = s[i];
  out[WL_TID] = v.x + v.y;
}
K sh_v4(float *out, const float *in, int a, int b) {
  __shared__ float4 s[1056];
  int t = threadIdx.x, i = (t * a) % 1056;
  s[i] = make_float4((float)t, 1.0f, 2.0f, 3.0f);
  __syncthreads();
  float4 v = s[i];
  out[WL_TID] = v.x + v.y + v.z + v.w;
}
// Atomics: every thread on one address, or spread over a addresses 32 bytes apart.
K atom_one(float *out, const float *in, int a, int b) { atomicAdd((int *)out, 1); }
K atom_spread(float *out, const float *in, int a, int b) {
  atomicAdd((int *)&out[(WL_TID % a) * 8], 1);
}
// Atomics whose result is used (atom, not red).
K atom_ret(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  int old = atomicAdd((int *)&out[(t % a) * 8], 1);
  out[4096 + t] = (float)old;
}
// A local array written in a loop and read at a thread-dependent index.
K local_array(float *out, const float *in, int a, int b) {
  float buf[32];
  int t = WL_TID;
  for (int k = 0; k < 32; k++) buf[k] = in[k] * (float)t;
  out[t] = buf[(t * a) & 31];
}
// A local array too large for registers: every thread stores 256 words at
// the same offsets (coalesced), then loads one at a thread-dependent offset
// (a = 0: the same offset in every thread; a = 1: all different).
K local_big(float *out, const float *in, int a, int b) {
  float buf[256];
  int t = WL_TID;
  for (int k = 0; k < 256; k++) buf[k] = in[k & 7] + (float)(t ^ k);
  out[t] = buf[(t * a) & 255];
}
// Votes: a ballot and a vote per warp, then one store.
K votes(float *out, const float *in, int a, int b) {
  int t = WL_TID;
  unsigned bal = __ballot_sync(0xffffffffu, (t % a) == 0);
  int any = __any_sync(0xffffffffu, t == a);
  out[t] = (float)(__popc(bal) + any);
}
