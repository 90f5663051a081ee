// Linear texture filtering and surface reductions on the GPU (issue 20):
// runs kernels/validation/tex_filter.cu on the textures and coordinates
// below and kernels/validation/sured.cu on 4 x 4 surfaces, and writes into
// OUT_DIR
//   tex.json             the cases: texture, coordinates' count, files
//   NAME.tex, NAME.crd, NAME.out   texel bytes, f32 coordinates (dims per
//                        sample), f32 x 4 results per sample
//   sured.json           every sured case's surface after the launch
// With a second argument "2", the second set of cases instead (16-bit and
// signed normalized texels, 3-D textures under every address mode and
// format) and no surfaces (tools/device/issue20_tex_bfs.sh); with "3" the
// third (signed 8-bit texels, tools/device/issue20_s8_stepped.sh).
// Texels and coordinates come from hash32 (tools/device/validation.py), so
// tests/tex_filter.rs makes the same ones. Build: nvcc -O2 -arch=sm_90 -I. -o
// probe tools/device/tex_filter_host.cu (from the repository root).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../../kernels/validation/sured.cu"
#include "../../kernels/validation/tex_filter.cu"

#define CK(x)                                                                    \
  do {                                                                           \
    cudaError_t e_ = (x);                                                        \
    if (e_ != cudaSuccess) {                                                     \
      fprintf(stderr, "%s:%d %s: %s\n", __FILE__, __LINE__, #x, cudaGetErrorString(e_)); \
      exit(1);                                                                   \
    }                                                                            \
  } while (0)

static unsigned hash32(unsigned x) {
  x ^= x >> 16;
  x *= 0x7FEB352Du;
  x ^= x >> 15;
  x *= 0x846CA68Bu;
  x ^= x >> 16;
  return x;
}

static const char *OUT;

struct Case {
  const char *name;
  int dims;            // 1, 2, 3
  const char *format;  // f32 f16 u8 u16 s8 s16
  int w, h, d;
  const char *addr;    // clamp border wrap mirror
  bool normalized;
  const char *texels;  // "random" (hash of the seed), or a fixed pattern
  int seed;
  int n;
  const char *coords;  // "uniform" lo..hi, or "grid" lo + k / 4096
  double lo, hi;
};

// Element e of a texture (channels innermost): its bits.
static unsigned texel_bits(const Case &c, int e) {
  int ch = e % 4, k = e / 4;
  if (!strcmp(c.texels, "random")) {
    unsigned h = hash32((unsigned)e + ((unsigned)c.seed << 20));
    if (!strcmp(c.format, "f32")) return (h & 0x807FFFFFu) | ((120u + hash32(h) % 15u) << 23);
    if (!strcmp(c.format, "f16")) return (h & 0x83FFu) | ((8u + hash32(h) % 15u) << 10);
    if (!strcmp(c.format, "u16") || !strcmp(c.format, "s16")) return h & 0xFFFFu;
    return h & 0xFFu;
  }
  float v = 0;
  int x = k % c.w, y = c.h ? k / c.w % c.h : 0;
  if (!strcmp(c.texels, "pair")) {  // texels (0, 1, 1, -3) and (1, 0, 2, 5)
    const float p[2][4] = {{0, 1, 1, -3}, {1, 0, 2, 5}};
    v = p[x][ch];
  } else if (!strcmp(c.texels, "index")) {  // (i, 4096 - i, 1, 0)
    const float p[4] = {(float)x, (float)(4096 - x), 1, 0};
    v = p[ch];
  } else if (!strcmp(c.texels, "corners")) {  // (x, y, x == y == 0, 2x + 3y)
    const float p[4] = {(float)x, (float)y, (float)(x == 0 && y == 0), (float)(2 * x + 3 * y)};
    v = p[ch];
  }
  unsigned b;
  memcpy(&b, &v, 4);
  return b;
}

// Coordinate d of sample i.
static float coord(const Case &c, int i, int d) {
  unsigned h = hash32((unsigned)(4 * i + d) + ((unsigned)(c.seed + 100) << 20));
  if (!strcmp(c.coords, "grid1")) return (float)(c.lo + i / 4096.0);
  if (!strcmp(c.coords, "grid")) return (float)(c.lo + (h % (unsigned)((c.hi - c.lo) * 4096)) / 4096.0);
  return (float)(c.lo + (c.hi - c.lo) * (double)h * 2.3283064365386963e-10);
}

static cudaTextureAddressMode addr_mode(const char *a) {
  if (!strcmp(a, "wrap")) return cudaAddressModeWrap;
  if (!strcmp(a, "mirror")) return cudaAddressModeMirror;
  if (!strcmp(a, "border")) return cudaAddressModeBorder;
  return cudaAddressModeClamp;
}

static void write_file(const std::string &name, const void *p, size_t n) {
  FILE *f = fopen((std::string(OUT) + "/" + name).c_str(), "wb");
  fwrite(p, 1, n, f);
  fclose(f);
}

static int elem_size(const char *f) {
  if (!strcmp(f, "f32")) return 4;
  if (!strcmp(f, "f16") || !strcmp(f, "u16") || !strcmp(f, "s16")) return 2;
  return 1;
}

static void run_case(const Case &c, FILE *J, bool first) {
  int esize = elem_size(c.format);
  bool is_float = c.format[0] == 'f';
  int count = c.w * (c.h ? c.h : 1) * (c.d ? c.d : 1) * 4;
  std::vector<unsigned char> raw(count * esize);
  for (int e = 0; e < count; e++) {
    unsigned b = texel_bits(c, e);
    memcpy(&raw[e * esize], &b, esize);
  }
  cudaChannelFormatKind kind = is_float           ? cudaChannelFormatKindFloat
                               : c.format[0] == 's' ? cudaChannelFormatKindSigned
                                                    : cudaChannelFormatKindUnsigned;
  int bits = esize * 8;
  cudaChannelFormatDesc cd = cudaCreateChannelDesc(bits, bits, bits, bits, kind);
  cudaArray_t a;
  CK(cudaMalloc3DArray(&a, &cd, make_cudaExtent(c.w, c.h, c.d), 0));
  cudaMemcpy3DParms cp;
  memset(&cp, 0, sizeof cp);
  cp.srcPtr = make_cudaPitchedPtr(raw.data(), (size_t)c.w * 4 * esize, c.w, c.h ? c.h : 1);
  cp.dstArray = a;
  cp.extent = make_cudaExtent(c.w, c.h ? c.h : 1, c.d ? c.d : 1);
  cp.kind = cudaMemcpyHostToDevice;
  CK(cudaMemcpy3D(&cp));
  cudaResourceDesc rd;
  memset(&rd, 0, sizeof rd);
  rd.resType = cudaResourceTypeArray;
  rd.res.array.array = a;
  cudaTextureDesc td;
  memset(&td, 0, sizeof td);
  for (int i = 0; i < 3; i++) td.addressMode[i] = addr_mode(c.addr);
  td.filterMode = cudaFilterModeLinear;
  td.readMode = is_float ? cudaReadModeElementType : cudaReadModeNormalizedFloat;
  td.normalizedCoords = c.normalized;
  cudaTextureObject_t t;
  CK(cudaCreateTextureObject(&t, &rd, &td, nullptr));
  std::vector<float> crd((size_t)c.n * c.dims);
  for (int i = 0; i < c.n; i++)
    for (int d = 0; d < c.dims; d++) crd[(size_t)i * c.dims + d] = coord(c, i, d);
  float *dc;
  float4 *dout;
  CK(cudaMalloc(&dc, crd.size() * 4));
  CK(cudaMalloc(&dout, (size_t)c.n * 16));
  CK(cudaMemcpy(dc, crd.data(), crd.size() * 4, cudaMemcpyHostToDevice));
  int blocks = (c.n + 127) / 128;
  if (c.dims == 1) tf_1d<<<blocks, 128>>>(t, dc, dout, c.n);
  if (c.dims == 2) tf_2d<<<blocks, 128>>>(t, dc, dout, c.n);
  if (c.dims == 3) tf_3d<<<blocks, 128>>>(t, dc, dout, c.n);
  CK(cudaGetLastError());
  CK(cudaDeviceSynchronize());
  std::vector<float> out((size_t)c.n * 4);
  CK(cudaMemcpy(out.data(), dout, out.size() * 4, cudaMemcpyDeviceToHost));
  write_file(std::string(c.name) + ".tex", raw.data(), raw.size());
  write_file(std::string(c.name) + ".crd", crd.data(), crd.size() * 4);
  write_file(std::string(c.name) + ".out", out.data(), out.size() * 4);
  fprintf(J,
          "%s{\"name\":\"%s\",\"dims\":%d,\"format\":\"%s\",\"size\":[%d,%d,%d],\"addr\":\"%s\","
          "\"normalized\":%s,\"texels\":\"%s\",\"seed\":%d,\"n\":%d,\"coords\":\"%s\",\"lo\":%.17g,\"hi\":%.17g}\n",
          first ? "" : ",", c.name, c.dims, c.format, c.w, c.h, c.d, c.addr, c.normalized ? "true" : "false", c.texels,
          c.seed, c.n, c.coords, c.lo, c.hi);
  CK(cudaDestroyTextureObject(t));
  CK(cudaFreeArray(a));
  CK(cudaFree(dc));
  CK(cudaFree(dout));
}

static const Case CASES[] = {
    {"w1_clamp", 1, "f32", 2, 0, 0, "clamp", false, "pair", 1, 16385, "grid1", -1, 3},
    {"w1_border", 1, "f32", 2, 0, 0, "border", false, "pair", 1, 16385, "grid1", -1, 3},
    {"wbig", 1, "f32", 4096, 0, 0, "clamp", false, "index", 2, 32768, "uniform", -4, 4100},
    {"w2", 2, "f32", 2, 2, 0, "clamp", false, "corners", 3, 32768, "grid", -1, 3},
    {"r1", 1, "f32", 4096, 0, 0, "clamp", false, "random", 4, 65536, "uniform", -2, 4098},
    {"r1b", 1, "f32", 4096, 0, 0, "border", false, "random", 4, 16384, "uniform", -2, 4098},
    {"r2", 2, "f32", 128, 128, 0, "clamp", false, "random", 5, 65536, "uniform", -2, 130},
    {"r2n", 2, "f32", 128, 128, 0, "wrap", true, "random", 5, 32768, "uniform", -1.5, 2.5},
    {"r2m", 2, "f32", 128, 128, 0, "mirror", true, "random", 5, 16384, "uniform", -1.5, 2.5},
    {"r3", 3, "f32", 16, 16, 16, "clamp", false, "random", 6, 32768, "uniform", -1, 17},
    {"h2", 2, "f16", 64, 64, 0, "clamp", false, "random", 7, 32768, "uniform", -1, 65},
    {"h1", 1, "f16", 256, 0, 0, "clamp", false, "random", 8, 16384, "uniform", -1, 257},
    {"u2", 2, "u8", 64, 64, 0, "clamp", false, "random", 9, 32768, "uniform", -1, 65},
    {"u2b", 2, "u8", 64, 64, 0, "border", false, "random", 9, 16384, "uniform", -1, 65},
    {"u1b", 1, "u8", 256, 0, 0, "border", false, "random", 10, 16384, "uniform", -1, 257},
};

// The second set: normalized 16-bit and signed texels in 1-D and 2-D, and
// 3-D textures of every address mode and of f16 and u8 texels, with one
// more f32 clamp case of many samples.
static const Case CASES2[] = {
    {"n2u16", 2, "u16", 64, 64, 0, "clamp", false, "random", 21, 16384, "uniform", -1, 65},
    {"n2s8", 2, "s8", 64, 64, 0, "clamp", false, "random", 22, 16384, "uniform", -1, 65},
    {"n2s16", 2, "s16", 64, 64, 0, "clamp", false, "random", 23, 16384, "uniform", -1, 65},
    {"n1s8b", 1, "s8", 256, 0, 0, "border", false, "random", 24, 8192, "uniform", -1, 257},
    {"r3big", 3, "f32", 16, 16, 16, "clamp", false, "random", 25, 65536, "uniform", -1, 17},
    {"r3b", 3, "f32", 16, 16, 16, "border", false, "random", 26, 16384, "uniform", -1, 17},
    {"r3w", 3, "f32", 16, 16, 16, "wrap", true, "random", 27, 16384, "uniform", -1.5, 2.5},
    {"r3m", 3, "f32", 16, 16, 16, "mirror", true, "random", 28, 16384, "uniform", -1.5, 2.5},
    {"h3", 3, "f16", 16, 16, 16, "clamp", false, "random", 29, 16384, "uniform", -1, 17},
    {"u3", 3, "u8", 16, 16, 16, "clamp", false, "random", 30, 16384, "uniform", -1, 17},
    {"u3b", 3, "u8", 16, 16, 16, "border", false, "random", 31, 16384, "uniform", -1, 17},
};

// The third set: signed 8-bit texels only, new seeds, every dimension and
// address mode (tools/device/issue20_s8_stepped.sh): a held-out check of the
// s8 rule read off n2s8 and n1s8b (docs/semantics.md).
static const Case CASES3[] = {
    {"s1c", 1, "s8", 256, 0, 0, "clamp", false, "random", 41, 4096, "uniform", -1, 257},
    {"s2w", 2, "s8", 64, 64, 0, "wrap", true, "random", 42, 4096, "uniform", -1.5, 2.5},
    {"s2m", 2, "s8", 64, 64, 0, "mirror", true, "random", 43, 4096, "uniform", -1.5, 2.5},
    {"s2b", 2, "s8", 64, 64, 0, "border", false, "random", 44, 4096, "uniform", -1, 65},
    {"s3c", 3, "s8", 16, 16, 16, "clamp", false, "random", 45, 4096, "uniform", -1, 17},
    {"s3b", 3, "s8", 16, 16, 16, "border", false, "random", 46, 4096, "uniform", -1, 17},
};

// ---- surfaces: 4 x 4 elements, initial words hash32(i + (7 << 20))
struct Sured {
  const char *name;
  void (*k)(cudaSurfaceObject_t);
  int esize;
  int threads;
};
#define S32(n) {#n, n, 4, 64}
#define S64(n) {#n, n, 8, 64}
static const Sured SURED[] = {
    S32(sr_add_u32), S32(sr_add_s32), S32(sr_min_u32), S32(sr_min_s32), S32(sr_max_u32), S32(sr_max_s32),
    S32(sr_and_b32), S32(sr_or_b32), S32(sr_add_u32_clamp), S32(sr_add_u32_zero), S32(sr_max_s32_clamp),
    S64(sr_add_u64), S64(sr_add_u64_clamp), S64(sr_add_u64_zero),
};

static void sured(FILE *J) {
  fprintf(J, "{\"surface\":\"4 x 4 elements, initial 32-bit words hash32(i + (7 << 20))\",\"cases\":[\n");
  bool first = true;
  for (const Sured &s : SURED) {
    int words = 16 * s.esize / 4;
    std::vector<unsigned> init(words), out(words);
    for (int i = 0; i < words; i++) init[i] = hash32((unsigned)i + (7u << 20));
    cudaChannelFormatDesc cd = s.esize == 4 ? cudaCreateChannelDesc(32, 0, 0, 0, cudaChannelFormatKindUnsigned)
                                            : cudaCreateChannelDesc(32, 32, 0, 0, cudaChannelFormatKindUnsigned);
    cudaArray_t a;
    CK(cudaMallocArray(&a, &cd, 4, 4, cudaArraySurfaceLoadStore));
    CK(cudaMemcpy2DToArray(a, 0, 0, init.data(), 4 * s.esize, 4 * s.esize, 4, cudaMemcpyHostToDevice));
    cudaResourceDesc rd;
    memset(&rd, 0, sizeof rd);
    rd.resType = cudaResourceTypeArray;
    rd.res.array.array = a;
    cudaSurfaceObject_t so;
    CK(cudaCreateSurfaceObject(&so, &rd));
    s.k<<<1, s.threads>>>(so);
    cudaError_t e = cudaDeviceSynchronize();
    if (e != cudaSuccess) {
      fprintf(stderr, "%s: %s\n", s.name, cudaGetErrorString(e));
      exit(1);
    }
    CK(cudaMemcpy2DFromArray(out.data(), 4 * s.esize, a, 0, 0, 4 * s.esize, 4, cudaMemcpyDeviceToHost));
    fprintf(J, "%s{\"kernel\":\"%s\",\"elem_bytes\":%d,\"threads\":%d,\"init\":[", first ? "" : ",\n", s.name, s.esize,
            s.threads);
    for (int i = 0; i < words; i++) fprintf(J, "%s%u", i ? "," : "", init[i]);
    fprintf(J, "],\"out\":[");
    for (int i = 0; i < words; i++) fprintf(J, "%s%u", i ? "," : "", out[i]);
    fprintf(J, "]}");
    first = false;
    CK(cudaDestroySurfaceObject(so));
    CK(cudaFreeArray(a));
  }
  fprintf(J, "\n]}\n");
}

int main(int argc, char **argv) {
  OUT = argc > 1 ? argv[1] : ".";
  bool second = argc > 2 && !strcmp(argv[2], "2");
  bool third = argc > 2 && !strcmp(argv[2], "3");
  FILE *J = fopen((std::string(OUT) + "/tex.json").c_str(), "w");
  fprintf(J, "[\n");
  bool first = true;
  if (third) {
    for (const Case &c : CASES3) {
      run_case(c, J, first);
      first = false;
    }
  } else if (second) {
    for (const Case &c : CASES2) {
      run_case(c, J, first);
      first = false;
    }
  } else {
    for (const Case &c : CASES) {
      run_case(c, J, first);
      first = false;
    }
  }
  fprintf(J, "]\n");
  fclose(J);
  if (second || third) {
    printf("done\n");
    return 0;
  }
  J = fopen((std::string(OUT) + "/sured.json").c_str(), "w");
  sured(J);
  fclose(J);
  printf("done\n");
  return 0;
}
