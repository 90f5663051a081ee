"""Writes tests/fixtures/mathlib/trig64_inputs.bin: N float64 (little endian)
for tools/device/trig64.cu. The float inputs of the math library fixture
(tests/fixtures/mathlib/inputs.bin, x widened), then arguments that take
libdevice's double sin/cos/tan through the long (Payne-Hanek) reduction:
every binary exponent from 2^20 to 2^1023 with random mantissas, integers
near multiples of pi/2, and the largest finite value. Deterministic (LCG)."""
import math, struct, sys

N = 2560
state = 271828
def rnd():
    global state
    state = (state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
    return state >> 11  # 53 random bits

src = sys.argv[1] if len(sys.argv) > 1 else 'tests/fixtures/mathlib/inputs.bin'
out = sys.argv[2] if len(sys.argv) > 2 else 'tests/fixtures/mathlib/trig64_inputs.bin'
with open(src, 'rb') as f:
    xs = list(struct.unpack('<2048f', f.read(2048 * 4)))
special = [1.7976931348623157e308, -1.7976931348623157e308, 5e-324, 2.2250738585072014e-308,
           6381956970095103.0 * 2.0 ** 797, 1e22, 1e300, 2.0 ** 1023, 3.0 * 2.0 ** 1022,
           math.pi, math.pi / 2, 2 * math.pi, 355.0, 103993.0, 6.0 * 2.0 ** 52]
xs += special
k = 0
while len(xs) < N - 64:  # every exponent 2^20 .. 2^1023, random mantissa, both signs
    e = 20 + (k * 37) % 1004  # 37 is prime to 1004: the exponents spread over the range
    m = 1.0 + rnd() / 2.0 ** 53
    xs.append(math.ldexp(m, e) * (1 if k % 2 == 0 else -1))
    k += 1
while len(xs) < N:  # near multiples of pi/2 of large integers
    n = rnd() % (1 << 40)
    xs.append(float(round(n * math.pi / 2)))
assert len(xs) == N
with open(out, 'wb') as f:
    f.write(struct.pack('<%dd' % N, *xs))
