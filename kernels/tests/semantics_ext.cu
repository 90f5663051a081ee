// Semantics of the instructions ordinary CUDA code emits beyond the basic set
// (issue 20, "Also"): warp reductions and matches, CTA barrier reductions,
// prmt modes, bfind, 64-bit bit counts, dot products, carry chains, half and
// bfloat16 arithmetic and conversions. One kernel per family, inline PTX so
// that neither compiler rewrites the instruction; every rounding is explicit
// (`.rn`), so that ptxas contracts nothing.
// out[i * W + k] is word k of the W words of thread i, from a[i] and b[i], for i < n.
#include "../prelude.h"

typedef unsigned long long u64;

// warp reductions: redux.sync over the whole warp
extern "C" __global__ void sem_redux(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned x = a[i] ^ b[i], r[8];
    asm volatile("redux.sync.add.u32 %0, %1, 0xffffffff;" : "=r"(r[0]) : "r"(x));
    asm volatile("redux.sync.min.u32 %0, %1, 0xffffffff;" : "=r"(r[1]) : "r"(x));
    asm volatile("redux.sync.max.u32 %0, %1, 0xffffffff;" : "=r"(r[2]) : "r"(x));
    asm volatile("redux.sync.min.s32 %0, %1, 0xffffffff;" : "=r"(r[3]) : "r"(x));
    asm volatile("redux.sync.max.s32 %0, %1, 0xffffffff;" : "=r"(r[4]) : "r"(x));
    asm volatile("redux.sync.and.b32 %0, %1, 0xffffffff;" : "=r"(r[5]) : "r"(x));
    asm volatile("redux.sync.or.b32 %0, %1, 0xffffffff;" : "=r"(r[6]) : "r"(x));
    asm volatile("redux.sync.xor.b32 %0, %1, 0xffffffff;" : "=r"(r[7]) : "r"(x));
    for (int k = 0; k < 8; k++) out[i * 8 + k] = r[k];
  }
}

// match.any / match.all over the whole warp, and activemask in a branch
extern "C" __global__ void sem_match(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned r0, r1, r2, r3, p1, p2, am = 0;
    u64 w = ((u64)a[i] << 32) | (b[i] & 3);
    asm volatile("match.any.sync.b32 %0, %1, 0xffffffff;" : "=r"(r0) : "r"(b[i]));
    asm volatile("match.any.sync.b64 %0, %1, 0xffffffff;" : "=r"(r1) : "l"(w));
    asm volatile("{ .reg .pred p; match.all.sync.b32 %0|p, %2, 0xffffffff; selp.u32 %1, 1, 0, p; }"
                 : "=r"(r2), "=r"(p1) : "r"(a[i]));
    asm volatile("{ .reg .pred p; match.all.sync.b32 %0|p, %2, 0xffffffff; selp.u32 %1, 1, 0, p; }"
                 : "=r"(r3), "=r"(p2) : "r"(b[i] & 0x80000000u));
    if (b[i] & 1) asm volatile("activemask.b32 %0;" : "=r"(am));
    out[i * 7] = r0;
    out[i * 7 + 1] = r1;
    out[i * 7 + 2] = r2;
    out[i * 7 + 3] = p1;
    out[i * 7 + 4] = r3;
    out[i * 7 + 5] = p2;
    out[i * 7 + 6] = am;
  }
}

// __syncthreads_count / _and / _or: bar.red over the CTA
extern "C" __global__ void sem_bar_red(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  unsigned x = i < n ? a[i] ^ b[i] : 0, c, all, any;
  asm volatile("{ .reg .pred p; setp.ne.u32 p, %1, 0; bar.red.popc.u32 %0, 0, p; }" : "=r"(c) : "r"(x & 1));
  asm volatile("{ .reg .pred p, q; setp.ne.u32 p, %1, 0; bar.red.and.pred q, 1, p; selp.u32 %0, 1, 0, q; }"
               : "=r"(all) : "r"(x & 0x80000000u));
  asm volatile("{ .reg .pred p, q; setp.ne.u32 p, %1, 0; bar.red.or.pred q, 2, p; selp.u32 %0, 1, 0, q; }"
               : "=r"(any) : "r"((unsigned)(x == 0x80000001u)));
  if (i < n) {
    out[i * 3] = c;
    out[i * 3 + 1] = all;
    out[i * 3 + 2] = any;
  }
}

// prmt in every mode, the selector from b
extern "C" __global__ void sem_prmt_modes(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned x = a[i], y = b[i] * 0x9E3779B9u, c = b[i] ^ (a[i] >> 3), r[7];
    asm volatile("prmt.b32.f4e %0, %1, %2, %3;" : "=r"(r[0]) : "r"(x), "r"(y), "r"(c));
    asm volatile("prmt.b32.b4e %0, %1, %2, %3;" : "=r"(r[1]) : "r"(x), "r"(y), "r"(c));
    asm volatile("prmt.b32.rc8 %0, %1, %2, %3;" : "=r"(r[2]) : "r"(x), "r"(y), "r"(c));
    asm volatile("prmt.b32.ecl %0, %1, %2, %3;" : "=r"(r[3]) : "r"(x), "r"(y), "r"(c));
    asm volatile("prmt.b32.ecr %0, %1, %2, %3;" : "=r"(r[4]) : "r"(x), "r"(y), "r"(c));
    asm volatile("prmt.b32.rc16 %0, %1, %2, %3;" : "=r"(r[5]) : "r"(x), "r"(y), "r"(c));
    asm volatile("prmt.b32 %0, %1, %2, %3;" : "=r"(r[6]) : "r"(x), "r"(y), "r"(c));
    for (int k = 0; k < 7; k++) out[i * 7 + k] = r[k];
  }
}

// bfind (32 and 64 bits, .shiftamt), and popc/clz/brev on 64 bits
extern "C" __global__ void sem_bits(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned r[10];
    u64 w = ((u64)a[i] << 32) | b[i], v = (u64)b[i], rv;
    asm volatile("bfind.u32 %0, %1;" : "=r"(r[0]) : "r"(b[i]));
    asm volatile("bfind.s32 %0, %1;" : "=r"(r[1]) : "r"(b[i]));
    asm volatile("bfind.shiftamt.u32 %0, %1;" : "=r"(r[2]) : "r"(b[i]));
    asm volatile("bfind.shiftamt.s32 %0, %1;" : "=r"(r[3]) : "r"(a[i]));
    asm volatile("bfind.u64 %0, %1;" : "=r"(r[4]) : "l"(w));
    asm volatile("bfind.s64 %0, %1;" : "=r"(r[5]) : "l"(w));
    asm volatile("popc.b64 %0, %1;" : "=r"(r[6]) : "l"(w));
    asm volatile("clz.b64 %0, %1;" : "=r"(r[7]) : "l"(v));
    asm volatile("brev.b64 %0, %1;" : "=l"(rv) : "l"(w));
    r[8] = (unsigned)rv;
    r[9] = (unsigned)(rv >> 32);
    for (int k = 0; k < 10; k++) out[i * 10 + k] = r[k];
  }
}

// dp4a / dp2a in every signedness
extern "C" __global__ void sem_dp(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned x = a[i], y = b[i] * 0x9E3779B9u, c = a[i] ^ b[i], r[6];
    asm volatile("dp4a.u32.u32 %0, %1, %2, %3;" : "=r"(r[0]) : "r"(x), "r"(y), "r"(c));
    asm volatile("dp4a.s32.s32 %0, %1, %2, %3;" : "=r"(r[1]) : "r"(x), "r"(y), "r"(c));
    asm volatile("dp4a.s32.u32 %0, %1, %2, %3;" : "=r"(r[2]) : "r"(x), "r"(y), "r"(c));
    asm volatile("dp2a.lo.u32.s32 %0, %1, %2, %3;" : "=r"(r[3]) : "r"(x), "r"(y), "r"(c));
    asm volatile("dp2a.hi.s32.s32 %0, %1, %2, %3;" : "=r"(r[4]) : "r"(x), "r"(y), "r"(c));
    asm volatile("dp2a.hi.u32.u32 %0, %1, %2, %3;" : "=r"(r[5]) : "r"(x), "r"(y), "r"(c));
    for (int k = 0; k < 6; k++) out[i * 6 + k] = r[k];
  }
}

// carry chains: 96-bit add and subtract, a 64-bit multiply-add
extern "C" __global__ void sem_carry(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    unsigned x = a[i], y = b[i], r[8];
    asm volatile("add.cc.u32 %0, %3, %4;\n\taddc.cc.u32 %1, %4, %3;\n\taddc.u32 %2, 0, 0;"
                 : "=r"(r[0]), "=r"(r[1]), "=r"(r[2]) : "r"(x), "r"(y));
    asm volatile("sub.cc.u32 %0, %3, %4;\n\tsubc.cc.u32 %1, %4, %3;\n\tsubc.u32 %2, 0, 0;"
                 : "=r"(r[3]), "=r"(r[4]), "=r"(r[5]) : "r"(x), "r"(y));
    asm volatile("mad.lo.cc.u32 %0, %2, %3, %2;\n\tmadc.hi.u32 %1, %2, %3, %3;"
                 : "=r"(r[6]), "=r"(r[7]) : "r"(x), "r"(y));
    for (int k = 0; k < 8; k++) out[i * 8 + k] = r[k];
  }
}

// half and bfloat16: conversions and arithmetic (a, b are f32 bits)
extern "C" __global__ void sem_half(unsigned *out, const unsigned *a, const unsigned *b, int n) {
  int i = WL_TID;
  if (i < n) {
    float fa = __int_as_float(a[i]), fb = __int_as_float(b[i]);
    unsigned short ha, hb, hz, r16[12];
    unsigned r[8];
    asm volatile("cvt.rn.f16.f32 %0, %1;" : "=h"(ha) : "f"(fa));
    asm volatile("cvt.rn.f16.f32 %0, %1;" : "=h"(hb) : "f"(fb));
    asm volatile("cvt.rz.f16.f32 %0, %1;" : "=h"(hz) : "f"(fa));
    asm volatile("add.rn.f16 %0, %1, %2;" : "=h"(r16[0]) : "h"(ha), "h"(hb));
    asm volatile("sub.rn.f16 %0, %1, %2;" : "=h"(r16[1]) : "h"(ha), "h"(hb));
    asm volatile("mul.rn.f16 %0, %1, %2;" : "=h"(r16[2]) : "h"(ha), "h"(hb));
    asm volatile("fma.rn.f16 %0, %1, %2, %1;" : "=h"(r16[3]) : "h"(ha), "h"(hb));
    asm volatile("neg.f16 %0, %1;" : "=h"(r16[4]) : "h"(ha));
    asm volatile("abs.f16 %0, %1;" : "=h"(r16[5]) : "h"(ha));
    asm volatile("min.f16 %0, %1, %2;" : "=h"(r16[6]) : "h"(ha), "h"(hb));
    asm volatile("max.f16 %0, %1, %2;" : "=h"(r16[7]) : "h"(ha), "h"(hb));
    asm volatile("add.rn.sat.f16 %0, %1, %2;" : "=h"(r16[8]) : "h"(ha), "h"(hb));
    asm volatile("cvt.f32.f16 %0, %1;" : "=r"(r[0]) : "h"(ha));
    asm volatile("{ .reg .b32 x, y; mov.b32 x, {%1, %2}; mov.b32 y, {%2, %1}; add.rn.f16x2 %0, x, y; }"
                 : "=r"(r[1]) : "h"(ha), "h"(hb));
    asm volatile("{ .reg .b32 x, y; mov.b32 x, {%1, %2}; mov.b32 y, {%2, %1}; fma.rn.f16x2 %0, x, y, x; }"
                 : "=r"(r[2]) : "h"(ha), "h"(hb));
    asm volatile("cvt.rn.f16x2.f32 %0, %1, %2;" : "=r"(r[3]) : "f"(fa), "f"(fb));
    // bfloat16
    unsigned short ba, bb, bz, s16[6];
    asm volatile("cvt.rn.bf16.f32 %0, %1;" : "=h"(ba) : "f"(fa));
    asm volatile("cvt.rn.bf16.f32 %0, %1;" : "=h"(bb) : "f"(fb));
    asm volatile("cvt.rz.bf16.f32 %0, %1;" : "=h"(bz) : "f"(fa));
    asm volatile("add.rn.bf16 %0, %1, %2;" : "=h"(s16[0]) : "h"(ba), "h"(bb));
    asm volatile("mul.rn.bf16 %0, %1, %2;" : "=h"(s16[1]) : "h"(ba), "h"(bb));
    asm volatile("fma.rn.bf16 %0, %1, %2, %1;" : "=h"(s16[2]) : "h"(ba), "h"(bb));
    asm volatile("min.bf16 %0, %1, %2;" : "=h"(s16[3]) : "h"(ba), "h"(bb));
    asm volatile("max.bf16 %0, %1, %2;" : "=h"(s16[4]) : "h"(ba), "h"(bb));
    asm volatile("neg.bf16 %0, %1;" : "=h"(s16[5]) : "h"(ba));
    asm volatile("cvt.f32.bf16 %0, %1;" : "=r"(r[4]) : "h"(ba));
    asm volatile("{ .reg .b32 x, y; mov.b32 x, {%1, %2}; mov.b32 y, {%2, %1}; fma.rn.bf16x2 %0, x, y, x; }"
                 : "=r"(r[5]) : "h"(ba), "h"(bb));
    asm volatile("cvt.rn.bf16x2.f32 %0, %1, %2;" : "=r"(r[6]) : "f"(fa), "f"(fb));
    asm volatile("{ .reg .pred p, q, s; setp.lt.f16 p, %1, %2; setp.nan.f16 q, %1, %2; setp.gtu.bf16 s, %3, %4;\n\t"
                 "selp.u32 %0, 1, 0, p; @q or.b32 %0, %0, 2; @s or.b32 %0, %0, 4; }"
                 : "=r"(r[7]) : "h"(ha), "h"(hb), "h"(ba), "h"(bb));
    out[i * 18] = ha | (unsigned)hz << 16;
    out[i * 18 + 1] = r16[0] | (unsigned)r16[1] << 16;
    out[i * 18 + 2] = r16[2] | (unsigned)r16[3] << 16;
    out[i * 18 + 3] = r16[4] | (unsigned)r16[5] << 16;
    out[i * 18 + 4] = r16[6] | (unsigned)r16[7] << 16;
    out[i * 18 + 5] = r16[8] | (unsigned)hb << 16;
    out[i * 18 + 6] = r[0];
    out[i * 18 + 7] = r[1];
    out[i * 18 + 8] = r[2];
    out[i * 18 + 9] = r[3];
    out[i * 18 + 10] = ba | (unsigned)bz << 16;
    out[i * 18 + 11] = s16[0] | (unsigned)s16[1] << 16;
    out[i * 18 + 12] = s16[2] | (unsigned)s16[3] << 16;
    out[i * 18 + 13] = s16[4] | (unsigned)s16[5] << 16;
    out[i * 18 + 14] = r[4];
    out[i * 18 + 15] = r[5];
    out[i * 18 + 16] = r[6];
    out[i * 18 + 17] = r[7];
  }
}
