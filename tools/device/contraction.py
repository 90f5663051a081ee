#!/usr/bin/env python3
"""FFMA contraction by ptxas: small PTX kernels, one per case, run on the GPU.

    python3 tools/device/contraction.py gen DIR      # writes DIR/contraction.ptx and DIR/inputs.json
    python3 tools/device/contraction.py run DIR OUT  # on the GPU machine: ptxas (default and --fmad=false),
                                                     # driver JIT, cuobjdump -sass; writes OUT/gpu_fma_contraction.json
    python3 tools/device/contraction.py finish RAW ENV FIXTURE   # adds the device description and a verdict per case

Each case is a kernel `(u64 in, u64 out)`: thread i loads four values a, b, c, d
from in[4i..4i+4] and stores two results o0, o1 at out[2i..2i+2]. Inputs are
drawn so that every candidate computation of the case (fused as one FMA, or
each operation rounded as written, ...) gives different bits; the candidates are
computed here exactly (fractions, one rounding per operation), so the GPU's
results can be matched against them without trusting any host FPU.
Pure standard library except `run`, which needs CuPy and the CUDA toolkit.
"""
import json
import os
import random
import re
import struct
import subprocess
import sys
from fractions import Fraction

# ----------------------------------------------------------------- exact IEEE arithmetic


class Fmt:
    def __init__(self, name, mant, emin, emax, width):
        self.name, self.mant, self.emin, self.emax, self.width = name, mant, emin, emax, width

    def to_frac(self, bits):
        if self.width == 16:
            v = struct.unpack("<e", struct.pack("<H", bits))[0]
        elif self.width == 32:
            v = struct.unpack("<f", struct.pack("<I", bits))[0]
        else:
            v = struct.unpack("<d", struct.pack("<Q", bits))[0]
        if v != v or v in (float("inf"), float("-inf")):
            raise ValueError("non-finite operand")
        return Fraction(v)

    def to_bits(self, q, mode="rn"):
        """Round the exact value q to this format (subnormals, overflow to inf)."""
        if q == 0:
            return 0
        sign = 1 if q < 0 else 0
        m = -q if sign else q
        e = m.numerator.bit_length() - m.denominator.bit_length()
        if Fraction(2) ** e > m:
            e -= 1
        e = max(e, self.emin)
        scale = Fraction(2) ** (e - (self.mant - 1))
        n = m / scale
        fl = n.numerator // n.denominator
        rem = n - fl
        if mode == "rn":
            up = rem > Fraction(1, 2) or (rem == Fraction(1, 2) and fl % 2 == 1)
        elif mode == "rz":
            up = False
        elif mode == "ru":
            up = rem > 0 and not sign
        else:  # rd
            up = rem > 0 and sign
        n = fl + (1 if up else 0)
        v = n * scale
        maxv = (2 - Fraction(2) ** (1 - self.mant)) * Fraction(2) ** self.emax
        if v > maxv:
            if mode == "rn" or (mode == "ru" and not sign) or (mode == "rd" and sign):
                inf = {16: 0x7C00, 32: 0x7F800000, 64: 0x7FF0000000000000}[self.width]
                return inf | (1 << (self.width - 1)) if sign else inf
            v = maxv
        f = float(v) * (-1 if sign else 1)
        if self.width == 16:
            return struct.unpack("<H", struct.pack("<e", f))[0]
        if self.width == 32:
            return struct.unpack("<I", struct.pack("<f", f))[0]
        return struct.unpack("<Q", struct.pack("<d", f))[0]


F16 = Fmt("f16", 11, -14, 15, 16)
F32 = Fmt("f32", 24, -126, 127, 32)
F64 = Fmt("f64", 53, -1022, 1023, 64)


class Ar:
    """Exact operations on bit patterns of one format, each rounded once."""

    def __init__(self, fmt):
        self.f = fmt

    def v(self, bits):
        return self.f.to_frac(bits)

    def flush(self, bits):
        tiny = Fraction(2) ** self.f.emin
        q = self.v(bits)
        if q != 0 and abs(q) < tiny:
            return (1 << (self.f.width - 1)) if q < 0 else 0
        return bits

    def mul(self, a, b, mode="rn"):
        return self.f.to_bits(self.v(a) * self.v(b), mode)

    def add(self, a, b, mode="rn"):
        return self.f.to_bits(self.v(a) + self.v(b), mode)

    def sub(self, a, b, mode="rn"):
        return self.f.to_bits(self.v(a) - self.v(b), mode)

    def neg(self, a):
        return a ^ (1 << (self.f.width - 1))

    def abs(self, a):
        return a & ((1 << (self.f.width - 1)) - 1)

    def fma(self, a, b, c, mode="rn"):
        return self.f.to_bits(self.v(a) * self.v(b) + self.v(c), mode)

    def sat(self, x):
        q = self.v(x)
        if q <= 0:
            return 0
        if q >= 1:
            return self.f.to_bits(Fraction(1))
        return x


A16, A32, A64 = Ar(F16), Ar(F32), Ar(F64)

# ----------------------------------------------------------------- the cases
# body: PTX using %fa %fb %fc %fd (inputs), %fo0 %fo1 (outputs), %ft0..%ft3, %p1..%p3, %n, %i (thread index).
# cands: name -> function(ar, a, b, c, d, i) -> (o0, o1); o1 defaults to the +0 the kernel starts with.
# gen: how inputs are drawn (see draw()).


def _two(f):
    return lambda A, a, b, c, d, i: f(A, a, b, c, d, i)


CASES = []


def case(name, body, cands, gen="cancel", ty="f32", note=""):
    CASES.append(dict(name=name, body=body, cands=cands, gen=gen, ty=ty, note=note))


def fused(A, a, b, c, d, i):
    return (A.fma(a, b, c), 0)


def unfused(A, a, b, c, d, i):
    return (A.add(A.mul(a, b), c), 0)


for ty in ("f32", "f64"):
    p = "" if ty == "f32" else "f64_"
    case(p + "mul_add", "mul.%T %ft0, %fa, %fb;\nadd.%T %fo0, %ft0, %fc;",
         {"fused": fused, "unfused": unfused}, ty=ty, note="product is add's first operand, single use")
    case(p + "add_mul_second", "mul.%T %ft0, %fa, %fb;\nadd.%T %fo0, %fc, %ft0;",
         {"fused": fused, "unfused": unfused}, ty=ty, note="product is add's second operand")
    case(p + "sub_mul_first", "mul.%T %ft0, %fa, %fb;\nsub.%T %fo0, %ft0, %fc;",
         {"fused fma(a,b,-c)": lambda A, a, b, c, d, i: (A.fma(a, b, A.neg(c)), 0),
          "unfused": lambda A, a, b, c, d, i: (A.sub(A.mul(a, b), c), 0)}, gen="cancel_pos", ty=ty)
    case(p + "sub_mul_second", "mul.%T %ft0, %fa, %fb;\nsub.%T %fo0, %fc, %ft0;",
         {"fused fma(-a,b,c)": lambda A, a, b, c, d, i: (A.fma(A.neg(a), b, c), 0),
          "unfused": lambda A, a, b, c, d, i: (A.sub(c, A.mul(a, b)), 0)}, gen="cancel_pos", ty=ty)
    case(p + "product_also_stored", "mul.%T %ft0, %fa, %fb;\nadd.%T %fo0, %ft0, %fc;\nmov.%T %fo1, %ft0;",
         {"fused, product stored": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.mul(a, b)),
          "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.mul(a, b))}, ty=ty,
         note="the product has a second use (a store)")
    case(p + "mul_rn_add", "mul.rn.%T %ft0, %fa, %fb;\nadd.%T %fo0, %ft0, %fc;",
         {"fused": fused, "unfused": unfused}, ty=ty, note=".rn written on the mul")
    case(p + "two_products_sum", "mul.%T %ft0, %fa, %fb;\nmul.%T %ft1, %fc, %fd;\nadd.%T %fo0, %ft0, %ft1;",
         {"fma(a,b,c*d)": lambda A, a, b, c, d, i: (A.fma(a, b, A.mul(c, d)), 0),
          "fma(c,d,a*b)": lambda A, a, b, c, d, i: (A.fma(c, d, A.mul(a, b)), 0),
          "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), A.mul(c, d)), 0)}, gen="two_products", ty=ty,
         note="a*b + c*d: which product is fused")

case("mul_add_rn", "mul.f32 %ft0, %fa, %fb;\nadd.rn.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note=".rn written on the add")
case("mul_rn_add_rn", "mul.rn.f32 %ft0, %fa, %fb;\nadd.rn.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note=".rn on both")
case("mul_rz_add", "mul.rz.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused (mul.rz)": lambda A, a, b, c, d, i: (A.add(A.mul(a, b, "rz"), c), 0)})
case("mul_add_rz", "mul.f32 %ft0, %fa, %fb;\nadd.rz.f32 %fo0, %ft0, %fc;",
     {"fused (fma.rz)": lambda A, a, b, c, d, i: (A.fma(a, b, c, "rz"), 0),
      "unfused (add.rz)": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c, "rz"), 0)})
case("neg_between", "mul.f32 %ft0, %fa, %fb;\nneg.f32 %ft1, %ft0;\nadd.f32 %fo0, %ft1, %fc;",
     {"fused fma(-a,b,c)": lambda A, a, b, c, d, i: (A.fma(A.neg(a), b, c), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.neg(A.mul(a, b)), c), 0)}, gen="cancel_pos")
case("neg_between_sub", "mul.f32 %ft0, %fa, %fb;\nneg.f32 %ft1, %ft0;\nsub.f32 %fo0, %ft1, %fc;",
     {"fused fma(-a,b,-c)": lambda A, a, b, c, d, i: (A.fma(A.neg(a), b, A.neg(c)), 0),
      "unfused": lambda A, a, b, c, d, i: (A.sub(A.neg(A.mul(a, b)), c), 0)})
case("abs_between", "mul.f32 %ft0, %fa, %fb;\nabs.f32 %ft1, %ft0;\nadd.f32 %fo0, %ft1, %fc;",
     {"fused fma(|a|,|b|,c)": lambda A, a, b, c, d, i: (A.fma(A.abs(a), A.abs(b), c), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.abs(A.mul(a, b)), c), 0)}, gen="cancel_neg")
case("mov_between", "mul.f32 %ft0, %fa, %fb;\nmov.f32 %ft1, %ft0;\nadd.f32 %fo0, %ft1, %fc;",
     {"fused": fused, "unfused": unfused})
case("product_two_adds", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\nadd.f32 %fo1, %ft0, %fd;",
     {"both fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.fma(a, b, d)),
      "first fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.add(A.mul(a, b), d)),
      "second fused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.fma(a, b, d)),
      "neither": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.add(A.mul(a, b), d))},
     gen="two_cancel", note="one product, two adds")
case("product_add_and_sub", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\nsub.f32 %fo1, %fd, %ft0;",
     {"both fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.fma(A.neg(a), b, d)),
      "neither": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.sub(d, A.mul(a, b))),
      "first fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.sub(d, A.mul(a, b))),
      "second fused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.fma(A.neg(a), b, d))},
     gen="two_cancel_mixed")
case("product_used_by_setp", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\n"
     "setp.gt.f32 %p1, %ft0, %fd;\nselp.f32 %fo1, 0f3F800000, 0f00000000, %p1;",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), _gt(A, A.mul(a, b), d)),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), _gt(A, A.mul(a, b), d))},
     gen="cancel_d_near_ab", note="the product also feeds a comparison")
case("two_products_diff", "mul.f32 %ft0, %fa, %fb;\nmul.f32 %ft1, %fc, %fd;\nsub.f32 %fo0, %ft0, %ft1;",
     {"fma(a,b,-(c*d))": lambda A, a, b, c, d, i: (A.fma(a, b, A.neg(A.mul(c, d))), 0),
      "fma(-c,d,a*b)": lambda A, a, b, c, d, i: (A.fma(A.neg(c), d, A.mul(a, b)), 0),
      "unfused": lambda A, a, b, c, d, i: (A.sub(A.mul(a, b), A.mul(c, d)), 0)}, gen="two_products_pos")
case("product_of_product", "mul.f32 %ft0, %fa, %fb;\nmul.f32 %ft1, %ft0, %fc;\nadd.f32 %fo0, %ft1, %fd;",
     {"fma(a*b,c,d)": lambda A, a, b, c, d, i: (A.fma(A.mul(a, b), c, d), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(A.mul(a, b), c), d), 0)}, gen="triple_product")
case("immediate_factor", "mul.f32 %ft0, %fa, 0f3DCCCCCD;\nadd.f32 %fo0, %ft0, %fc;",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, 0x3DCCCCCD, c), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, 0x3DCCCCCD), c), 0)}, gen="cancel_imm",
     note="mul by an immediate (0.1f)")
case("ftz_both", "mul.ftz.f32 %ft0, %fa, %fb;\nadd.ftz.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note="normal inputs and results")
case("ftz_mul_only", "mul.ftz.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note="normal inputs and results")
case("ftz_add_only", "mul.f32 %ft0, %fa, %fb;\nadd.ftz.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note="normal inputs and results")
case("sat_add", "mul.f32 %ft0, %fa, %fb;\nadd.sat.f32 %fo0, %ft0, %fc;",
     {"fused, saturated": lambda A, a, b, c, d, i: (A.sat(A.fma(a, b, c)), 0),
      "unfused": lambda A, a, b, c, d, i: (A.sat(A.add(A.mul(a, b), c)), 0)}, gen="sat")
case("sat_mul", "mul.sat.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;",
     {"fused (sat dropped)": fused,
      "unfused": lambda A, a, b, c, d, i: (A.add(A.sat(A.mul(a, b)), c), 0)}, gen="sat")
case("branch_divergent", "mul.f32 %ft0, %fa, %fb;\nsetp.lt.f32 %p1, %fd, 0f00000000;\n@%p1 bra $L_neg;\n"
     "add.f32 %fo0, %ft0, %fc;\nbra.uni $L_end;\n$L_neg:\nsub.f32 %fo0, %ft0, %fc;\n$L_end:",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, b, A.neg(c) if _neg(A, d) else c), 0),
      "unfused": lambda A, a, b, c, d, i: ((A.sub if _neg(A, d) else A.add)(A.mul(a, b), c), 0)},
     gen="branch", note="mul in one block, add/sub in the two successors (per-lane branch)")
case("across_loop", "mul.f32 %ft0, %fa, %fb;\nand.b32 %n, %i, 3;\n$L_loop:\nsetp.eq.u32 %p1, %n, 0;\n"
     "@%p1 bra $L_done;\nsub.u32 %n, %n, 1;\nbra.uni $L_loop;\n$L_done:\nadd.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note="mul before a loop, add after it")
case("in_loop_accumulate", "mov.f32 %fo0, %fc;\nand.b32 %n, %i, 1;\nadd.u32 %n, %n, 1;\n$L_loop:\n"
     "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %fo0, %ft0;\nsub.u32 %n, %n, 1;\nsetp.ne.u32 %p1, %n, 0;\n@%p1 bra $L_loop;",
     {"fused": lambda A, a, b, c, d, i: (_acc(A, a, b, c, i, True), 0),
      "unfused": lambda A, a, b, c, d, i: (_acc(A, a, b, c, i, False), 0)},
     note="acc = c; repeat 1 + (i & 1) times: acc += a*b (loop-invariant product)")

# Second batch: where the uses of the product are (blocks, predicates, other users).
case("branch_single_use", "mul.f32 %ft0, %fa, %fb;\nmov.f32 %fo0, %fc;\nsetp.lt.f32 %p1, %fd, 0f00000000;\n"
     "@%p1 bra $L_skip;\nadd.f32 %fo0, %ft0, %fc;\n$L_skip:",
     {"fused": fused, "unfused": unfused}, gen="cancel_dpos",
     note="mul in the entry block, its only use (add) in a conditional block (never skipped at run time)")
case("predicated_add", "mul.f32 %ft0, %fa, %fb;\nmov.f32 %fo0, %fc;\nsetp.ge.f32 %p1, %fd, 0f00000000;\n"
     "@%p1 add.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, gen="cancel_dpos", note="the add is predicated (predicate true at run time)")
case("branch_both_arms_add", "mul.f32 %ft0, %fa, %fb;\nand.b32 %n, %i, 1;\nsetp.eq.u32 %p1, %n, 1;\n"
     "@%p1 bra $L_odd;\nadd.f32 %fo0, %ft0, %fc;\nbra.uni $L_end;\n$L_odd:\nadd.f32 %fo0, %ft0, %fd;\n$L_end:",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, b, d if i & 1 else c), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), d if i & 1 else c), 0)}, gen="two_cancel",
     note="two uses (adds) in the two arms of a branch on the thread index")
case("phi_of_products", "and.b32 %n, %i, 1;\nsetp.eq.u32 %p1, %n, 1;\n@%p1 bra $L_odd;\nmul.f32 %ft0, %fa, %fb;\n"
     "bra.uni $L_end;\n$L_odd:\nmul.f32 %ft0, %fa, %fd;\n$L_end:\nadd.f32 %fo0, %ft0, %fc;",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, d if i & 1 else b, c), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, d if i & 1 else b), c), 0)}, gen="phi",
     note="the add's operand is a product from either arm of a branch")
case("barrier_between", "mul.f32 %ft0, %fa, %fb;\nbar.sync 0;\nadd.f32 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, note="bar.sync between mul and add")
case("product_add_and_mul", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\nmul.f32 %fo1, %ft0, %fd;",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.mul(A.mul(a, b), d)),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.mul(A.mul(a, b), d))},
     note="the product also feeds a multiplication")
case("product_three_adds", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\nadd.f32 %ft1, %ft0, %fd;\n"
     "add.f32 %fo1, %ft1, %ft0;",
     {"all fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.fma(a, b, A.fma(a, b, d))),
      "none": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.add(A.add(A.mul(a, b), d), A.mul(a, b)))},
     gen="two_cancel", note="o0 = p + c, o1 = (p + d) + p")
case("two_products_sum_later_def", "mul.f32 %ft1, %fc, %fd;\nmul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %ft1;",
     {"fma(a,b,c*d)": lambda A, a, b, c, d, i: (A.fma(a, b, A.mul(c, d)), 0),
      "fma(c,d,a*b)": lambda A, a, b, c, d, i: (A.fma(c, d, A.mul(a, b)), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), A.mul(c, d)), 0)}, gen="two_products",
     note="a*b + c*d with c*d computed first")
case("two_products_sum_swapped", "mul.f32 %ft0, %fa, %fb;\nmul.f32 %ft1, %fc, %fd;\nadd.f32 %fo0, %ft1, %ft0;",
     {"fma(a,b,c*d)": lambda A, a, b, c, d, i: (A.fma(a, b, A.mul(c, d)), 0),
      "fma(c,d,a*b)": lambda A, a, b, c, d, i: (A.fma(c, d, A.mul(a, b)), 0),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), A.mul(c, d)), 0)}, gen="two_products",
     note="c*d + a*b (operands of the add swapped)")
case("two_products_one_shared", "mul.f32 %ft0, %fa, %fb;\nmul.f32 %ft1, %fc, %fd;\nadd.f32 %fo0, %ft0, %ft1;\n"
     "mov.f32 %fo1, %ft0;",
     {"fma(a,b,c*d)": lambda A, a, b, c, d, i: (A.fma(a, b, A.mul(c, d)), A.mul(a, b)),
      "fma(c,d,a*b)": lambda A, a, b, c, d, i: (A.fma(c, d, A.mul(a, b)), A.mul(a, b)),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), A.mul(c, d)), A.mul(a, b))}, gen="two_products",
     note="a*b + c*d where a*b is also stored")
case("f64_product_two_adds", "mul.f64 %ft0, %fa, %fb;\nadd.f64 %fo0, %ft0, %fc;\nadd.f64 %fo1, %ft0, %fd;",
     {"both fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.fma(a, b, d)),
      "first fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.add(A.mul(a, b), d)),
      "second fused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.fma(a, b, d)),
      "neither": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.add(A.mul(a, b), d))},
     gen="two_cancel", ty="f64")
case("f64_product_used_by_setp", "mul.f64 %ft0, %fa, %fb;\nadd.f64 %fo0, %ft0, %fc;\n"
     "setp.gt.f64 %p1, %ft0, %fd;\nselp.f64 %fo1, 0d3FF0000000000000, 0d0000000000000000, %p1;",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), _gt(A, A.mul(a, b), d)),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), _gt(A, A.mul(a, b), d))},
     gen="cancel_d_near_ab", ty="f64")

# Third batch: definitions rather than register names, uses in two blocks, f16.
case("redefined_after_use", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\nmul.f32 %ft0, %fd, %fd;\n"
     "mov.f32 %fo1, %ft0;",
     {"fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.mul(d, d)),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.mul(d, d))},
     note="the product's register is reassigned (and stored) after its only use")
case("same_and_other_block_adds", "mul.f32 %ft0, %fa, %fb;\nadd.f32 %fo0, %ft0, %fc;\n"
     "setp.gt.f32 %p1, %fa, 0f7F000000;\n@%p1 bra $L_skip;\nadd.f32 %fo1, %ft0, %fd;\n$L_skip:",
     {"both fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.fma(a, b, d)),
      "first fused": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.add(A.mul(a, b), d)),
      "second fused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.fma(a, b, d)),
      "neither": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.add(A.mul(a, b), d))},
     gen="two_cancel", note="one add in the mul's block, one in the next block (branch never taken at run time)")
case("f16_mul_add", "mul.f16 %ft0, %fa, %fb;\nadd.f16 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, ty="f16", note="f16 in .b16 registers")
case("f16_mul_rn_add", "mul.rn.f16 %ft0, %fa, %fb;\nadd.f16 %fo0, %ft0, %fc;",
     {"fused": fused, "unfused": unfused}, ty="f16")
case("f16_product_also_stored", "mul.f16 %ft0, %fa, %fb;\nadd.f16 %fo0, %ft0, %fc;\nmov.b16 %fo1, %ft0;",
     {"fused, product stored": lambda A, a, b, c, d, i: (A.fma(a, b, c), A.mul(a, b)),
      "unfused": lambda A, a, b, c, d, i: (A.add(A.mul(a, b), c), A.mul(a, b))}, ty="f16")


def _gt(A, x, y):
    one = 0x3F800000 if A.f.width == 32 else 0x3FF0000000000000
    return one if A.v(x) > A.v(y) else 0


def _neg(A, d):
    return A.v(d) < 0


def _acc(A, a, b, c, i, f):
    acc = c
    for _ in range(1 + (i & 1)):
        acc = A.fma(a, b, acc) if f else A.add(A.mul(a, b), acc)
    return acc

# ----------------------------------------------------------------- inputs


def rnd_val(rng, fmt, lo_exp=-2, hi_exp=2, sign=None):
    s = rng.randrange(2) if sign is None else sign
    e = rng.randint(lo_exp, hi_exp)
    if fmt.width == 16:
        return (s << 15) | ((e + 15) << 10) | rng.getrandbits(10)
    if fmt.width == 32:
        return (s << 31) | ((e + 127) << 23) | rng.getrandbits(23)
    return (s << 63) | ((e + 1023) << 52) | rng.getrandbits(52)


def near(rng, A, x, neg, spread=4096):
    """A value within `spread` ulps of x (x negated if neg)."""
    spread = min(spread, 1 << (A.f.mant - 4))
    y = x + rng.randint(-spread, spread)
    y &= (1 << A.f.width) - 1
    return A.neg(y) if neg else y


def draw(gen, rng, A, i):
    f = A.f
    a, b = rnd_val(rng, f), rnd_val(rng, f)
    ab = A.mul(a, b)
    c = d = rnd_val(rng, f)
    if gen == "cancel":          # c close to -a*b (or random sign: also plain sums)
        c = near(rng, A, ab, rng.random() < 0.8)
    elif gen == "cancel_pos":    # c close to +a*b
        c = near(rng, A, ab, rng.random() < 0.2)
    elif gen == "cancel_neg":
        c = near(rng, A, A.abs(ab), True)
    elif gen == "two_cancel":
        c, d = near(rng, A, ab, True), near(rng, A, ab, True)
    elif gen == "two_cancel_mixed":
        c, d = near(rng, A, ab, True), near(rng, A, ab, False)
    elif gen == "cancel_d_near_ab":
        c, d = near(rng, A, ab, True), near(rng, A, ab, False, 2)
    elif gen in ("two_products", "two_products_pos"):
        c = rnd_val(rng, f)
        q = f.to_bits(A.v(ab) / A.v(c))
        d = near(rng, A, q, gen == "two_products", 64)
    elif gen == "triple_product":
        c = rnd_val(rng, f)
        d = near(rng, A, A.mul(ab, c), True)
    elif gen == "cancel_imm":
        c = near(rng, A, A.mul(a, 0x3DCCCCCD), True)
    elif gen == "sat":
        a, b = rnd_val(rng, f, -1, -1, 0), rnd_val(rng, f, -1, -1, 0)
        ab = A.mul(a, b)
        c = near(rng, A, ab, True, 1 << 22)
    elif gen == "cancel_dpos":
        c, d = near(rng, A, ab, rng.random() < 0.8), A.abs(rnd_val(rng, f))
    elif gen == "phi":
        d = rnd_val(rng, f)
        c = near(rng, A, A.mul(a, d) if i & 1 else ab, True)
    elif gen == "branch":
        d = rnd_val(rng, f)
        c = near(rng, A, ab, not _neg(A, d))
    return a, b, c, d


NTHREADS = 64


def make_inputs(cs, seed):
    A = {"f16": A16, "f32": A32, "f64": A64}[cs["ty"]]
    rng = random.Random(seed)
    rows, cands = [], {k: [] for k in cs["cands"]}
    tries = 0
    while len(rows) < NTHREADS:
        tries += 1
        if tries > 200000:
            raise RuntimeError("no distinguishing inputs for " + cs["name"])
        i = len(rows)
        a, b, c, d = draw(cs["gen"], rng, A, i)
        try:
            outs = {k: tuple(fn(A, a, b, c, d, i)) for k, fn in cs["cands"].items()}
        except ValueError:
            continue
        vals = list(outs.values())
        if len(set(vals)) != len(vals):
            continue
        if any(_bad(A, x) for v in vals for x in v):
            continue
        rows.append([a, b, c, d])
        for k in outs:
            cands[k].append(list(outs[k]))
    return rows, cands


def _bad(A, x):
    """Exclude results that are infinite, NaN or subnormal (ftz would blur the comparison)."""
    e = (x >> A.f.mant - 1) & ((1 << (A.f.width - A.f.mant)) - 1)
    return e == (1 << (A.f.width - A.f.mant)) - 1 or (e == 0 and (x & ((1 << (A.f.mant - 1)) - 1)) != 0)

# ----------------------------------------------------------------- PTX


def kernel_ptx(cs):
    t = cs["ty"]
    w = {"f16": 2, "f32": 4, "f64": 8}[t]
    body = cs["body"].replace("%T", t).replace("$L_", "$L_%s_" % cs["name"])
    body = "\n".join("    " + ln if not ln.startswith("$") else ln for ln in body.split("\n"))
    zero = {"f16": "0", "f32": "0f00000000", "f64": "0d0000000000000000"}[t]
    ld = {"f32": "    ld.global.v4.f32 {%fa, %fb, %fc, %fd}, [%rd3];",
          "f16": "    ld.global.v4.b16 {%fa, %fb, %fc, %fd}, [%rd3];",
          "f64": "    ld.global.v2.f64 {%fa, %fb}, [%rd3];\n    ld.global.v2.f64 {%fc, %fd}, [%rd3+16];"}[t]
    rt = "b16" if t == "f16" else t  # f16 values live in .b16 registers (as nvcc writes them)
    return f""".visible .entry {cs['name']}(.param .u64 pin, .param .u64 pout)
{{
    .reg .pred %p<4>;
    .reg .b32 %i, %n, %r<4>;
    .reg .b64 %rd<8>;
    .reg .{rt} %fa, %fb, %fc, %fd, %fo0, %fo1, %ft<4>;
    ld.param.u64 %rd0, [pin];
    ld.param.u64 %rd1, [pout];
    cvta.to.global.u64 %rd0, %rd0;
    cvta.to.global.u64 %rd1, %rd1;
    mov.u32 %r0, %tid.x;
    mov.u32 %r1, %ctaid.x;
    mov.u32 %r2, %ntid.x;
    mad.lo.u32 %i, %r1, %r2, %r0;
    mul.wide.u32 %rd2, %i, {4 * w};
    add.u64 %rd3, %rd0, %rd2;
{ld}
    mov.{rt} %fo1, {zero};
{body}
    mul.wide.u32 %rd4, %i, {2 * w};
    add.u64 %rd5, %rd1, %rd4;
    st.global.v2.{rt} [%rd5], {{%fo0, %fo1}};
    ret;
}}
"""


def module_ptx():
    head = ".version 8.0\n.target sm_90\n.address_size 64\n\n"
    return head + "\n".join(kernel_ptx(c) for c in CASES)


def gen(d):
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "contraction.ptx"), "w") as f:
        f.write(module_ptx())
    data = {}
    for k, cs in enumerate(CASES):
        rows, cands = make_inputs(cs, 1000 + k)
        data[cs["name"]] = dict(inputs=rows, candidates=cands)
    with open(os.path.join(d, "inputs.json"), "w") as f:
        json.dump(data, f)

# ----------------------------------------------------------------- GPU


def sass_ops(sass):
    """Per kernel, the floating-point opcodes of its SASS, in order."""
    out, cur = {}, None
    for ln in sass.splitlines():
        m = re.search(r"Function : (\S+)", ln)
        if m:
            cur = m.group(1)
            out[cur] = []
            continue
        m = re.search(r"/\*[0-9a-f]{4}\*/\s+(@!?U?P\w+\s+)?([A-Z][A-Z0-9_.]+)", ln)
        if cur and m:
            op = m.group(2)
            # HFMA2.MMA RZ-forms are how ptxas materialises constants (a move), not arithmetic
            if re.match(r"^(FFMA|FMUL|FADD|DFMA|DMUL|DADD|HFMA2|HMUL2|HADD2|FMNMX|FSETP|FSEL)", op) and op != "HFMA2.MMA":
                out[cur].append(op)
    return out


def run(d, out):
    import cupy as cp
    sh = lambda c: subprocess.run(c, shell=True, check=True, capture_output=True, text=True).stdout
    ptx = os.path.join(d, "contraction.ptx")
    with open(os.path.join(d, "inputs.json")) as f:
        data = json.load(f)
    builds = {"default": "", "fmad_false": "--fmad=false"}
    sass = {}
    mods = {}
    for k, flag in builds.items():
        cub = os.path.join(d, k + ".cubin")
        sh(f"ptxas -arch=sm_90 {flag} -o {cub} {ptx}")
        txt = sh(f"cuobjdump -sass {cub}")
        with open(os.path.join(out, "contraction_sass_%s.txt" % k), "w") as f:
            f.write(txt)
        sass[k] = sass_ops(txt)
        mods[k] = cp.RawModule(path=cub)
    mods["jit"] = cp.RawModule(path=ptx)   # the driver's JIT compiler, default options
    res = {"ptxas_version": sh("ptxas --version").strip().splitlines()[-1],
           "cuobjdump": "cuobjdump -sass", "cases": []}
    for cs in CASES:
        nm, ty = cs["name"], cs["ty"]
        dt = {"f16": cp.uint16, "f32": cp.uint32, "f64": cp.uint64}[ty]
        rows = data[nm]["inputs"]
        cands = data[nm]["candidates"]
        din = cp.asarray([x for r in rows for x in r], dtype=dt)
        entry = dict(name=nm, type=ty, note=cs["note"], ptx=kernel_ptx(cs), inputs=rows, candidates=cands,
                     results={}, matches={}, sass={})
        for k, mod in mods.items():
            dout = cp.zeros(2 * len(rows), dtype=dt)
            mod.get_function(nm)((1,), (len(rows),), (din, dout))
            cp.cuda.runtime.deviceSynchronize()
            got = [[int(v) for v in dout[2 * j:2 * j + 2].get()] for j in range(len(rows))]
            entry["results"][k] = got
            entry["matches"][k] = [c for c, v in cands.items() if v == got]
            if k in sass:
                entry["sass"][k] = sass[k].get(nm, [])
        res["cases"].append(entry)
        print(nm, {k: v for k, v in entry["matches"].items()}, entry["sass"])
    with open(os.path.join(out, "gpu_fma_contraction.json"), "w") as f:
        json.dump(res, f)


def finish(raw_path, env_path, out_path):
    raw = json.load(open(raw_path))
    env = open(env_path).read()
    out = {
        "device": re.search(r"\| +0 +(NVIDIA [^|]*?) +(On|Off) +\|", env).group(1),
        "compute_capability": "9.0",
        "driver": re.search(r"Driver Version: (\S+)", env).group(1),
        "ptxas": raw["ptxas_version"],
        "builds": {"default": "ptxas -arch=sm_90 contraction.ptx", "fmad_false": "ptxas -arch=sm_90 --fmad=false "
                   "contraction.ptx", "jit": "CuPy RawModule(path=the PTX file): the driver's JIT compiler, default options"},
        "command": "python3 tools/device/contraction.py gen DIR && python3 tools/device/contraction.py run DIR OUT",
        "layout": "each kernel (u64 in, u64 out): thread i loads a, b, c, d = in[4i..4i+4] and stores o0, o1 at "
                  "out[2i..2i+2] (o1 is +0 unless the body writes it); one block of 64 threads; values are f32 or "
                  "f64 bit patterns as integers",
        "candidates": "exact results of each way the case can be computed, one rounding per operation, from "
                      "fractions (tools/device/contraction.py); the inputs are chosen so that all candidates of a "
                      "case differ on every thread",
        "cases": [],
    }
    for c in raw["cases"]:
        for k in c["sass"]:  # drop constant moves (see sass_ops) from lists made before that filter
            c["sass"][k] = [op for op in c["sass"][k] if op != "HFMA2.MMA"]
        m = c["matches"]
        c["contracted"] = bool(m["default"]) and m["default"] != m["fmad_false"]
        c["jit_equals_default"] = c["results"]["jit"] == c["results"]["default"]
        out["cases"].append(c)
    with open(out_path, "w") as f:
        json.dump(out, f, separators=(",", ":"))
        f.write("\n")


if __name__ == "__main__":
    if sys.argv[1] == "gen":
        gen(sys.argv[2])
    elif sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3])
    else:
        finish(sys.argv[2], sys.argv[3], sys.argv[4])
