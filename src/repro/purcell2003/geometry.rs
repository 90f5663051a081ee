//! The kernels' ray geometry in Rust: `kernels/purcell2003/photons.cu`'s
//! vector helpers, triangle intersection, normals, cosine-weighted and
//! specular directions, f32 operation for operation (no contraction, the
//! same order of additions, correctly rounded division and square root).
//! The native per-pixel passes ([`super::native`]) and the converged
//! reference ([`super::reference`]) both trace with these.

/// A point or direction (x, y, z).
pub(super) type V3 = [f32; 3];

pub(super) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub(super) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(super) fn mul(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub(super) fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(super) fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
pub(super) fn normalize(v: V3) -> V3 {
    mul(v, 1.0 / dot(v, v).sqrt())
}
pub(super) fn at(t: &[f32], i: usize) -> V3 {
    [t[i], t[i + 1], t[i + 2]]
}

/// The kernels' `intersect`: nearest (t, triangle) with t in (eps, inf).
pub(super) fn intersect(tris: &[f32], o: V3, d: V3, eps: f32) -> Option<(f32, usize)> {
    let mut hit = None;
    let mut ht = 3.0e38f32;
    for (i, t) in tris.chunks_exact(12).enumerate() {
        let (v0, e1, e2) = (at(t, 0), at(t, 3), at(t, 6));
        let p = cross(d, e2);
        let det = dot(e1, p);
        if det.abs() < 1e-12 {
            continue;
        }
        let inv = 1.0 / det;
        let s = sub(o, v0);
        let u = dot(s, p) * inv;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = cross(s, e1);
        let v = dot(d, q) * inv;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let tt = dot(e2, q) * inv;
        if tt > eps && tt < ht {
            ht = tt;
            hit = Some((tt, i));
        }
    }
    hit
}

pub(super) fn tri_normal(tris: &[f32], i: usize) -> V3 {
    normalize(cross(at(tris, 12 * i + 3), at(tris, 12 * i + 6)))
}

/// The kernels' `__cosf` (`cos.approx.f32`) as the emulator executes it:
/// the cosine in f64, rounded once (`src/sim/alu.rs`). The C library's
/// `cosf` (`f32::cos`) differs from it in the last bit for some arguments,
/// which moves a photon by an ulp and can turn its path or its cell.
pub fn cos_approx(x: f32) -> f32 {
    (x as f64).cos() as f32
}

/// The kernels' `__sinf` (`sin.approx.f32`) as the emulator executes it
/// (see [`cos_approx`]).
pub fn sin_approx(x: f32) -> f32 {
    (x as f64).sin() as f32
}

/// The kernels' `cosine_dir`: a cosine-weighted direction about `n`.
pub(super) fn cosine_dir(n: V3, u1: f32, u2: f32) -> V3 {
    let a = if n[0].abs() > 0.5 { [0.0, 1.0, 0.0] } else { [1.0, 0.0, 0.0] };
    let t = normalize(cross(a, n));
    let b = cross(n, t);
    let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
    let z = (1.0 - u1).max(0.0).sqrt();
    add(add(mul(t, r * cos_approx(phi)), mul(b, r * sin_approx(phi))), mul(n, z))
}

pub(super) fn reflect(d: V3, n: V3) -> V3 {
    sub(d, mul(n, 2.0 * dot(d, n)))
}

/// The kernels' `specular` (mirror; glass by Schlick's Fresnel choice with `u`).
pub(super) fn specular(d: V3, n: V3, kind: i32, ior: f32, u: f32) -> V3 {
    if kind == 1 {
        return reflect(d, n);
    }
    let mut c = dot(d, n);
    let mut eta = 1.0 / ior;
    let mut nn = n;
    if c > 0.0 {
        eta = ior;
        nn = mul(n, -1.0);
    } else {
        c = -c;
    }
    let k = 1.0 - eta * eta * (1.0 - c * c);
    let mut r0 = (1.0 - ior) / (1.0 + ior);
    r0 = r0 * r0;
    let m = 1.0 - c;
    let fr = r0 + (1.0 - r0) * m * m * m * m * m;
    if k < 0.0 || u < fr {
        return reflect(d, nn);
    }
    normalize(add(mul(d, eta), mul(nn, eta * c - k.sqrt())))
}
