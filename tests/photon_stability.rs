//! Where photon differentials and VKDE fail (issue 13 item 7, the extract's
//! stability cases), on hand-made photons through the native code the
//! kernels repeat operation for operation (`tests/photons.rs`,
//! `tests/vkde.rs`): footprints at grazing incidence are discarded exactly
//! where eq. 5.33 says, re-emission at grazing angles and Russian roulette on
//! dark surfaces give finite kernels within h_max (clamped where the
//! footprint outgrows it), never NaN or infinity.

use warplight::repro::fabianowski2011::photons::{self, Differentials, Photon};
use warplight::repro::fabianowski2011::vkde::{self, Construction, Kernel, Settings};

/// Photons of the settings (Δp = √(4π/n)) and the spread.
const EMITTED: usize = 1 << 17;
const SPREAD: f32 = 20.0;

/// A photon from a point light at the origin straight along +z (p1 = 0, p2 = 0:
/// ∂ω/∂p1 = x, ∂ω/∂p2 = y), propagated to the plane through (0, 0, `d`)
/// tilted by `deg` degrees about the y axis.
fn onto_tilted_plane(d: f32, deg: f32) -> (Differentials, [f32; 3]) {
    let mut p = photons::emit([0.0; 3], 1.0, (1.0, 0.0));
    let th = deg.to_radians();
    let n = [th.sin(), 0.0, -th.cos()];
    photons::propagate(&mut p, d, n);
    (p, n)
}

fn stored(p: &Differentials, n: [f32; 3], flux: [f32; 3]) -> Photon {
    Photon { z: p.z, flux, dz: p.dz, dw: p.dw, normal: n, tri: 0, interaction: 2 }
}

fn len(a: [f32; 3]) -> f32 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn kernel_is_sound(k: &Kernel, s: &Settings) {
    let vals: Vec<f32> =
        [k.z, k.major, k.minor, k.m_prime, k.flux, k.normal, k.lo, k.hi].iter().flatten().copied().collect();
    assert!(finite(&vals) && k.area.is_finite() && k.area > 0.0, "{k:?}");
    for axis in [k.major, k.minor, k.m_prime] {
        assert!(len(axis) <= s.h_max * (1.0 + 1e-5), "axis {axis:?} beyond h_max");
    }
}

#[test]
fn grazing_footprints_are_discarded_where_eq_5_33_says() {
    // on the tilted plane the footprint is d/cos θ by d: the height ratio of eq. 5.33 is cos θ,
    // so an interaction is discarded exactly when cos θ < f = 1/20 (θ > 87.13°)
    let s = Settings::thesis(EMITTED, SPREAD);
    let mut discarded = Vec::new();
    for deg in [0.0f32, 60.0, 80.0, 86.0, 87.0, 87.3, 88.0, 89.0, 89.9] {
        let (p, n) = onto_tilted_plane(2.0, deg);
        let l = [len(p.dz[0]), len(p.dz[1])];
        assert!((l[0] * deg.to_radians().cos() / 2.0 - 1.0).abs() < 1e-3, "{deg}°: stretched by 1/cos θ: {l:?}");
        match vkde::construct(&stored(&p, n, [1.0; 3]), &s) {
            Construction::Discarded => discarded.push(deg),
            Construction::Stored(k) => kernel_is_sound(&k, &s),
        }
    }
    assert_eq!(discarded, [87.3, 88.0, 89.0, 89.9]);
}

#[test]
fn re_emission_at_grazing_angles_and_dark_roulette_stay_finite_and_clamped() {
    let s = Settings::thesis(EMITTED, SPREAD);
    // re-emission with cos p'1 → 0: y1 the largest float the generator gives (1 − 2^-24), so
    // cos p'1 = 2^-12 and both direction differentials are √(1/(4 cos p'1)) = 32 long; the
    // footprint 3 units on, on a wall facing the nearly tangent direction, is finite, within h_max
    let (mut p, _) = onto_tilted_plane(1.0, 0.0);
    let y1 = 1.0 - 1.0 / 16_777_216.0;
    photons::reemit(&mut p, [0.0, 0.0, -1.0], y1, photons::azimuth(0.3));
    let dw: Vec<f32> = p.dw.iter().flatten().copied().collect();
    assert!(finite(&dw), "{dw:?}");
    for d in p.dw {
        assert!((len(d) - 32.0).abs() < 1e-2, "|∂ω'/∂p'| = {}", len(d));
    }
    let h = len([p.w[0], p.w[1], 0.0]);
    let wall = [-p.w[0] / h, -p.w[1] / h, 0.0];
    photons::propagate(&mut p, 3.0, wall);
    let dz: Vec<f32> = p.dz.iter().flatten().copied().collect();
    assert!(finite(&dz), "{dz:?}");
    match vkde::construct(&stored(&p, wall, [1.0; 3]), &s) {
        Construction::Discarded => {}
        Construction::Stored(k) => kernel_is_sound(&k, &s),
    }
    // Russian roulette on a surface of reflectivity ρ = 1e-6: a survivor's differentials grow by
    // ρ^(-1/2) = 1000 and its flux by the tint over ρ; its kernel is clamped, its flux finite
    let (p, n) = onto_tilted_plane(2.0, 30.0);
    let rho = 1e-6f32;
    let g = 1.0 / rho.sqrt();
    let mut q = stored(&p, n, [3.0, 0.0, 0.0]);
    q.dz = [scale(q.dz[0], g), scale(q.dz[1], g)];
    match vkde::construct(&q, &s) {
        Construction::Stored(k) => {
            kernel_is_sound(&k, &s);
            assert!(k.clamped);
            // clamped to h_max on both axes: Φ' = Φ / (h_max² sin α), here α = 90°
            assert!((k.flux[0] - 3.0 / (s.h_max * s.h_max)).abs() < 1e-4, "{:?}", k.flux);
        }
        Construction::Discarded => panic!("a scaled footprint keeps its shape and is not discarded"),
    }
}

/// The extract's §2.8 item 9: the normal derivative needs ‖n'(λ)‖ ≠ 0, and
/// vertex normals that cancel make it vanish. At the midpoint of an edge whose
/// end normals are opposite the interpolated normal is undefined
/// (`normal_at` is `None`) and the mirror falls back to the geometric normal
/// with ∂n/∂p = 0 (fixture); beside it the normal exists and the reflected
/// differentials are finite, however large.
#[test]
fn cancelling_vertex_normals_fall_back_to_the_flat_mirror_and_stay_finite() {
    let t = photons::ShadingTriangle {
        v: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        n: [[0.3, 0.0, 1.0], [-0.3, 0.0, -1.0], [0.0, 0.5, 1.0]],
    };
    let geo = [0.0, 0.0, 1.0];
    let beam = |x: f32| {
        let mut p = Differentials {
            z: [x, 0.0, 1.0],
            w: [0.0, 0.0, -1.0],
            dz: [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0]],
            dw: [[0.0; 3]; 2],
        };
        photons::propagate(&mut p, 1.0, geo);
        p
    };
    // n1 = −n0: n0 + ½(n1 − n0) = 0 at (½, 0, 0)
    assert!(t.normal_at([0.5, 0.0, 0.0]).is_none());
    let mut p = beam(0.5);
    let mut flat = p;
    let at = t.normal_at(p.z);
    photons::reflect_curved(&mut p, at.as_ref(), geo);
    photons::reflect(&mut flat, geo);
    assert_eq!(p, flat);
    // just beside it: defined and finite, but ∂n/∂v = (n'2 − (n'2·n)n)/‖n'(λ)‖
    // grows as ‖n'(λ)‖ → 0, and with it the reflected ∂ω/∂p2
    let mut sizes = Vec::new();
    for x in [0.49, 0.499, 0.4999, 0.51] {
        let s = t.normal_at([x, 0.0, 0.0]).expect("defined off the cancelling point");
        let mut p = beam(x);
        photons::reflect_curved(&mut p, Some(&s), geo);
        let all = [p.w, p.dw[0], p.dw[1], p.dz[0], p.dz[1]];
        assert!(all.iter().flatten().all(|v| v.is_finite()), "x {x}: {p:?}");
        sizes.push(len(p.dw[1]));
    }
    // ‖n'(λ)‖ = |1 − 2u| ‖n0‖ on the edge: ten times closer, ten times the differential
    for w in sizes[..3].windows(2) {
        assert!((w[1] / w[0] - 10.0).abs() < 1.0, "{sizes:?}");
    }
    // past the point the normal flips to −n0 (a back face): the same size as at 0.49
    assert!((sizes[3] / sizes[0] - 1.0).abs() < 0.05, "{sizes:?}");
}
