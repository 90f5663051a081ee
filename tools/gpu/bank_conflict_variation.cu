// Run-to-run variation of Nsight Compute's shared-memory metrics: each kernel
// is launched REPEATS times on the same data and profiled launch by launch by
// tools/gpu/measure_bank_conflict_variation.sh. A metric whose value differs
// between identical launches depends on timing (requests of different warps
// meeting in the shared-memory pipeline), not only on the addresses.
#include <cstdio>
#include <cuda_runtime.h>

#define TILE 32
#define REPEATS 5

// transpose through a 32x32 tile: the column reads conflict 32 ways inside each warp
__global__ void transpose_conflicting(const float *in, float *out, int n) {
    __shared__ float t[TILE][TILE];
    int x = blockIdx.x * TILE + threadIdx.x, y = blockIdx.y * TILE + threadIdx.y;
    t[threadIdx.y][threadIdx.x] = in[y * n + x];
    __syncthreads();
    x = blockIdx.y * TILE + threadIdx.x;
    y = blockIdx.x * TILE + threadIdx.y;
    out[y * n + x] = t[threadIdx.x][threadIdx.y];
}

// the same with a padded tile: no two lanes of a warp share a bank
__global__ void transpose_padded(const float *in, float *out, int n) {
    __shared__ float t[TILE][TILE + 1];
    int x = blockIdx.x * TILE + threadIdx.x, y = blockIdx.y * TILE + threadIdx.y;
    t[threadIdx.y][threadIdx.x] = in[y * n + x];
    __syncthreads();
    x = blockIdx.y * TILE + threadIdx.x;
    y = blockIdx.x * TILE + threadIdx.y;
    out[y * n + x] = t[threadIdx.x][threadIdx.y];
}

// a shared-memory reduction tree (stride-1 accesses, shrinking active warps)
__global__ void reduce_shared(const float *in, float *out) {
    __shared__ float s[1024];
    unsigned t = threadIdx.x;
    s[t] = in[blockIdx.x * blockDim.x + t];
    __syncthreads();
    for (unsigned k = blockDim.x / 2; k > 0; k >>= 1) {
        if (t < k) s[t] += s[t + k];
        __syncthreads();
    }
    if (t == 0) out[blockIdx.x] = s[0];
}

// a shared histogram: atomics on 64 bins, addresses from the data
__global__ void histogram_shared(const unsigned *in, unsigned *bins, int n) {
    __shared__ unsigned h[64];
    if (threadIdx.x < 64) h[threadIdx.x] = 0;
    __syncthreads();
    for (int i = blockIdx.x * blockDim.x + threadIdx.x; i < n; i += gridDim.x * blockDim.x)
        atomicAdd(&h[in[i] & 63], 1u);
    __syncthreads();
    if (threadIdx.x < 64) atomicAdd(&bins[threadIdx.x], h[threadIdx.x]);
}

int main() {
    const int n = 2048;
    float *a, *b;
    unsigned *u, *bins;
    cudaMalloc(&a, n * n * sizeof(float));
    cudaMalloc(&b, n * n * sizeof(float));
    cudaMalloc(&u, n * n * sizeof(unsigned));
    cudaMalloc(&bins, 64 * sizeof(unsigned));
    cudaMemset(a, 0, n * n * sizeof(float));
    unsigned *h = new unsigned[n * n];
    for (int i = 0; i < n * n; i++) h[i] = (i * 2654435761u) >> 7;
    cudaMemcpy(u, h, n * n * sizeof(unsigned), cudaMemcpyHostToDevice);
    dim3 grid(n / TILE, n / TILE), block(TILE, TILE);
    for (int r = 0; r < REPEATS; r++) transpose_conflicting<<<grid, block>>>(a, b, n);
    for (int r = 0; r < REPEATS; r++) transpose_padded<<<grid, block>>>(a, b, n);
    for (int r = 0; r < REPEATS; r++) reduce_shared<<<n * n / 1024, 1024>>>(a, b);
    for (int r = 0; r < REPEATS; r++) histogram_shared<<<264, 256>>>(u, bins, n * n);
    cudaError_t e = cudaDeviceSynchronize();
    printf("%s\n", cudaGetErrorString(e));
    return e != cudaSuccess;
}
