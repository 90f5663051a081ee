// What `txq` returns on the GPU for texture objects: one kernel per query
// (so that a query the GPU rejects fails alone), each run on texture objects
// of several shapes, formats and sampler settings. The output buffer is
// pre-filled with 0xDEADBEEF and every launch's status is printed, so "the
// kernel wrote 0" and "the kernel did not run" differ.
//   txq_probe Q  ->  stdout: "OBJECT QUERY STATUS VALUE" lines for query
//                    number Q (0..10; a process per query, so that an error,
//                    which is sticky, ends one query only)
// Built and run by tools/device/exec_probe.sh (docs/ptx-support.md).
#include <cuda_runtime.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#define QUERY(NAME)                                                    \
  __global__ void q_##NAME(cudaTextureObject_t t, unsigned *out) {     \
    unsigned v;                                                        \
    asm volatile("txq." #NAME ".b32 %0, [%1];" : "=r"(v) : "l"(t));    \
    if (threadIdx.x == 0) out[0] = v;                                  \
  }
QUERY(width)
QUERY(height)
QUERY(depth)
QUERY(channel_data_type)
QUERY(channel_order)
QUERY(normalized_coords)
QUERY(filter_mode)
QUERY(addr_mode_0)
QUERY(addr_mode_1)
QUERY(addr_mode_2)
QUERY(num_mipmap_levels)

typedef void (*Query)(cudaTextureObject_t, unsigned *);
static const struct {
  const char *name;
  Query k;
} QUERIES[] = {{"width", q_width},
               {"height", q_height},
               {"depth", q_depth},
               {"channel_data_type", q_channel_data_type},
               {"channel_order", q_channel_order},
               {"normalized_coords", q_normalized_coords},
               {"filter_mode", q_filter_mode},
               {"addr_mode_0", q_addr_mode_0},
               {"addr_mode_1", q_addr_mode_1},
               {"addr_mode_2", q_addr_mode_2},
               {"num_mipmap_levels", q_num_mipmap_levels}};

struct Obj {
  const char *name;
  cudaTextureObject_t t;
};

static cudaTextureObject_t array_tex(cudaChannelFormatDesc ch, int w, int h, int d, cudaTextureAddressMode am,
                                     cudaTextureFilterMode fm, cudaTextureReadMode rm, int norm) {
  cudaArray_t a = nullptr;
  cudaExtent e = make_cudaExtent(w, h, d);
  if (d) cudaMalloc3DArray(&a, &ch, e);
  else cudaMallocArray(&a, &ch, w, h);
  cudaResourceDesc r;
  memset(&r, 0, sizeof r);
  r.resType = cudaResourceTypeArray;
  r.res.array.array = a;
  cudaTextureDesc td;
  memset(&td, 0, sizeof td);
  td.addressMode[0] = td.addressMode[1] = td.addressMode[2] = am;
  td.filterMode = fm;
  td.readMode = rm;
  td.normalizedCoords = norm;
  cudaTextureObject_t t = 0;
  cudaError_t err = cudaCreateTextureObject(&t, &r, &td, nullptr);
  if (err != cudaSuccess) printf("# create: %s\n", cudaGetErrorString(err));
  return t;
}

int main(int argc, char **argv) {
  int qi = argc > 1 ? atoi(argv[1]) : -1;
  if (qi < 0 || qi >= (int)(sizeof QUERIES / sizeof QUERIES[0])) {
    fprintf(stderr, "usage: %s QUERY (0..%d)\n", argv[0], (int)(sizeof QUERIES / sizeof QUERIES[0]) - 1);
    return 2;
  }
  std::vector<Obj> objs;
  objs.push_back({"f32_1d_w8_clamp_point", array_tex(cudaCreateChannelDesc<float>(), 8, 0, 0, cudaAddressModeClamp,
                                                     cudaFilterModePoint, cudaReadModeElementType, 0)});
  objs.push_back({"f32x4_2d_5x3_clamp_linear", array_tex(cudaCreateChannelDesc<float4>(), 5, 3, 0, cudaAddressModeClamp,
                                                         cudaFilterModeLinear, cudaReadModeElementType, 0)});
  objs.push_back({"f32_3d_3x3x2_border_linear_norm",
                  array_tex(cudaCreateChannelDesc<float>(), 3, 3, 2, cudaAddressModeBorder, cudaFilterModeLinear,
                            cudaReadModeElementType, 1)});
  objs.push_back({"u8x4_2d_4x4_wrap_point_normread_norm",
                  array_tex(cudaCreateChannelDesc<uchar4>(), 4, 4, 0, cudaAddressModeWrap, cudaFilterModePoint,
                            cudaReadModeNormalizedFloat, 1)});
  objs.push_back({"s16x2_2d_7x2_mirror_point_norm",
                  array_tex(cudaCreateChannelDesc<short2>(), 7, 2, 0, cudaAddressModeMirror, cudaFilterModePoint,
                            cudaReadModeElementType, 1)});
  {
    float *lin = nullptr;
    cudaMalloc(&lin, 16 * sizeof(float));
    cudaResourceDesc r;
    memset(&r, 0, sizeof r);
    r.resType = cudaResourceTypeLinear;
    r.res.linear.devPtr = lin;
    r.res.linear.desc = cudaCreateChannelDesc<float>();
    r.res.linear.sizeInBytes = 16 * sizeof(float);
    cudaTextureDesc td;
    memset(&td, 0, sizeof td);
    td.readMode = cudaReadModeElementType;
    cudaTextureObject_t t = 0;
    cudaCreateTextureObject(&t, &r, &td, nullptr);
    objs.push_back({"f32_linear_16", t});
  }
  unsigned *out = nullptr;
  cudaMalloc(&out, 4);
  for (auto &o : objs) {
    {
      auto &q = QUERIES[qi];
      unsigned v = 0xDEADBEEF;
      cudaMemcpy(out, &v, 4, cudaMemcpyHostToDevice);
      q.k<<<1, 32>>>(o.t, out);
      cudaError_t e1 = cudaGetLastError();
      cudaError_t e2 = cudaDeviceSynchronize();
      cudaError_t e = e1 != cudaSuccess ? e1 : e2;
      if (e == cudaSuccess) cudaMemcpy(&v, out, 4, cudaMemcpyDeviceToHost);
      printf("%s %s %s %u\n", o.name, q.name, e == cudaSuccess ? "ok" : cudaGetErrorName(e), v);
      if (e != cudaSuccess) return 1;  // a sticky error: the rest would fail too
    }
  }
  return 0;
}
