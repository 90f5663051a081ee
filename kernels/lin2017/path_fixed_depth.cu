// Thesis 003's path tracer without Russian roulette: path.cu compiled with
// PATH_FIXED_DEPTH, so every path goes on to the longest path's bounces (or
// until it leaves the scene). It is the other side of the thesis' claim that
// roulette "greatly speeds up rendering without increasing the variance"
// (003:L269); `warplight chart lin-convergence --termination` draws the two.
// The same entry points as path.cu; the host tells the two builds apart by
// the empty kernel below.
#define PATH_FIXED_DEPTH 1
#include "path.cu"

extern "C" __global__ void path_fixed_depth_build() {}
