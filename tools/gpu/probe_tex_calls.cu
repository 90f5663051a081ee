// Ground truth for texture and surface objects, indirect calls and the
// half-precision special functions, on an NVIDIA GPU (sm_90): runs the kernels
// of kernels/tests/{textures,indirect,half_sfu}.cu on inputs made here and
// writes them with the results.
//   probe OUT_DIR  ->  OUT_DIR/probe.json (textures, surfaces, indirect calls,
//                      setp on packed halves, txq) and OUT_DIR/half_<kernel>.bin
//                      (every 16-bit input's result, little-endian)
// Built and run by tools/gpu/probe_tex_calls.sh; tools/gpu/probe_to_fixture.py
// turns the output into tests/fixtures/gpu_textures.json.
#include <cuda_runtime.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "../../kernels/tests/half_sfu.cu"
#include "../../kernels/tests/indirect.cu"
#include "../../kernels/tests/textures.cu"

#define CK(x)                                                                              \
  do {                                                                                     \
    cudaError_t e = (x);                                                                   \
    if (e != cudaSuccess) {                                                                \
      fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #x, cudaGetErrorString(e));   \
      exit(1);                                                                             \
    }                                                                                      \
  } while (0)

// A kernel launch whose configuration is checked at once (cudaGetLastError);
// what the kernel did is checked where its results are read (back()).
#define LAUNCH(kernel, grid, block, ...)    \
  do {                                     \
    kernel<<<grid, block>>>(__VA_ARGS__);  \
    CK(cudaGetLastError());                \
  } while (0)

static FILE *J;
static bool first_case = true;

static unsigned fbits(float f) {
  unsigned u;
  memcpy(&u, &f, 4);
  return u;
}
static void arr_u32(const char *name, const std::vector<unsigned> &v) {
  fprintf(J, "\"%s\":[", name);
  for (size_t i = 0; i < v.size(); i++) fprintf(J, "%s%u", i ? "," : "", v[i]);
  fprintf(J, "]");
}
// Named arrays of a case, comma-separated: "a":[...],"b":[...]
static void arrays(std::initializer_list<std::pair<const char *, std::vector<unsigned>>> named) {
  bool first = true;
  for (auto &n : named) {
    if (!first) fprintf(J, ",");
    first = false;
    arr_u32(n.first, n.second);
  }
}
static std::vector<unsigned> fb(const std::vector<float> &v) {
  std::vector<unsigned> o;
  for (float f : v) o.push_back(fbits(f));
  return o;
}
template <class T> static T *dev(const std::vector<T> &v) {
  T *p;
  CK(cudaMalloc(&p, v.size() * sizeof(T) + 16));
  CK(cudaMemcpy(p, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice));
  return p;
}
template <class T> static std::vector<T> back(T *p, size_t n) {
  std::vector<T> v(n);
  CK(cudaDeviceSynchronize());
  CK(cudaMemcpy(v.data(), p, n * sizeof(T), cudaMemcpyDeviceToHost));
  return v;
}

// A texture: its description as the fixture records it, and the CUDA object.
struct Tex {
  const char *format;  // f32 | f16 | u8
  int channels, w, h, d;  // h = d = 0 for fewer dimensions
  bool linear_resource;   // cudaResourceTypeLinear (tex1Dfetch) instead of an array
  const char *addr, *filter, *read;
  bool normalized;
  std::vector<unsigned> texels;  // element bits in x, y, z order, channels innermost
  cudaTextureObject_t obj;
};

static cudaTextureAddressMode addr_mode(const char *a) {
  if (!strcmp(a, "wrap")) return cudaAddressModeWrap;
  if (!strcmp(a, "mirror")) return cudaAddressModeMirror;
  if (!strcmp(a, "border")) return cudaAddressModeBorder;
  return cudaAddressModeClamp;
}

static void make(Tex &t) {
  int esize = !strcmp(t.format, "f32") ? 4 : !strcmp(t.format, "f16") ? 2 : 1;
  int bits = esize * 8;
  cudaChannelFormatKind kind =
      !strcmp(t.format, "u8") ? cudaChannelFormatKindUnsigned : cudaChannelFormatKindFloat;
  cudaChannelFormatDesc cd = cudaCreateChannelDesc(bits, t.channels > 1 ? bits : 0, t.channels > 2 ? bits : 0,
                                                   t.channels > 3 ? bits : 0, kind);
  std::vector<unsigned char> raw(t.texels.size() * esize);
  for (size_t i = 0; i < t.texels.size(); i++) memcpy(&raw[i * esize], &t.texels[i], esize);
  cudaResourceDesc rd;
  memset(&rd, 0, sizeof rd);
  if (t.linear_resource) {
    void *p;
    CK(cudaMalloc(&p, raw.size()));
    CK(cudaMemcpy(p, raw.data(), raw.size(), cudaMemcpyHostToDevice));
    rd.resType = cudaResourceTypeLinear;
    rd.res.linear.devPtr = p;
    rd.res.linear.desc = cd;
    rd.res.linear.sizeInBytes = raw.size();
  } else {
    cudaArray_t a;
    cudaExtent ext = make_cudaExtent(t.w, t.h, t.d);
    CK(cudaMalloc3DArray(&a, &cd, ext, 0));
    cudaMemcpy3DParms cp;
    memset(&cp, 0, sizeof cp);
    cp.srcPtr = make_cudaPitchedPtr(raw.data(), (size_t)t.w * t.channels * esize, t.w, t.h ? t.h : 1);
    cp.dstArray = a;
    cp.extent = make_cudaExtent(t.w, t.h ? t.h : 1, t.d ? t.d : 1);
    cp.kind = cudaMemcpyHostToDevice;
    CK(cudaMemcpy3D(&cp));
    rd.resType = cudaResourceTypeArray;
    rd.res.array.array = a;
  }
  cudaTextureDesc td;
  memset(&td, 0, sizeof td);
  for (int i = 0; i < 3; i++) td.addressMode[i] = addr_mode(t.addr);
  td.filterMode = !strcmp(t.filter, "linear") ? cudaFilterModeLinear : cudaFilterModePoint;
  td.readMode = !strcmp(t.read, "normalized") ? cudaReadModeNormalizedFloat : cudaReadModeElementType;
  td.normalizedCoords = t.normalized;
  CK(cudaCreateTextureObject(&t.obj, &rd, &td, nullptr));
}

static void tex_json(const Tex &t) {
  fprintf(J, "\"texture\":{\"format\":\"%s\",\"channels\":%d,\"dims\":[%d,%d,%d],\"resource\":\"%s\",", t.format,
          t.channels, t.w, t.h, t.d, t.linear_resource ? "linear" : "array");
  fprintf(J, "\"addr\":\"%s\",\"filter\":\"%s\",\"read\":\"%s\",\"normalized\":%s,", t.addr, t.filter, t.read,
          t.normalized ? "true" : "false");
  arr_u32("texels", t.texels);
  fprintf(J, "}");
}

static void begin_case(const char *name, const char *kernel) {
  fprintf(J, "%s\n{\"name\":\"%s\",\"kernel\":\"%s\",", first_case ? "" : ",", name, kernel);
  first_case = false;
}

static const int B = 128;
static int grid(int n) { return (n + B - 1) / B; }

// tex1d_f / tex1dfetch_f over coordinates xs
static void case_1d(const char *name, Tex &t, const std::vector<float> &xs) {
  make(t);
  int n = xs.size();
  float *dx = dev(xs), *dout;
  CK(cudaMalloc(&dout, n * 4));
  LAUNCH(tex1d_f, grid(n), B, t.obj, dx, dout, n);
  auto out = back(dout, n);
  begin_case(name, "tex1d_f");
  tex_json(t);
  fprintf(J, ",");
  arrays({{"x", fb(xs)}, {"out", fb(out)}});
  fprintf(J, "}");
}

static void case_2d(const char *name, const char *kernel, Tex &t, const std::vector<float> &xs,
                    const std::vector<float> &ys) {
  make(t);
  int n = xs.size();
  float *dx = dev(xs), *dy = dev(ys);
  std::vector<unsigned> out;
  if (!strcmp(kernel, "tex2d_f4")) {
    float4 *o;
    CK(cudaMalloc(&o, n * 16));
    LAUNCH(tex2d_f4, grid(n), B, t.obj, dx, dy, o, n);
    auto v = back((unsigned *)o, 4 * n);
    out = v;
  } else if (!strcmp(kernel, "tld4_f4")) {
    float4 *o;
    CK(cudaMalloc(&o, n * 64));
    LAUNCH(tld4_f4, grid(n), B, t.obj, dx, dy, o, n);
    out = back((unsigned *)o, 16 * n);
  } else {
    unsigned *o;
    CK(cudaMalloc(&o, n * 4));
    LAUNCH(tex2d_u4, grid(n), B, t.obj, dx, dy, o, n);
    out = back(o, n);
  }
  begin_case(name, kernel);
  tex_json(t);
  fprintf(J, ",");
  arrays({{"x", fb(xs)}, {"y", fb(ys)}, {"out", out}});
  fprintf(J, "}");
}

static void textures() {
  // 1-D: eight f32 texels of assorted magnitudes
  std::vector<unsigned> f8 = fb({0.1f, 1000.0f, -3.7f, 12345.678f, 1.0f, 0.0f, 2.5f, -0.001f});
  std::vector<float> c1, c1n;
  for (int k = 0; k <= 640; k++) c1.push_back(-1.0f + k / 64.0f);
  for (int k = 0; k < 2048; k++) c1.push_back(2.0f + k / 2048.0f);
  for (int k = 0; k <= 1024; k++) c1n.push_back(-1.5f + k / 256.0f);
  for (int k = 0; k < 512; k++) c1n.push_back(0.25f + k / 16384.0f);
  for (float s : {NAN, INFINITY, -INFINITY, 1e30f, -1e30f, 3.0e9f}) {
    c1.push_back(s);
    c1n.push_back(s);
  }
  const char *filters[] = {"point", "linear"};
  const char *modes[] = {"clamp", "border", "wrap", "mirror"};
  for (const char *f : filters) {
    for (int m = 0; m < 2; m++) {
      Tex t{"f32", 1, 8, 0, 0, false, modes[m], f, "element", false, f8, 0};
      std::string name = std::string("f1d_") + f + "_" + modes[m];
      case_1d(name.c_str(), t, c1);
    }
    for (const char *m : modes) {
      Tex t{"f32", 1, 8, 0, 0, false, m, f, "element", true, f8, 0};
      std::string name = std::string("f1d_norm_") + f + "_" + m;
      case_1d(name.c_str(), t, c1n);
    }
  }
  // 1-D half texels, linear
  {
    std::vector<unsigned> h8 = {0x3c00, 0x4500, 0xc266, 0x7bff, 0x0001, 0x3555, 0xbc00, 0x4248};
    Tex t{"f16", 1, 8, 0, 0, false, "clamp", "linear", "element", false, h8, 0};
    case_1d("h1d_linear_clamp", t, c1);
  }
  // 2-D: 5 x 3 float4
  std::vector<unsigned> f2;
  for (int y = 0; y < 3; y++)
    for (int x = 0; x < 5; x++)
      for (int c = 0; c < 4; c++) f2.push_back(fbits((float)(x * 17 + y * 5 + c * 3 - 20) * 0.37f + 0.001f * c));
  std::vector<float> gx, gy, nx, ny;
  for (int j = 0; j < 40; j++)
    for (int i = 0; i < 56; i++) {
      gx.push_back(-1.0f + i / 8.0f);
      gy.push_back(-1.0f + j / 8.0f);
      nx.push_back((-1.0f + i / 8.0f) / 4.0f);
      ny.push_back((-1.0f + j / 8.0f) / 2.0f);
    }
  {
    Tex t{"f32", 4, 5, 3, 0, false, "clamp", "linear", "element", false, f2, 0};
    case_2d("f2d_linear_clamp", "tex2d_f4", t, gx, gy);
    Tex g{"f32", 4, 5, 3, 0, false, "clamp", "point", "element", false, f2, 0};
    case_2d("f2d_tld4_clamp", "tld4_f4", g, gx, gy);
    Tex gb{"f32", 4, 5, 3, 0, false, "border", "linear", "element", false, f2, 0};
    case_2d("f2d_tld4_border", "tld4_f4", gb, gx, gy);
    Tex w{"f32", 4, 5, 3, 0, false, "wrap", "linear", "element", true, f2, 0};
    case_2d("f2d_norm_linear_wrap", "tex2d_f4", w, nx, ny);
    Tex mp{"f32", 4, 5, 3, 0, false, "mirror", "point", "element", true, f2, 0};
    case_2d("f2d_norm_point_mirror", "tex2d_f4", mp, nx, ny);
  }
  // 2-D: 4 x 4 uchar4
  std::vector<unsigned> u8;
  for (int y = 0; y < 4; y++)
    for (int x = 0; x < 4; x++)
      for (int c = 0; c < 4; c++) u8.push_back((x * 61 + y * 23 + c * 97 + 11) & 255);
  {
    Tex t{"u8", 4, 4, 4, 0, false, "border", "linear", "normalized", false, u8, 0};
    case_2d("u8_linear_border_normalized", "tex2d_f4", t, gx, gy);
    Tex e{"u8", 4, 4, 4, 0, false, "clamp", "point", "element", false, u8, 0};
    case_2d("u8_point_clamp_element", "tex2d_u4", e, gx, gy);
  }
  // 3-D: 3 x 3 x 2 f32, linear
  {
    std::vector<unsigned> f3;
    for (int z = 0; z < 2; z++)
      for (int y = 0; y < 3; y++)
        for (int x = 0; x < 3; x++) f3.push_back(fbits(((x * 7 + y * 13 + z * 29) % 17) * 0.73f - 2.0f));
    Tex t{"f32", 1, 3, 3, 2, false, "clamp", "linear", "element", false, f3, 0};
    make(t);
    std::vector<float> xs, ys, zs;
    for (int k = 0; k < 11; k++)
      for (int j = 0; j < 17; j++)
        for (int i = 0; i < 17; i++) {
          xs.push_back(-0.5f + i / 4.0f);
          ys.push_back(-0.5f + j / 4.0f);
          zs.push_back(-0.5f + k / 4.0f);
        }
    int n = xs.size();
    float *dx = dev(xs), *dy = dev(ys), *dz = dev(zs), *o;
    CK(cudaMalloc(&o, n * 4));
    LAUNCH(tex3d_f, grid(n), B, t.obj, dx, dy, dz, o, n);
    auto out = back(o, n);
    begin_case("f3d_linear_clamp", "tex3d_f");
    tex_json(t);
    fprintf(J, ",");
    arrays({{"x", fb(xs)}, {"y", fb(ys)}, {"z", fb(zs)}, {"out", fb(out)}});
    fprintf(J, "}");
    // txq of the 3-D, the 2-D float4 and the uchar4 textures
    int *q;
    CK(cudaMalloc(&q, 64));
    Tex t2{"f32", 4, 5, 3, 0, false, "clamp", "linear", "element", false, f2, 0};
    Tex t8{"u8", 4, 4, 4, 0, false, "border", "linear", "normalized", true, u8, 0};
    make(t2);
    make(t8);
    fprintf(J, ",\n{\"name\":\"txq\",\"kernel\":\"tex_query\",\"results\":{");
    const char *names[] = {"f3d_linear_clamp", "f2d_linear_clamp", "u8_linear_border_normalized_norm"};
    cudaTextureObject_t objs[] = {t.obj, t2.obj, t8.obj};
    for (int k = 0; k < 3; k++) {
      LAUNCH(tex_query, 1, 32, objs[k], q);
      auto r = back((unsigned *)q, 6);
      fprintf(J, "%s\"%s\":", k ? "," : "", names[k]);
      fprintf(J, "[%u,%u,%u,%u,%u,%u]", r[0], r[1], r[2], r[3], r[4], r[5]);
    }
    fprintf(J, "}}");
  }
  // linear memory, tex1Dfetch with indices out of range too
  {
    std::vector<unsigned> l16;
    for (int i = 0; i < 16; i++) l16.push_back(fbits(i * 1.5f - 4.0f));
    Tex t{"f32", 1, 16, 0, 0, true, "clamp", "point", "element", false, l16, 0};
    make(t);
    std::vector<int> is;
    for (int i = -4; i < 21; i++) is.push_back(i);
    is.push_back(1 << 30);
    is.push_back(-(1 << 30));
    int n = is.size();
    int *di = dev(is);
    float *o;
    CK(cudaMalloc(&o, n * 4));
    LAUNCH(tex1dfetch_f, 1, 32, t.obj, di, o, n);
    auto out = back(o, n);
    begin_case("linear_fetch", "tex1dfetch_f");
    tex_json(t);
    fprintf(J, ",");
    std::vector<unsigned> iu(is.begin(), is.end());
    arrays({{"x", iu}, {"out", fb(out)}});
    fprintf(J, "}");
  }
}

static void surfaces() {
  const int W = 8, H = 4;
  std::vector<int> init;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) init.push_back(x * 100 + y + 7);
  cudaChannelFormatDesc cd = cudaCreateChannelDesc(32, 0, 0, 0, cudaChannelFormatKindSigned);
  auto make_surf = [&](cudaArray_t &a) {
    CK(cudaMallocArray(&a, &cd, W, H, cudaArraySurfaceLoadStore));
    CK(cudaMemcpy2DToArray(a, 0, 0, init.data(), W * 4, W * 4, H, cudaMemcpyHostToDevice));
    cudaResourceDesc rd;
    memset(&rd, 0, sizeof rd);
    rd.resType = cudaResourceTypeArray;
    rd.res.array.array = a;
    cudaSurfaceObject_t s;
    CK(cudaCreateSurfaceObject(&s, &rd));
    return s;
  };
  std::vector<int> xs, ys;
  for (int y : {-1, 0, 3, 4, 9})
    for (int x : {-8, -4, 0, 4, 28, 32, 36, 64}) {
      xs.push_back(x);
      ys.push_back(y);
    }
  int n = xs.size();
  int *dx = dev(xs), *dy = dev(ys);
  cudaArray_t a;
  cudaSurfaceObject_t s = make_surf(a);
  int *z, *c;
  CK(cudaMalloc(&z, n * 4));
  CK(cudaMalloc(&c, n * 4));
  LAUNCH(surf_read, 1, 64, s, dx, dy, z, c, n);
  auto oz = back((unsigned *)z, n), oc = back((unsigned *)c, n);
  std::vector<unsigned> iu(init.begin(), init.end()), xu(xs.begin(), xs.end()), yu(ys.begin(), ys.end());
  begin_case("surf_read", "surf_read");
  fprintf(J, "\"surface\":{\"format\":\"s32\",\"dims\":[%d,%d,0],", W, H);
  arr_u32("texels", iu);
  fprintf(J, "},");
  arrays({{"x", xu}, {"y", yu}, {"zero", oz}, {"clamp", oc}});
  fprintf(J, "}");
  // writes: each lane writes 1000 + lane at its coordinates, in zero and clamp mode
  for (int clamp = 0; clamp < 2; clamp++) {
    cudaArray_t a2;
    cudaSurfaceObject_t s2 = make_surf(a2);
    std::vector<int> v;
    for (int i = 0; i < n; i++) v.push_back(1000 + i);
    int *dv = dev(v);
    LAUNCH(surf_write, 1, 64, s2, dx, dy, dv, clamp, n);
    CK(cudaDeviceSynchronize());
    std::vector<unsigned> after(W * H);
    CK(cudaMemcpy2DFromArray(after.data(), W * 4, a2, 0, 0, W * 4, H, cudaMemcpyDeviceToHost));
    begin_case(clamp ? "surf_write_clamp" : "surf_write_zero", "surf_write");
    fprintf(J, "\"surface\":{\"format\":\"s32\",\"dims\":[%d,%d,0],", W, H);
    arr_u32("texels", iu);
    fprintf(J, "},\"clamp\":%d,", clamp);
    std::vector<unsigned> vu(v.begin(), v.end());
    arrays({{"x", xu}, {"y", yu}, {"v", vu}, {"after", after}});
    fprintf(J, "}");
  }
}

static void indirect() {
  const int n = 256;
  std::vector<float> a, b, s;
  for (int i = 0; i < n; i++) {
    a.push_back(i * 0.25f - 3.0f);
    b.push_back(1.5f - i * 0.125f);
    s.push_back((i % 16) / 16.0f);
  }
  float *da = dev(a), *db = dev(b), *ds = dev(s), *o;
  CK(cudaMalloc(&o, n * 4));
  LAUNCH(call_table, 2, 128, da, db, o, n);
  auto t = back(o, n);
  begin_case("call_table", "call_table");
  arrays({{"a", fb(a)}, {"b", fb(b)}, {"out", fb(t)}});
  fprintf(J, "}");
  LAUNCH(call_select, 2, 128, ds, o, n);
  auto sel = back(o, n);
  begin_case("call_select", "call_select");
  arrays({{"a", fb(s)}, {"out", fb(sel)}});
  fprintf(J, "}");
  LAUNCH(call_virtual, 2, 128, da, o, n);
  auto vir = back(o, n);
  begin_case("call_virtual", "call_virtual");
  arrays({{"a", fb(a)}, {"out", fb(vir)}});
  fprintf(J, "}");
}

// Every input's result, little-endian, in DIR/half_NAME.bin.
template <class T> static void write_bin(const char *dir, const char *name, const std::vector<T> &v) {
  std::string p = std::string(dir) + "/half_" + name + ".bin";
  FILE *f = fopen(p.c_str(), "wb");
  if (!f || fwrite(v.data(), sizeof(T), v.size(), f) != v.size()) {
    fprintf(stderr, "cannot write %s\n", p.c_str());
    exit(1);
  }
  fclose(f);
}

static void halves(const char *dir) {
  const int n = 65536;
  unsigned short *o16;
  unsigned *o32;
  CK(cudaMalloc(&o16, n * 2));
  CK(cudaMalloc(&o32, n * 4));
  struct K16 {
    const char *name;
    void (*k)(unsigned short *, int);
  } k16[] = {{"ex2_f16", ex2_f16}, {"tanh_f16", tanh_f16}, {"ex2_bf16", ex2_bf16}, {"tanh_bf16", tanh_bf16}};
  for (auto &k : k16) {
    LAUNCH(k.k, n / 256, 256, o16, n);
    write_bin(dir, k.name, back(o16, n));
  }
  struct K32 {
    const char *name;
    void (*k)(unsigned *, int);
  } k32[] = {{"ex2_f16x2", ex2_f16x2}, {"tanh_f16x2", tanh_f16x2}, {"ex2_bf16x2", ex2_bf16x2},
             {"tanh_bf16x2", tanh_bf16x2}};
  for (auto &k : k32) {
    LAUNCH(k.k, n / 256, 256, o32, n);
    write_bin(dir, k.name, back(o32, n));
  }
  // setp on packed halves: every pair of 11 values in the low halves, the reverse in the high
  unsigned hv[] = {0x0000, 0x8000, 0x3c00, 0xbc00, 0x7c00, 0xfc00, 0x7e00, 0x7c01, 0x0001, 0x3c01, 0x4000};
  unsigned bv[] = {0x0000, 0x8000, 0x3f80, 0xbf80, 0x7f80, 0xff80, 0x7fc0, 0x7f81, 0x0001, 0x3f81, 0x4000};
  for (int bf = 0; bf < 2; bf++) {
    unsigned *v = bf ? bv : hv;
    std::vector<unsigned> as, bs;
    for (int i = 0; i < 121; i++) {
      as.push_back(v[i % 11] | v[i / 11] << 16);
      bs.push_back(v[i / 11] | v[i % 11] << 16);
    }
    unsigned *da = dev(as), *db = dev(bs), *o;
    CK(cudaMalloc(&o, 121 * 4));
    if (bf)
      LAUNCH(setp_bf16x2, 1, 128, da, db, o, 121);
    else
      LAUNCH(setp_f16x2, 1, 128, da, db, o, 121);
    auto out = back(o, 121);
    begin_case(bf ? "setp_bf16x2" : "setp_f16x2", bf ? "setp_bf16x2" : "setp_f16x2");
    arrays({{"a", as}, {"b", bs}, {"out", out}});
    fprintf(J, "}");
  }
}

int main(int argc, char **argv) {
  const char *dir = argc > 1 ? argv[1] : ".";
  std::string p = std::string(dir) + "/probe.json";
  J = fopen(p.c_str(), "w");
  cudaDeviceProp prop;
  CK(cudaGetDeviceProperties(&prop, 0));
  int drv = 0, rt = 0;
  cudaDriverGetVersion(&drv);
  cudaRuntimeGetVersion(&rt);
  fprintf(J, "{\"device\":\"%s\",\"cc\":\"%d.%d\",\"driver_api\":%d,\"runtime\":%d,\"cases\":[", prop.name, prop.major,
          prop.minor, drv, rt);
  textures();
  surfaces();
  indirect();
  halves(dir);
  fprintf(J, "]}\n");
  fclose(J);
  CK(cudaDeviceSynchronize());
  fprintf(stderr, "probe: done\n");
  return 0;
}
