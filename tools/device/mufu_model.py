import json, zlib, struct, math
T = {n: zlib.decompress(open('tests/fixtures/mufu/%s.i8.zlib' % n, 'rb').read()) for n in ['rcp_1_2', 'rsqrt_1_4', 'sqrt_1_4']}
def d(t, i):
    b = T[t][i]; return b - 256 if b > 127 else b
def f(u): return struct.unpack('<f', struct.pack('<I', u))[0]
def u(x): return struct.unpack('<I', struct.pack('<f', x))[0]  # RN double->float
QNAN = 0x7fffffff
def rcp(x):
    s = x & 0x80000000; e = (x >> 23) & 255
    if e == 255: return QNAN if x & 0x7fffff else s
    if e == 0: return s | 0x7f800000
    mb = 0x3f800000 | (x & 0x7fffff)
    yb = u(1.0 / f(mb)) + d('rcp_1_2', mb - 0x3f800000)
    ye = ((yb >> 23) & 255) - (e - 127)
    return s if ye <= 0 else s | (ye << 23) | (yb & 0x7fffff)
def rsq(x, sq):
    s = x & 0x80000000; e = (x >> 23) & 255
    if e == 0: return s if sq else s | 0x7f800000
    if s: return QNAN
    if e == 255: return QNAN if x & 0x7fffff else (0x7f800000 if sq else 0)
    ue = e - 127; k = ue // 2
    mb = ((ue - 2 * k + 127) << 23) | (x & 0x7fffff)
    md = f(mb)
    yb = u(math.sqrt(md) if sq else 1.0 / math.sqrt(md)) + d('sqrt_1_4' if sq else 'rsqrt_1_4', mb - 0x3f800000)
    return ((((yb >> 23) & 255) + (k if sq else -k)) << 23) | (yb & 0x7fffff)
def fmul(a, b, ftz=False):
    fa, fb = f(a), f(b)
    if ftz:
        if (a >> 23) & 255 == 0: fa = math.copysign(0.0, fa)
        if (b >> 23) & 255 == 0: fb = math.copysign(0.0, fb)
    if math.isnan(fa) or math.isnan(fb): return QNAN
    p = fa * fb
    if math.isnan(p): return QNAN
    try: r = u(p)
    except OverflowError: r = u(math.copysign(math.inf, p))
    if ftz and (r >> 23) & 255 == 0: r &= 0x80000000
    return r
TINY, BIG = 2.0 ** -126, 2.0 ** 126
def model(name, x, a):
    fx = f(x)
    if name == 'rcp.approx.ftz.f32': return rcp(x)
    if name == 'rsqrt.approx.ftz.f32': return rsq(x, False)
    if name == 'sqrt.approx.ftz.f32': return rsq(x, True)
    if name == 'rcp.approx.f32':
        s = 1.0 if abs(fx) >= TINY else 16777216.0
        s = 0.25 if abs(fx) > BIG else s
        return fmul(u(s), rcp(fmul(x, u(s))))
    if name in ('rsqrt.approx.f32', 'sqrt.approx.f32'):
        sq = name.startswith('sqrt'); p = abs(fx) >= TINY or math.isnan(fx)
        y = rsq(x if p else fmul(x, u(16777216.0)), sq)
        return y if p else fmul(y, u(0.000244140625 if sq else 4096.0))
    if name == 'div.approx.ftz.f32': return fmul(a, rcp(x), True)
    if name == 'div.approx.f32':
        p = abs(fx) >= TINY or math.isnan(fx)
        b = x if p else fmul(x, u(16777216.0)); aa = a if p else fmul(a, u(16777216.0))
        return fmul(rcp(b), aa)
    if name == 'div.full.f32':
        big = abs(fx) > BIG; p1 = abs(fx) >= TINY or math.isnan(fx)
        b = fmul(x, u(0.25)) if big else x; b = b if p1 else fmul(b, u(16777216.0))
        aa = fmul(a, u(0.25)) if big else a; aa = aa if p1 else fmul(aa, u(16777216.0))
        return fmul(rcp(b), aa)
    if name == 'div.full.ftz.f32':
        big = abs(fx) > BIG
        b = fmul(x, u(0.25), True) if big else x; aa = fmul(a, u(0.25), True) if big else a
        return fmul(rcp(b), aa, True)
def mix32(x):
    x ^= x >> 16; x = (x * 0x7FEB352D) & 0xFFFFFFFF; x ^= x >> 15; x = (x * 0x846CA68B) & 0xFFFFFFFF; x ^= x >> 16; return x
S = json.load(open('tests/fixtures/gpu_sfu_samples.json'))
for op in S['ops']:
    nm = op['name']
    if not (nm.startswith(('rcp', 'rsqrt', 'sqrt', 'div'))): continue
    wide = 'mix32(b)' in op.get('a_mode', '') and '0x3f800000' not in op.get('a_mode', '')
    bad = 0
    for x, y in zip(op['x'], op['y']):
        a = mix32(x) if wide else (0x3f800000 | (mix32(x) & 0x7fffff))
        m = model(nm, x, a)
        mn = (m & 0x7fffffff) > 0x7f800000
        if m != y and not (mn and y == QNAN):
            bad += 1
            if bad < 4: print('  mismatch', nm, hex(x), hex(a), hex(y), hex(m))
    print(nm, 'wide' if wide else '', len(op['x']), 'mismatches', bad)
