// Thesis 003 (Lin 2017), §3.5-3.6: the SAH BVH and its automatic refitting
// (003:L191-205).
//
// The BVH is binned-SAH built on the CPU (003:L195; src/host/path/bvh.rs);
// triangles go to a child by their centroid (003:L199) and the children are
// stored front-back: the left child, the lower centroids on the split axis,
// right after its parent. A node is two float4 (32 bytes):
//   [lo.x lo.y lo.z word]  word = axis << 30 | right child      (inner)
//                                 3 << 30 | first reference       (leaf)
//   [hi.x hi.y hi.z count] count = the leaf's triangles (0 for an inner node)
//
// bvh_trace: one thread per ray, the closest hit. The search cannot stop at
// the first leaf hit (the back child may hold a nearer one, 003:L197-199):
// visit the front child first (by the ray's sign on the node's axis), push
// the back one, trim the ray's range to the hit, and test each popped node's
// box against the trimmed range; it ends when the stack is empty. A stack
// entry is the node index alone (4 bytes, local memory).
//
// Movable objects (003:L203): each triangle belongs to an object whose
// translation vector is applied as an offset in the triangle test (the ray
// origin moves by -translation); vertices are never rewritten.
//
// bvh_refit: one thread per leaf recomputes its box from its triangles'
// vertices plus their objects' translations, then climbs: at each parent it
// counts its arrival with an atomic add; the first of the two children to
// arrive stops, the second computes the parent's box as the union of both
// children's and climbs on. Every inner node is thus written once, after
// both children, and receives exactly two atomic arrivals. This is the
// full (growing and shrinking) refit of the whole tree; the unions are
// min / max, exact in any order, so the result does not depend on which
// thread arrives second.
#include "../prelude.h"

#if defined(__clang__) && !defined(__NVCC__)
#pragma clang fp contract(off)
#endif

#define BVH_LEAF 3u
#define BVH_STACK 64

struct BvhParams {
  int num_rays, num_leaves;
};

// The ray's entry and exit of box [lo, hi] (the path tracer's scene clip).
static __device__ __forceinline__ void slab(float4 lo, float4 hi, float ox, float oy, float oz, float ix, float iy,
                                            float iz, float *tn, float *tf) {
  float t0x = (lo.x - ox) * ix, t1x = (hi.x - ox) * ix;
  float t0y = (lo.y - oy) * iy, t1y = (hi.y - oy) * iy;
  float t0z = (lo.z - oz) * iz, t1z = (hi.z - oz) * iz;
  *tn = fmaxf(fmaxf(fminf(t0x, t1x), fminf(t0y, t1y)), fminf(t0z, t1z));
  *tf = fminf(fminf(fmaxf(t0x, t1x), fmaxf(t0y, t1y)), fmaxf(t0z, t1z));
}

// §6.4's affine test of triangle t with its object's translation off (the
// ray origin moved by -off); updates *t_hit on a hit in [t_min, *t_hit].
static __device__ __forceinline__ bool affine(const float4 *tris, unsigned t, float4 off, float ox, float oy,
                                              float oz, float dx, float dy, float dz, float t_min, float *t_hit) {
  const float4 *m = tris + 3 * t;
  float px = ox - off.x, py = oy - off.y, pz = oz - off.z;
  float4 r2 = m[2];
  float qz = r2.x * px + r2.y * py + r2.z * pz + r2.w;
  float ez = r2.x * dx + r2.y * dy + r2.z * dz;
  float tt = -qz / ez;                                   // @count tri_tests div.rn.f32
  if (!(tt >= t_min && tt <= *t_hit)) return false;
  float4 r0 = m[0];
  float u = r0.x * px + r0.y * py + r0.z * pz + r0.w + tt * (r0.x * dx + r0.y * dy + r0.z * dz);
  if (u < 0.0f) return false;
  float4 r1 = m[1];
  float v = r1.x * px + r1.y * py + r1.z * pz + r1.w + tt * (r1.x * dx + r1.y * dy + r1.z * dz);
  if (v < 0.0f || u + v > 1.0f) return false;
  *t_hit = tt;
  return true;
}

// rays: per ray [o, t_min], [d, t_max]; hits: per ray [t, triangle (int bits, -1 none), nodes, 0].
extern "C" __global__ void bvh_trace(const BvhParams *params, const float4 *nodes, const unsigned *refs,
                                     const float4 *tris, const unsigned *tri_obj, const float4 *offsets,
                                     const float4 *rays, float4 *hits) {
  int i = (int)WL_TID;
  if (i >= params->num_rays) return;
  float4 ro = rays[2 * i], rd = rays[2 * i + 1];
  float ix = 1.0f / rd.x;                                // @count rays rcp.rn.f32
  float iy = 1.0f / rd.y, iz = 1.0f / rd.z;
  float t_min = ro.w, t_hit = rd.w;
  int found = -1;
  unsigned stack[BVH_STACK];
  int size = 0;
  unsigned idx = 0;
  for (;;) {
    uint4 a = ((const uint4 *)nodes)[2 * idx];           // @count nodes ld.global.v4.u32
    uint4 b = ((const uint4 *)nodes)[2 * idx + 1];
    unsigned word = a.w, kind = word >> 30;
    float tn, tf;
    slab(make_float4(__uint_as_float(a.x), __uint_as_float(a.y), __uint_as_float(a.z), 0.0f),
         make_float4(__uint_as_float(b.x), __uint_as_float(b.y), __uint_as_float(b.z), 0.0f), ro.x, ro.y, ro.z, ix,
         iy, iz, &tn, &tf);
    // the trimmed range test: [t_min, t_hit] shrinks with every hit
    if (fmaxf(tn, t_min) <= fminf(tf, t_hit)) {
      if (kind == BVH_LEAF) {
        unsigned count = b.w, first = word & 0x3fffffffu;
        for (unsigned r = 0; r < count; r++) {
          unsigned t = refs[first + r];
          if (affine(tris, t, offsets[tri_obj[t]], ro.x, ro.y, ro.z, rd.x, rd.y, rd.z, t_min, &t_hit))
            found = (int)t;
        }
      } else {
        unsigned axis = kind;
        float da = axis == 0 ? rd.x : (axis == 1 ? rd.y : rd.z);
        // front-back order: the left child (lower centroids) is idx + 1
        unsigned front = idx + 1, back = word & 0x3fffffffu;
        if (__float_as_int(da) < 0) {
          unsigned t = front;
          front = back;
          back = t;
        }
        stack[size] = back;                              // @count push st.local.u32
        size++;
        idx = front;
        continue;
      }
    }
    if (size == 0) break;
    size--;
    idx = stack[size];                                   // @count pop ld.local.u32
  }
  hits[i] = make_float4(found >= 0 ? t_hit : 0.0f, __int_as_float(found), 0.0f, 0.0f);
}

// verts: per triangle three float4 (w unused); leaves: the leaf node indices;
// parents: per node its parent (the root's is itself); arrivals: per node,
// zero before the launch.
extern "C" __global__ void bvh_refit(const BvhParams *params, float4 *nodes, const unsigned *leaves,
                                     const unsigned *parents, const unsigned *refs, const float4 *verts,
                                     const unsigned *tri_obj, const float4 *offsets, unsigned *arrivals) {
  int i = (int)WL_TID;
  if (i >= params->num_leaves) return;
  unsigned idx = leaves[i];
  float4 a = nodes[2 * idx];
  unsigned first = __float_as_uint(a.w) & 0x3fffffffu, count = __float_as_uint(nodes[2 * idx + 1].w);
  float lx = __int_as_float(0x7f800000), ly = lx, lz = lx;
  float hx = -lx, hy = -lx, hz = -lx;
  for (unsigned r = 0; r < count; r++) {
    unsigned t = refs[first + r];
    float4 off = offsets[tri_obj[t]];
    for (unsigned k = 0; k < 3; k++) {
      float4 v = verts[3 * t + k];
      float x = v.x + off.x, y = v.y + off.y, z = v.z + off.z;
      lx = fminf(lx, x);
      ly = fminf(ly, y);
      lz = fminf(lz, z);
      hx = fmaxf(hx, x);
      hy = fmaxf(hy, y);
      hz = fmaxf(hz, z);
    }
  }
  volatile float *vn = (volatile float *)nodes;
  for (;;) {
    vn[8 * idx] = lx;
    vn[8 * idx + 1] = ly;
    vn[8 * idx + 2] = lz;
    vn[8 * idx + 4] = hx;
    vn[8 * idx + 5] = hy;
    vn[8 * idx + 6] = hz;
    if (idx == 0) break;
    __threadfence();
    unsigned p = parents[idx];
    if (atomicAdd(&arrivals[p], 1u) == 0u) break;   // the kernel's only atomic
    // the second arrival: both children's boxes are final; their union,
    // left then right whichever arrived second
    unsigned l = 8 * (p + 1), r = 8 * (__float_as_uint(vn[8 * p + 3]) & 0x3fffffffu);
    lx = fminf(vn[l], vn[r]);
    ly = fminf(vn[l + 1], vn[r + 1]);
    lz = fminf(vn[l + 2], vn[r + 2]);
    hx = fmaxf(vn[l + 4], vn[r + 4]);
    hy = fmaxf(vn[l + 5], vn[r + 5]);
    hz = fmaxf(vn[l + 6], vn[r + 6]);
    idx = p;
  }
}
