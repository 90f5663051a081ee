// Surface reductions `sured.b` (issue 20): each thread applies its value at
// a position of a 2-D surface of 4 x 4 elements (x in bytes), in range
// (`.trap`) or partly out of range (`.clamp`, `.zero`). The surfaces, values
// and the H200's results: tools/device/sured_host.cu,
// tests/fixtures/validation/h200_sured.json; compared by tests/tex_filter.rs.
#include "../prelude.h"

#define T (blockIdx.x * blockDim.x + threadIdx.x)

// in range: (t % 4, t / 4 % 4); out of range: (t % 6 - 1, t / 6 % 6 - 1)
__device__ __forceinline__ void coords(int esize, bool out_of_range, int &x, int &y) {
  int t = T;
  if (out_of_range) {
    x = (t % 6 - 1) * esize;
    y = t / 6 % 6 - 1;
  } else {
    x = (t % 4) * esize;
    y = t / 4 % 4;
  }
}

#define SR32(name, instr, oor)                                                            \
  extern "C" __global__ void name(cudaSurfaceObject_t s) {                              \
    int x, y;                                                                           \
    coords(4, oor, x, y);                                                               \
    unsigned v = (unsigned)T * 2654435761u;                                             \
    asm volatile(instr " [%0, {%1, %2}], %3;" ::"l"(s), "r"(x), "r"(y), "r"(v) : "memory"); \
  }
#define SR64(name, instr, oor)                                                            \
  extern "C" __global__ void name(cudaSurfaceObject_t s) {                              \
    int x, y;                                                                           \
    coords(8, oor, x, y);                                                               \
    unsigned long long v = (unsigned long long)T * 0x9E3779B97F4A7C15ull;               \
    asm volatile(instr " [%0, {%1, %2}], %3;" ::"l"(s), "r"(x), "r"(y), "l"(v) : "memory"); \
  }

SR32(sr_add_u32, "sured.b.add.2d.u32.trap", false)
SR32(sr_add_s32, "sured.b.add.2d.s32.trap", false)
SR32(sr_min_u32, "sured.b.min.2d.u32.trap", false)
SR32(sr_min_s32, "sured.b.min.2d.s32.trap", false)
SR32(sr_max_u32, "sured.b.max.2d.u32.trap", false)
SR32(sr_max_s32, "sured.b.max.2d.s32.trap", false)
SR32(sr_and_b32, "sured.b.and.2d.b32.trap", false)
SR32(sr_or_b32, "sured.b.or.2d.b32.trap", false)
SR32(sr_add_u32_clamp, "sured.b.add.2d.u32.clamp", true)
SR32(sr_add_u32_zero, "sured.b.add.2d.u32.zero", true)
SR32(sr_max_s32_clamp, "sured.b.max.2d.s32.clamp", true)
SR64(sr_add_u64, "sured.b.add.2d.u64.trap", false)
SR64(sr_add_u64_clamp, "sured.b.add.2d.u64.clamp", true)
SR64(sr_add_u64_zero, "sured.b.add.2d.u64.zero", true)
