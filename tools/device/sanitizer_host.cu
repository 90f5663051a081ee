// Host harness for the planted kernels (kernels/tests/planted_*.cu): launches
// one of them, by name, with the buffers and launch shape that
// tests/fixtures/sanitizer/planted_*.toml give warplight, and prints the
// results. Built and run under compute-sanitizer by tools/device/sanitizer.sh.
#include <cstring>
#include <vector>

#include "host_harness.h"

#include "../../kernels/tests/planted_race_raw.cu"
#include "../../kernels/tests/planted_race_waw.cu"
#include "../../kernels/tests/planted_race_global.cu"
#include "../../kernels/tests/planted_uninit_global.cu"
#include "../../kernels/tests/planted_uninit_shared.cu"
#include "../../kernels/tests/planted_oob.cu"
#include "../../kernels/tests/planted_barrier_divergent.cu"
#include "../../kernels/tests/planted_barrier_mismatch.cu"
#include "../../kernels/tests/planted_warp_race.cu"

// `n` ints on the device, copied from `init` (left unwritten without it).
static int *device_ints(size_t n, const std::vector<int> *init) {
  int *p = nullptr;
  CK(cudaMalloc(&p, n * sizeof(int)));
  if (init) CK(cudaMemcpy(p, init->data(), n * sizeof(int), cudaMemcpyHostToDevice));
  return p;
}

// Launches a planted kernel and waits for it: what it does wrong is
// compute-sanitizer's to report (the status is printed at the end), so its
// errors do not stop the harness. Then prints `n` ints of `out` as `name`
// ("done" for none).
template <class Launch> static void run(Launch launch, const char *name, const int *out, size_t n) {
  launch();
  cudaDeviceSynchronize();
  if (!n) {
    printf("done\n");
    return;
  }
  std::vector<int> h(n);
  cudaMemcpy(h.data(), out, n * sizeof(int), cudaMemcpyDeviceToHost);
  printf("%s:", name);
  for (size_t i = 0; i < n; i++) printf(" %d", h[i]);
  printf("\n");
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s KERNEL\n", argv[0]);
    return 2;
  }
  const char *k = argv[1];
  std::vector<int> zeros(4096, 0);
  if (!strcmp(k, "planted_race_raw")) {
    std::vector<int> in(512);
    for (int i = 0; i < 512; i++) in[i] = i % 7;
    int *sums = device_ints(2, &zeros), *din = device_ints(512, &in);
    run([&] { block_sum_nosync<<<2, 256>>>(sums, din); }, "sums", sums, 2);
  } else if (!strcmp(k, "planted_race_waw")) {
    int *out = device_ints(2, &zeros);
    run([&] { last_writer<<<2, 128>>>(out); }, "out", out, 2);
  } else if (!strcmp(k, "planted_race_global")) {
    int *out = device_ints(1, &zeros);
    run([&] { global_total<<<4, 32>>>(out); }, "out", out, 1);
  } else if (!strcmp(k, "planted_uninit_global")) {
    int *out = device_ints(32, &zeros), *in = device_ints(32, nullptr);  // `in` never written
    run([&] { add_one<<<1, 32>>>(out, in); }, "", out, 0);
  } else if (!strcmp(k, "planted_uninit_shared")) {
    int *out = device_ints(64, &zeros);
    run([&] { mirror<<<1, 64>>>(out); }, "", out, 0);
  } else if (!strcmp(k, "planted_oob")) {
    std::vector<int> data(4096);
    for (int i = 0; i < 4096; i++) data[i] = i;
    int *out = device_ints(4096, &zeros), *d = device_ints(4096, &data);
    run([&] { shift_left<<<16, 256>>>(out, d); }, "out[4094..]", out + 4094, 2);
  } else if (!strcmp(k, "planted_barrier_divergent")) {
    int *out = device_ints(32, &zeros);
    run([&] { half_barrier<<<1, 32>>>(out); }, "out", out, 32);
  } else if (!strcmp(k, "planted_barrier_mismatch")) {
    int *out = device_ints(64, &zeros);
    run([&] { two_barriers<<<1, 64>>>(out); }, "out", out, 64);
  } else if (!strcmp(k, "planted_warp_race_synced")) {
    int *out = device_ints(128, &zeros);
    run([&] { warp_swap_synced<<<2, 64>>>(out); }, "out", out, 128);
  } else if (!strcmp(k, "planted_warp_race_nosync")) {
    int *out = device_ints(128, &zeros);
    run([&] { warp_swap_nosync<<<2, 64>>>(out); }, "out", out, 128);
  } else {
    fprintf(stderr, "unknown kernel %s\n", k);
    return 2;
  }
  cudaError_t e = cudaGetLastError();
  printf("status: %s\n", cudaGetErrorString(e));
  return e == cudaSuccess ? 0 : 1;
}
