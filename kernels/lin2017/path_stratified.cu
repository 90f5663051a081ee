// Thesis 003's path tracer with stratified pixel sampling: path.cu compiled
// with PATH_STRATIFIED, so frame f's camera rays fall uniformly in stratum
// f mod D^2 of a D x D grid over their subpixel (a box filter) instead of
// the thesis' tent-jittered ones. It is the other side of 003:L223-225:
// stratification "reduces the error ... to O(1/n)", and the tent filter gives
// "same image quality given same sampling number as stratified sampling";
// `warplight chart lin-pixel-sampling` draws the two. The same entry points
// as path.cu (mlt's camera sample is its chain's, never a stratum); the host
// tells the builds apart by the empty kernel below.
#define PATH_STRATIFIED 1
#include "path.cu"

extern "C" __global__ void path_stratified_build() {}
