// The instrumented build of raytrace.cu: the same kernels with the TALLY
// statements compiled in, counting rays, inner-node steps, texture node
// fetches, leaf visits, plane and barycentric tests and local-memory stack
// accesses per pixel into the stats buffer. Used only to cross-check the
// counts read off the emulator's per-line counters (tests/raytrace.rs).
#define RAYTRACE_STATS 1
#include "raytrace.cu"
