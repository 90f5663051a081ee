// A first kernel with CUDA's math library and printf (README, docs/prelude.md):
//   warplight run examples/softmax.cu --grid 1 --block 8 --buffer x=f32:8:iota --args x,8
__global__ void softmax(float *x, int n) {
  int i = threadIdx.x;
  float e = expf(x[i]);
  float sum = 0;
  for (int j = 0; j < n; j++) sum += expf(x[j]);
  printf("thread %d: exp(%d) = %.4f, softmax = %f\n", i, i, e, e / sum);
  x[i] = e / sum;
}
