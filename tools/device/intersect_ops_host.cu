// Host program for tools/device/intersect_ops.sh: runs kernels/lin2017/
// intersect.cu's tri_standard and tri_affine (compiled by nvcc with this
// file, -arch=sm_90 -O3 -lineinfo) on N = 4096 (ray, triangle) pairs that
// all hit, so that Nsight Compute's per-thread instruction counts divided by
// N are the operations of one test (table lin:s6.4, docs/reproduction-lin2017.md).
//
// Pairs: random non-degenerate triangles (vertices in [-1, 1]^3, area and
// smallest angle bounded below), each ray from a point off the triangle's
// plane (along the normal, plus a tangential offset) through its centroid;
// t_min 1e-4, t_max 1e30. The affine rows are those of
// src/host/path/layout.rs (inverse of [a - c, b - c, n], translation -M^-1 c,
// in double, rounded once). Checks every output is a hit within 1e-4
// (relative) of the distance to the centroid; prints the hits to argv[1]
// (default stdout) and a summary; exits 1 on any miss or CUDA error.
// With a second argument FILE.ptx, runs that PTX's tri_standard and
// tri_affine instead (JIT-compiled by the driver; the committed clang PTX
// kernels/lin2017/intersect.ptx, say), on the same pairs.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>
#include <string>
#include <cuda.h>
#include <cuda_runtime.h>
#include "../../kernels/lin2017/intersect.cu"

#define CD(x) do { CUresult e = (x); if (e != CUDA_SUCCESS) { const char *m; cuGetErrorString(e, &m); fprintf(stderr, "%s: %s\n", #x, m); exit(1); } } while (0)
#define CK(x) do { cudaError_t e = (x); if (e != cudaSuccess) { fprintf(stderr, "%s: %s\n", #x, cudaGetErrorString(e)); exit(1); } } while (0)

static const unsigned N = 4096;

struct V3 { double x, y, z; };
static V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
static V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
static V3 scale(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
static double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
static double len(V3 a) { return std::sqrt(dot(a, a)); }

// xorshift64*, fixed seed: the same pairs on every run
static unsigned long long rng_state = 0x9E3779B97F4A7C15ull;
static double uniform(double lo, double hi) {
  rng_state ^= rng_state >> 12; rng_state ^= rng_state << 25; rng_state ^= rng_state >> 27;
  unsigned long long r = rng_state * 2685821657736338717ull;
  return lo + (hi - lo) * (double)(r >> 11) * (1.0 / 9007199254740992.0);
}
static V3 rnd(double lo, double hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }

// smallest angle (radians) of triangle (a, b, c)
static double min_angle(V3 a, V3 b, V3 c) {
  V3 p[3] = {a, b, c};
  double m = 10.0;
  for (int i = 0; i < 3; i++) {
    V3 u = sub(p[(i + 1) % 3], p[i]), v = sub(p[(i + 2) % 3], p[i]);
    m = std::fmin(m, std::acos(dot(u, v) / (len(u) * len(v))));
  }
  return m;
}

int main(int argc, char **argv) {
  std::vector<float4> rays(2 * N), verts(3 * N), rows(3 * N);
  std::vector<double> want(N);
  for (unsigned i = 0; i < N; i++) {
    V3 a, b, c, n;
    do {
      a = rnd(-1, 1); b = rnd(-1, 1); c = rnd(-1, 1);
      n = cross(sub(b, a), sub(c, a));
    } while (0.5 * len(n) < 0.05 || min_angle(a, b, c) < 0.2);
    // the vertices as the kernels see them (f32); everything below from these
    float4 fa = make_float4((float)a.x, (float)a.y, (float)a.z, 0.0f);
    float4 fb = make_float4((float)b.x, (float)b.y, (float)b.z, 0.0f);
    float4 fc = make_float4((float)c.x, (float)c.y, (float)c.z, 0.0f);
    a = {fa.x, fa.y, fa.z}; b = {fb.x, fb.y, fb.z}; c = {fc.x, fc.y, fc.z};
    n = cross(sub(b, a), sub(c, a));
    V3 nh = scale(n, 1.0 / len(n));
    V3 cen = scale(add(add(a, b), c), 1.0 / 3.0);
    // origin: off the plane by 0.3..2 on either side, shifted along the plane
    double h = uniform(0.3, 2.0) * (uniform(0, 1) < 0.5 ? -1.0 : 1.0);
    V3 tang = scale(sub(a, cen), uniform(-0.5, 0.5));
    V3 o = add(add(cen, scale(nh, h)), tang);
    V3 d = sub(cen, o);
    d = scale(d, 1.0 / len(d));
    float4 fo = make_float4((float)o.x, (float)o.y, (float)o.z, 1e-4f);
    float4 fd = make_float4((float)d.x, (float)d.y, (float)d.z, 1e30f);
    rays[2 * i] = fo; rays[2 * i + 1] = fd;
    verts[3 * i] = fa; verts[3 * i + 1] = fb; verts[3 * i + 2] = fc;
    want[i] = len(sub(cen, {fo.x, fo.y, fo.z}));
    // affine rows: inverse of the columns [a - c, b - c, n'] with n' = (a - c) x (b - c)
    V3 e0 = sub(a, c), e1 = sub(b, c), nn = cross(e0, e1);
    double det = dot(e0, cross(e1, nn));
    V3 r0 = scale(cross(e1, nn), 1.0 / det), r1 = scale(cross(nn, e0), 1.0 / det), r2 = scale(cross(e0, e1), 1.0 / det);
    V3 r[3] = {r0, r1, r2};
    for (int k = 0; k < 3; k++)
      rows[3 * i + k] = make_float4((float)r[k].x, (float)r[k].y, (float)r[k].z, (float)(-dot(r[k], c)));
  }
  float4 *d_rays, *d_verts, *d_rows;
  float *d_out;
  CK(cudaMalloc(&d_rays, rays.size() * sizeof(float4)));
  CK(cudaMalloc(&d_verts, verts.size() * sizeof(float4)));
  CK(cudaMalloc(&d_rows, rows.size() * sizeof(float4)));
  CK(cudaMalloc(&d_out, N * sizeof(float)));
  CK(cudaMemcpy(d_rays, rays.data(), rays.size() * sizeof(float4), cudaMemcpyHostToDevice));
  CK(cudaMemcpy(d_verts, verts.data(), verts.size() * sizeof(float4), cudaMemcpyHostToDevice));
  CK(cudaMemcpy(d_rows, rows.data(), rows.size() * sizeof(float4), cudaMemcpyHostToDevice));
  FILE *hits = argc > 1 ? fopen(argv[1], "w") : stdout;
  if (!hits) { fprintf(stderr, "cannot write %s\n", argv[1]); return 1; }
  fprintf(hits, "# pair t_standard t_affine t_expected\n");
  std::vector<float> ts(N), ta(N);
  const unsigned block = 128, grid = (N + block - 1) / block;
  unsigned n = N;
  if (argc > 2) {
    // the kernels of a PTX file, loaded by the driver's JIT
    FILE *pf = fopen(argv[2], "rb");
    if (!pf) { fprintf(stderr, "cannot read %s\n", argv[2]); return 1; }
    std::string ptx;
    char buf[65536];
    size_t k;
    while ((k = fread(buf, 1, sizeof buf, pf)) > 0) ptx.append(buf, k);
    fclose(pf);
    CK(cudaFree(0));  // the runtime's primary context, current for the driver calls
    CUmodule m;
    char log[8192] = {0};
    CUjit_option opts[] = {CU_JIT_ERROR_LOG_BUFFER, CU_JIT_ERROR_LOG_BUFFER_SIZE_BYTES};
    void *vals[] = {log, (void *)(size_t)sizeof log};
    if (cuModuleLoadDataEx(&m, ptx.c_str(), 2, opts, vals) != CUDA_SUCCESS) {
      fprintf(stderr, "%s: JIT failed: %s\n", argv[2], log);
      return 1;
    }
    CUfunction fs, fa;
    CD(cuModuleGetFunction(&fs, m, "tri_standard"));
    CD(cuModuleGetFunction(&fa, m, "tri_affine"));
    void *ps[] = {&d_rays, &d_verts, &n, &d_out}, *pa[] = {&d_rays, &d_rows, &n, &d_out};
    CD(cuLaunchKernel(fs, grid, 1, 1, block, 1, 1, 0, 0, ps, 0));
    CK(cudaMemcpy(ts.data(), d_out, N * sizeof(float), cudaMemcpyDeviceToHost));
    CD(cuLaunchKernel(fa, grid, 1, 1, block, 1, 1, 0, 0, pa, 0));
    CK(cudaMemcpy(ta.data(), d_out, N * sizeof(float), cudaMemcpyDeviceToHost));
  } else {
    tri_standard<<<grid, block>>>(d_rays, d_verts, n, d_out);
    CK(cudaGetLastError());
    CK(cudaMemcpy(ts.data(), d_out, N * sizeof(float), cudaMemcpyDeviceToHost));
    tri_affine<<<grid, block>>>(d_rays, d_rows, n, d_out);
    CK(cudaGetLastError());
    CK(cudaMemcpy(ta.data(), d_out, N * sizeof(float), cudaMemcpyDeviceToHost));
  }
  unsigned hs = 0, ha = 0;
  double worst = 0.0;
  for (unsigned i = 0; i < N; i++) {
    double es = std::fabs(ts[i] - want[i]) / want[i], ea = std::fabs(ta[i] - want[i]) / want[i];
    if (ts[i] > 0.0f && es < 1e-4) hs++;
    if (ta[i] > 0.0f && ea < 1e-4) ha++;
    worst = std::fmax(worst, std::fmax(es, ea));
    fprintf(hits, "%u %.9g %.9g %.9g\n", i, ts[i], ta[i], want[i]);
  }
  if (hits != stdout) fclose(hits);
  printf("%s: pairs %u: tri_standard hits %u, tri_affine hits %u, max relative error %.3g\n", argc > 2 ? argv[2] : "nvcc", N, hs, ha, worst);
  return (hs == N && ha == N) ? 0 : 1;
}
