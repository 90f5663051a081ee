//! Thesis 000 §5.1: photon tracing with photon differentials, on the emulator
//! (`kernels/fabianowski2011/photons.cu`) and natively ([`reference`]).
//!
//! An isotropic point light emits `n` photons of equal flux; each carries its
//! position, direction and four differentials, pre-scaled so that one global
//! Δp = √(4π/n) applies (eqs. 5.9–5.11). Surface hits propagate the
//! differentials (eqs. 3.7–3.9, [`propagate`]); mirrors reflect them (eqs.
//! 3.10–3.11: about the interpolated vertex normal with ∂n/∂p from eqs.
//! 5.12–5.21 where the scene has vertex normals, [`reflect_curved`],
//! otherwise flat with ∂n/∂p = 0, [`reflect`]); diffuse surfaces
//! absorb and re-emit with cosine sampling and the virtual offset t_v (eqs.
//! 5.22–5.29); Russian roulette scales survivors' differentials by ρ^(−1/2)
//! (§5.1.4). The 2nd and 3rd surface interactions on diffuse surfaces are
//! stored ([`Photon`]). Random numbers are counter based ([`rng`]), so the
//! native reference replays each photon with the kernel's float operations in
//! the kernel's order, and both agree bit for bit (`tests/photons.rs`).
//! Fixtures the thesis leaves open are listed in `docs/photon-mapping.md`.

use std::f32::consts::{FRAC_1_SQRT_2, FRAC_PI_2, FRAC_PI_4, PI};

use glam::Vec3;

use crate::host::camera::Ray;
use crate::host::kdtree::KdTree;
use crate::host::kdtree::layout::{layout, wald};
use crate::host::raycast::{Caster, EPS_REL, TraceStats};
use crate::host::scene::{Light, MaterialKind, Scene};
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, LaunchConfig, LaunchStats, Module, SimError};

/// The kernel's PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/fabianowski2011/photons.ptx");
/// The kernel's entry point.
pub const KERNEL: &str = "trace_photons";
/// Floats per stored slot in the kernel's output (two slots per photon).
pub const SLOT: usize = 24;
/// Threads per CTA of the launch.
pub const THREADS: u32 = 256;
/// At most this many CTAs (one per GTX 280 SM); threads loop over photons.
pub const MAX_CTAS: u32 = 30;
/// The last surface interaction traced (seed 000 L2468: "until their third surface interaction").
pub const LAST_INTERACTION: u32 = 3;

/// Why photons could not be traced.
#[derive(Debug, thiserror::Error)]
pub enum PhotonError {
    /// The scene has no point light to emit from.
    #[error("scene `{0}` has no point light: photon emission needs one (seed 000 §5.1.1)")]
    NoPointLight(String),
    /// More photons than the kernel's 32-bit index addresses.
    #[error("{0} photons: at most {max} can be traced in one launch", max = i32::MAX)]
    TooMany(usize),
    /// The emulator failed.
    #[error(transparent)]
    Sim(#[from] SimError),
}

/// A stored photon interaction (a surface hit on a diffuse surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Photon {
    /// Position z.
    pub z: [f32; 3],
    /// Flux arriving (RGB, W), before Russian roulette at this hit.
    pub flux: [f32; 3],
    /// Position differentials ∂z/∂p1, ∂z/∂p2 after propagation to the hit.
    pub dz: [[f32; 3]; 2],
    /// Direction differentials ∂ω/∂p1, ∂ω/∂p2 of the incoming photon.
    pub dw: [[f32; 3]; 2],
    /// Geometric normal, facing the incoming photon.
    pub normal: [f32; 3],
    /// Triangle hit.
    pub tri: u32,
    /// Surface interaction (2 or 3).
    pub interaction: u32,
}

impl Photon {
    /// The fields' bits, for exact comparison.
    pub fn bits(&self) -> Vec<u32> {
        let mut v: Vec<u32> = Vec::with_capacity(SLOT);
        for a in [self.z, self.flux, self.dz[0], self.dz[1], self.dw[0], self.dw[1], self.normal] {
            v.extend(a.iter().map(|x| x.to_bits()));
        }
        v.push(self.tri);
        v.push(self.interaction);
        v
    }

    /// The footprint's spanning vectors Δp·∂z/∂p_i (eq. 3.4) for `n` photons emitted (Δp = √(4π/n), eq. 5.11).
    pub fn footprint(&self, n: usize) -> [Vec3; 2] {
        let dp = delta_p(n);
        [Vec3::from(self.dz[0]) * dp, Vec3::from(self.dz[1]) * dp]
    }
}

/// The global parameter distance Δp = √(4π/n) (eq. 5.11).
pub fn delta_p(n: usize) -> f32 {
    (4.0 * PI / n as f32).sqrt()
}

/// The counter-based generator: a uniform float in [0, 1) with 24 random bits for
/// photon `i`, dimension `d` (two rounds of a 32-bit integer hash). Dimensions:
/// 0, 1 emission; at interaction k, 4k−2 roulette, 4k−1 and 4k re-emission.
pub fn rng(i: u32, d: u32) -> f32 {
    let mut h = i.wrapping_mul(0x9e37_79b9) ^ d.wrapping_add(1).wrapping_mul(0x85eb_ca6b);
    for _ in 0..2 {
        h ^= h >> 16;
        h = h.wrapping_mul(0x7feb_352d);
        h ^= h >> 15;
        h = h.wrapping_mul(0x846c_a68b);
        h ^= h >> 16;
    }
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// (cos, sin) of the azimuth 2πy for y in [0, 1), as the kernel computes them:
/// a quarter turn q = ⌊4y⌋, the rest in [−π/4, π/4) by Taylor polynomials
/// (error below 1e-7), rotated by π/4 and q quarter turns.
pub fn azimuth(y: f32) -> (f32, f32) {
    let f4 = y * 4.0;
    let q = f4 as i32;
    let x = (f4 - q as f32) * FRAC_PI_2 - FRAC_PI_4;
    let x2 = x * x;
    let sx = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
    let cx = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0))));
    let h = FRAC_1_SQRT_2;
    let (cr, sr) = ((cx - sx) * h, (sx + cx) * h);
    match q {
        0 => (cr, sr),
        1 => (-sr, cr),
        2 => (-cr, -sr),
        _ => (sr, -cr),
    }
}

/// a · b, summed left to right (as the kernels do).
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// a + b.
pub(crate) fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// a · s.
pub(crate) fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// a × b.
pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
/// ‖a‖ = √(a · a).
pub(crate) fn len(a: [f32; 3]) -> f32 {
    dot(a, a).sqrt()
}

/// A photon in flight: position, direction and the four differentials.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Differentials {
    /// Position z.
    pub z: [f32; 3],
    /// Direction ω.
    pub w: [f32; 3],
    /// ∂z/∂p1, ∂z/∂p2.
    pub dz: [[f32; 3]; 2],
    /// ∂ω/∂p1, ∂ω/∂p2.
    pub dw: [[f32; 3]; 2],
}

/// The photon emitted by an isotropic point light at `z` for parameters
/// cos p1 = `cp1`, (cos p2, sin p2) = `c2` (eqs. 5.1, 5.9, 5.10 with α = π, R = I).
pub fn emit(z: [f32; 3], cp1: f32, c2: (f32, f32)) -> Differentials {
    let sp1 = (1.0 - cp1 * cp1).max(0.0).sqrt();
    let (cp2, sp2) = c2;
    Differentials {
        z,
        w: [cp2 * sp1, sp2 * sp1, cp1],
        dz: [[0.0; 3]; 2],
        dw: [[cp2 * cp1, sp2 * cp1, -sp1], [-sp2, cp2, 0.0]],
    }
}

/// Propagates `p` by `t` to a surface with unit normal `n` (eqs. 3.7–3.9):
/// ∂z'/∂p = ∂z/∂p + t ∂ω/∂p + (∂t/∂p) ω with ∂t/∂p = −((∂z/∂p + t ∂ω/∂p)·n)/(ω·n).
pub fn propagate(p: &mut Differentials, t: f32, n: [f32; 3]) {
    let wn = dot(p.w, n);
    for i in 0..2 {
        let a = add(p.dz[i], scale(p.dw[i], t));
        let dt = -dot(a, n) / wn;
        p.dz[i] = add(a, scale(p.w, dt));
    }
    p.z = [p.z[0] + p.w[0] * t, p.z[1] + p.w[1] * t, p.z[2] + p.w[2] * t];
}

/// Mirror reflection about unit normal `n` (eqs. 3.10–3.11 with ∂n/∂p = 0):
/// ω' = ω − 2(ω·n)n, ∂z'/∂p = ∂z/∂p, ∂ω'/∂p = ∂ω/∂p − 2(∂ω/∂p·n)n.
pub fn reflect(p: &mut Differentials, n: [f32; 3]) {
    let s2 = 2.0 * dot(p.w, n);
    p.w = [p.w[0] - s2 * n[0], p.w[1] - s2 * n[1], p.w[2] - s2 * n[2]];
    for i in 0..2 {
        let s = 2.0 * dot(p.dw[i], n);
        p.dw[i] = [p.dw[i][0] - s * n[0], p.dw[i][1] - s * n[1], p.dw[i][2] - s * n[2]];
    }
}

/// A triangle with vertex normals, as §5.1.2 interpolates them (L2247):
/// n(λ) = normalize(n0 + u n'1 + v n'2) with n'i = ni − n0 and λ = (u, v)
/// the weights of v1 and v2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingTriangle {
    /// Vertices v0, v1, v2.
    pub v: [[f32; 3]; 3],
    /// Vertex normals n0, n1, n2 (unit or not: the interpolation normalises).
    pub n: [[f32; 3]; 3],
}

/// The interpolated normal at a point and its derivative along the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingNormal {
    /// n(λ), unit length.
    pub n: [f32; 3],
    /// ∂n/∂λ (eq. 5.13): ∂n/∂u, ∂n/∂v.
    pub dn_dl: [[f32; 3]; 2],
    /// ∂λ/∂z (eq. 5.21): the rows ∂u/∂z, ∂v/∂z.
    pub dl_dz: [[f32; 3]; 2],
}

impl ShadingNormal {
    /// ∂n/∂p = (∂n/∂λ)(∂λ/∂z)(∂z/∂p) (eq. 5.12) for the position differential `dz`.
    pub fn dn_dp(&self, dz: [f32; 3]) -> [f32; 3] {
        let (du, dv) = (dot(self.dl_dz[0], dz), dot(self.dl_dz[1], dz));
        add(scale(self.dn_dl[0], du), scale(self.dn_dl[1], dv))
    }
}

impl ShadingTriangle {
    /// The interpolated normal at `z` (on the triangle's plane) with ∂n/∂λ and
    /// ∂λ/∂z from Wald's projection (eqs. 5.13–5.21): k = argmax |n_geo,k|,
    /// (i, j) = (k + 1, k + 2) mod 3, e1 = v1 − v0, e2 = v2 − v0,
    /// e'1 = (−e1j, e1i, det(e1ji, v0ji)) / det(e1ij, e2ij),
    /// e'2 = (e2j, −e2i, det(e2ij, v0ij)) / det(e1ij, e2ij),
    /// (u, v) = (e'2xy · z_ij + e'2z, e'1xy · z_ij + e'1z); the kernels' Wald
    /// form ([`wald`]) and [`shading_normal`].
    /// `None` where the derivative is undefined: a degenerate triangle, or
    /// vertex normals that cancel, ‖n'(λ)‖ = 0 (the extract's §2.8 item 9).
    pub fn normal_at(&self, z: [f32; 3]) -> Option<ShadingNormal> {
        let (k, _, e1p, e2p) = wald(&self.v.map(Vec3::from));
        let (i, j) = ((k as usize + 1) % 3, (k as usize + 2) % 3);
        let u = e2p[0] * z[i] + e2p[1] * z[j] + e2p[2];
        let v = e1p[0] * z[i] + e1p[1] * z[j] + e1p[2];
        shading_normal(k, e1p, e2p, (u, v), normal_deltas(self.n))
    }
}

/// What the photon kernel stores per triangle for its interpolated normal
/// (L2247): n0, n'1 = n1 − n0, n'2 = n2 − n0.
pub fn normal_deltas(n: [[f32; 3]; 3]) -> [[f32; 3]; 3] {
    let [n0, n1, n2] = n;
    [n0, add(n1, scale(n0, -1.0)), add(n2, scale(n0, -1.0))]
}

/// The interpolated normal n(λ) = normalize(n0 + u n'1 + v n'2) at the
/// barycentric weights `uv` = (u, v) of vertices 1 and 2 (eq. 5.20, as
/// Wald's test computes them at the hit), with ∂n/∂λ (eq. 5.13) and ∂λ/∂z
/// (eq. 5.21: the rows e'2 and e'1 of the Wald form placed at the axes
/// i, j = k + 1, k + 2, zero at k), from `nd` = [`normal_deltas`]; the
/// photon kernel's float operations in its order. `None` where ‖n'(λ)‖ is 0
/// or not finite (vertex normals that cancel, or a triangle without any:
/// all zero) or a derivative is not finite.
pub fn shading_normal(
    k: u32,
    e1p: [f32; 3],
    e2p: [f32; 3],
    uv: (f32, f32),
    nd: [[f32; 3]; 3],
) -> Option<ShadingNormal> {
    let [n0, d1, d2] = nd;
    let raw = add(n0, add(scale(d1, uv.0), scale(d2, uv.1)));
    let l = len(raw);
    if !(l > 0.0 && l.is_finite()) {
        return None;
    }
    let il = 1.0 / l;
    let n = scale(raw, il);
    let col = |d: [f32; 3]| scale(add(d, scale(n, -dot(d, n))), il);
    let (i, j) = ((k as usize + 1) % 3, (k as usize + 2) % 3);
    let row = |a: f32, b: f32| {
        let mut r = [0.0; 3];
        r[i] = a;
        r[j] = b;
        r
    };
    let out = ShadingNormal { n, dn_dl: [col(d1), col(d2)], dl_dz: [row(e2p[0], e2p[1]), row(e1p[0], e1p[1])] };
    let finite = |a: &[[f32; 3]; 2]| a.iter().flatten().all(|x| x.is_finite());
    (finite(&out.dn_dl) && finite(&out.dl_dz)).then_some(out)
}

/// Mirror reflection about a curved surface (eqs. 3.10–3.11 with the
/// extract's erratum): ω' = ω − 2(ω·n)n, ∂z'/∂p = ∂z/∂p and
/// ∂ω'/∂p = ∂ω/∂p − 2[(ω·n) ∂n/∂p + (∂ω/∂p·n + ω·∂n/∂p) n], with
/// ∂n/∂p from `s` (eq. 5.12) for each of the photon's position differentials.
/// Where `s` is `None` (cancelling vertex normals, fixture: the geometric
/// normal `flat` with ∂n/∂p = 0) it is [`reflect`] about `flat`.
pub fn reflect_curved(p: &mut Differentials, s: Option<&ShadingNormal>, flat: [f32; 3]) {
    let Some(s) = s else { return reflect(p, flat) };
    let n = s.n;
    let wn = dot(p.w, n);
    for i in 0..2 {
        let dn = s.dn_dp(p.dz[i]);
        let d = dot(p.dw[i], n) + dot(p.w, dn);
        p.dw[i] = add(p.dw[i], scale(add(scale(dn, wn), scale(n, d)), -2.0));
    }
    p.w = add(p.w, scale(n, -2.0 * wn));
}

/// Diffuse absorption and re-emission about unit normal `n` (eqs. 5.22–5.29):
/// cos p'1 = √(1−y1), azimuth (cos, sin) `c2`; the virtual offset
/// t_v = √(2‖∂z/∂p1 × ∂z/∂p2‖) from the incoming position differentials, then
/// ∂ω'/∂p'1 = √(1/(4 cos p'1)) R(cos p'2 cos p'1, sin p'2 cos p'1, −sin p'1),
/// ∂ω'/∂p'2 = √(1/(4 cos p'1)) R(−sin p'2, cos p'2, 0), ∂z'/∂p'i = t_v ∂ω'/∂p'i.
/// The frame R: tangent from the x axis (the y axis when |n_x| ≥ 1/2), bitangent n × tangent.
pub fn reemit(p: &mut Differentials, n: [f32; 3], y1: f32, c2: (f32, f32)) {
    let tv = (2.0 * len(cross(p.dz[0], p.dz[1]))).sqrt();
    let (c1, s1) = ((1.0 - y1).sqrt(), y1.sqrt());
    let (c2, s2) = c2;
    let ax = if n[0].abs() < 0.5 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let tg = add(ax, scale(n, -dot(ax, n)));
    let tg = scale(tg, 1.0 / len(tg));
    let bt = cross(n, tg);
    let sc = (1.0 / (4.0 * c1)).sqrt();
    p.w = add(add(scale(tg, c2 * s1), scale(bt, s2 * s1)), scale(n, c1));
    p.dw[0] = add(add(scale(tg, c2 * c1 * sc), scale(bt, s2 * c1 * sc)), scale(n, -s1 * sc));
    p.dw[1] = add(scale(tg, -s2 * sc), scale(bt, c2 * sc));
    p.dz = [scale(p.dw[0], tv), scale(p.dw[1], tv)];
}

/// What the photon tracer needs of a scene: the first point light and each photon's flux.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Emission {
    /// The light's position.
    pub position: [f32; 3],
    /// Flux per photon: Φ/n with Φ = 4π I for radiant intensity I (an isotropic point light).
    pub flux: [f32; 3],
    /// Photons emitted.
    pub n: usize,
}

impl Emission {
    /// The same emission from the light moved by `offset` (a flight's animated light).
    pub fn moved(&self, offset: [f32; 3]) -> Emission {
        Emission { position: std::array::from_fn(|c| self.position[c] + offset[c]), ..*self }
    }

    /// Emission of `n` photons from `scene`'s first point light.
    pub fn of(scene: &Scene, n: usize) -> Result<Emission, PhotonError> {
        if n > i32::MAX as usize {
            return Err(PhotonError::TooMany(n));
        }
        let (position, intensity) = scene
            .lights
            .iter()
            .find_map(|l| match l {
                Light::Point { position, intensity } => Some((*position, *intensity)),
                _ => None,
            })
            .ok_or_else(|| PhotonError::NoPointLight(scene.name.clone()))?;
        let flux = intensity.map(|i| 4.0 * PI * i / n as f32);
        Ok(Emission { position, flux, n })
    }
}

/// Material kind as the kernel encodes it: 0 diffuse, 1 mirror (glass too), 2 emitter.
fn kind_code(k: MaterialKind) -> f32 {
    match k {
        MaterialKind::Diffuse => 0.0,
        MaterialKind::Mirror | MaterialKind::Glass { .. } => 1.0,
        MaterialKind::Emitter => 2.0,
    }
}

/// Traces photon `i` natively through `caster`: the kernel's path, operation for operation.
pub fn trace_one(caster: &Caster, e: &Emission, i: u32) -> [Option<Photon>; 2] {
    let mut out = [None, None];
    let cp1 = rng(i, 0) * 2.0 - 1.0;
    let mut p = emit(e.position, cp1, azimuth(rng(i, 1)));
    let mut flux = e.flux;
    let mut st = TraceStats::default();
    for k in 1..=LAST_INTERACTION {
        let ray = Ray { origin: Vec3::from(p.z), dir: Vec3::from(p.w) };
        let Some(h) = caster.intersect(&ray, caster.eps(), f32::INFINITY, false, &mut st) else { break };
        let n = caster.normal(h.tri, ray.dir).to_array();
        propagate(&mut p, h.t, n);
        let m = &caster.scene.materials[caster.scene.triangles[h.tri as usize].material as usize];
        let kind = kind_code(m.kind);
        if kind == 2.0 {
            break;
        }
        let diffuse = kind == 0.0;
        if diffuse && k >= 2 {
            out[(k - 2) as usize] =
                Some(Photon { z: p.z, flux, dz: p.dz, dw: p.dw, normal: n, tri: h.tri, interaction: k });
        }
        if k == LAST_INTERACTION {
            break;
        }
        let col = m.color;
        let rho = (col[0] + col[1] + col[2]) / 3.0;
        // survive only if y < rho (as the kernel's `!(y < rho)` test; a NaN rho terminates)
        if rng(i, 4 * k - 2).partial_cmp(&rho) != Some(std::cmp::Ordering::Less) {
            break;
        }
        flux = [flux[0] * (col[0] / rho), flux[1] * (col[1] / rho), flux[2] * (col[2] / rho)];
        let g = 1.0 / rho.sqrt();
        p.dz = [scale(p.dz[0], g), scale(p.dz[1], g)];
        p.dw = [scale(p.dw[0], g), scale(p.dw[1], g)];
        if diffuse {
            reemit(&mut p, n, rng(i, 4 * k - 1), azimuth(rng(i, 4 * k)));
        } else {
            reflect_curved(&mut p, mirror_normal(caster.scene, &h).as_ref(), n);
        }
    }
    out
}

/// The interpolated normal a mirror reflects about at hit `h` (eqs.
/// 5.12–5.21), from the scene's vertex normals and the hit's barycentric
/// weights; `None` (the flat mirror) where the scene or the triangle has no
/// vertex normals, or they cancel there.
fn mirror_normal(scene: &Scene, h: &crate::host::raycast::Hit) -> Option<ShadingNormal> {
    if scene.normals.is_empty() {
        return None;
    }
    let (k, _, e1p, e2p) = wald(&scene.triangles[h.tri as usize].v);
    shading_normal(k, e1p, e2p, (h.u, h.v), normal_deltas(scene.vertex_normals(h.tri)))
}

/// The kernel's table of [`normal_deltas`], nine floats per triangle, and
/// whether the scene has vertex normals (one zero float when it has none).
pub fn normal_table(scene: &Scene) -> (Vec<f32>, bool) {
    if scene.normals.is_empty() {
        return (vec![0.0], false);
    }
    let table = (0..scene.triangles.len() as u32)
        .flat_map(|t| normal_deltas(scene.vertex_normals(t)).into_iter().flatten())
        .collect();
    (table, true)
}

/// The native reference: every photon of `e` traced through `scene`'s `tree`.
pub fn reference(scene: &Scene, tree: &KdTree, e: &Emission) -> Vec<[Option<Photon>; 2]> {
    let caster = Caster::new(scene, tree);
    (0..e.n as u32).map(|i| trace_one(&caster, e, i)).collect()
}

/// What the emulated kernel produced.
#[derive(Debug, Clone)]
pub struct KernelPhotons {
    /// Per photon, its stored 2nd and 3rd interactions.
    pub photons: Vec<[Option<Photon>; 2]>,
    /// The emulator's counters.
    pub launch: LaunchStats,
}

fn slot(s: &[f32]) -> Option<Photon> {
    if s[23] != 1.0 {
        return None;
    }
    let v = |a: usize| [s[a], s[a + 1], s[a + 2]];
    Some(Photon {
        z: v(0),
        flux: v(3),
        dz: [v(6), v(9)],
        dw: [v(12), v(15)],
        normal: v(18),
        tri: s[21].to_bits(),
        interaction: s[22].to_bits(),
    })
}

/// Loads the photon kernel's PTX on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/fabianowski2011/photons.ptx")
}

/// Runs the photon kernel for `e` over `scene`'s `tree` (laid out as chapter 4's kernels read it).
pub fn trace_kernel(
    dev: &mut Device,
    module: &Module,
    scene: &Scene,
    tree: &KdTree,
    e: &Emission,
) -> Result<KernelPhotons, PhotonError> {
    trace_kernel_observed(dev, module, scene, tree, e, None)
}

/// As [`trace_kernel`], the launch observed by `model` when given (a memory model for the timing model).
pub fn trace_kernel_observed(
    dev: &mut Device,
    module: &Module,
    scene: &Scene,
    tree: &KdTree,
    e: &Emission,
    model: Option<&crate::model::Model>,
) -> Result<KernelPhotons, PhotonError> {
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let lay = layout(tree, &tris, 0);
    let eps = tree.bounds.size().length().max(1e-3) * EPS_REL;
    let (lo, hi) = (tree.bounds.lo, tree.bounds.hi);
    let mut params = to_bytes(&[
        e.position[0],
        e.position[1],
        e.position[2],
        e.flux[0],
        e.flux[1],
        e.flux[2],
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        eps,
    ]);
    params.extend_from_slice(&(e.n as i32).to_le_bytes());
    let (normals, has_normals) = normal_table(scene);
    params.extend_from_slice(&(has_normals as i32).to_le_bytes());
    let mats = crate::host::rt_kernels::material_table(scene);
    let tri_mat: Vec<u32> = scene.triangles.iter().map(|t| t.material).collect();
    let up = crate::host::rt_kernels::upload;
    let pp = up(dev, &params, "params")?;
    let nodes = up(dev, &lay.nodes, "nodes")?;
    let refs = up(dev, &lay.tri_refs, "tri_refs")?;
    let tb = up(dev, &lay.triangles, "triangles")?;
    let tm = up(dev, &to_bytes(&tri_mat), "tri_mat")?;
    let mb = up(dev, &to_bytes(&mats), "materials")?;
    let nb = up(dev, &to_bytes(&normals), "normals")?;
    let out = dev.alloc_zeroed::<f32>(2 * SLOT * e.n.max(1));
    let ctas = (e.n.div_ceil(THREADS as usize) as u32).clamp(1, MAX_CTAS);
    let args: Vec<Arg> = [pp, nodes, refs, tb, tm, mb, nb, out].into_iter().map(Arg::Ptr).collect();
    let observer = model.map(|m| m as &dyn crate::sim::ObserverFactory);
    let launch = dev.launch_observed(module, KERNEL, LaunchConfig::linear(ctas, THREADS), &args, observer)?;
    let raw = dev.read::<f32>(out, 2 * SLOT * e.n);
    let photons = raw.chunks_exact(2 * SLOT).map(|p| [slot(&p[..SLOT]), slot(&p[SLOT..])]).collect();
    Ok(KernelPhotons { photons, launch })
}
