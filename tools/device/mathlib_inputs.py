"""Writes tests/fixtures/mathlib/inputs.bin: x then y, N float32 each (little
endian), for tools/device/mathlib.cu. Special values first, then a
log-spaced sweep over every magnitude of both signs, then uniform samples in
the ranges students use (|x| < 10, angles up to 1000). Deterministic (LCG)."""
import math, struct, sys

N = 2048
state = 12345
def rnd():
    global state
    state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
    return (state >> 11) / float(1 << 53)

def f32(v):
    return struct.unpack('<f', struct.pack('<f', v))[0]

special = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 3.0, 10.0, 100.0, math.inf, -math.inf, math.nan,
           1.17549435e-38, -1.17549435e-38, 1e-45, 1e-40, -1e-40, 3.4028235e38, -3.4028235e38,
           math.pi, -math.pi, math.pi / 2, math.pi / 4, 2 * math.pi, 88.72, 88.73, -87.33, -103.98, -104.0,
           1e-7, 1e-4, 0.999999, 1.000001, 105615.0, 105616.0, 1e6, 1e10, 1e30, 16777216.0, 0.1, -0.1]
xs = [f32(v) for v in special]
ys = [f32(v) for v in reversed(special)]
while len(xs) < N // 2:  # every magnitude 2^-40 .. 2^40, both signs
    m = 2.0 ** (rnd() * 80 - 40) * (1 if rnd() < 0.5 else -1)
    xs.append(f32(m))
    ys.append(f32(2.0 ** (rnd() * 12 - 6) * (1 if rnd() < 0.8 else -1)))
while len(xs) < 3 * N // 4:  # |x| < 10
    xs.append(f32(rnd() * 20 - 10))
    ys.append(f32(rnd() * 8 - 4))
while len(xs) < N:  # angles and exponents up to 1000
    xs.append(f32(rnd() * 2000 - 1000))
    ys.append(f32(rnd() * 2))
out = sys.argv[1] if len(sys.argv) > 1 else 'tests/fixtures/mathlib/inputs.bin'
with open(out, 'wb') as f:
    f.write(struct.pack('<%df' % N, *xs))
    f.write(struct.pack('<%df' % N, *ys))
