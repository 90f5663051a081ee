// Indirect calls: function pointers chosen per lane (a divergent call), a
// table of function pointers in a __device__ array, and virtual dispatch.
#include "prelude.h"

typedef float (*binop)(float, float);
__device__ __noinline__ float op_add(float a, float b) { return a + b; }
__device__ __noinline__ float op_mul(float a, float b) { return a * b; }
__device__ __noinline__ float op_sub(float a, float b) { return a - b; }
__device__ __noinline__ float op_max(float a, float b) { return fmaxf(a, b); }
__device__ binop op_table[4] = {op_add, op_mul, op_sub, op_max};

// each lane picks its function from its index: four targets in one warp
extern "C" __global__ void call_table(const float *a, const float *b, float *out, int n) {
  int i = WL_TID;
  if (i < n) out[i] = op_table[(i * 7 + i / 5) & 3](a[i], b[i]);
}

// a pointer chosen by a condition, called twice
extern "C" __global__ void call_select(const float *a, float *out, int n) {
  int i = WL_TID;
  if (i < n) {
    binop f = (a[i] > 0.5f) ? op_mul : op_sub;
    out[i] = f(f(a[i], 3.0f), a[i]);
  }
}

struct Shape {
  __device__ virtual float area(float s) const = 0;
  __device__ virtual int sides() const { return 0; }
};
struct Square : Shape {
  __device__ float area(float s) const override { return s * s; }
  __device__ int sides() const override { return 4; }
};
struct Disc : Shape {
  __device__ float area(float s) const override { return 3.14159265f * s * s; }
};
__device__ __noinline__ float describe(const Shape *p, float s) { return p->area(s) + (float)p->sides(); }

// virtual dispatch through vtables in global memory
extern "C" __global__ void call_virtual(const float *a, float *out, int n) {
  int i = WL_TID;
  if (i < n) {
    Square sq;
    Disc d;
    const Shape *p = (i % 3 == 0) ? (const Shape *)&d : (const Shape *)&sq;
    out[i] = describe(p, a[i]);
  }
}
