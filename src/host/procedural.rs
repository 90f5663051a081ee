//! Procedural reconstructions of thesis 000's scenes that have no public copy:
//! Scene 6, Passage and Ring. Triangle counts and extents match Table A.1
//! exactly; the layout inside is a documented reconstruction (docs/scenes.md).

use glam::Vec3;

use super::scene::{Material, MaterialKind, Triangle};

/// Geometry and materials of a generated scene.
pub struct Generated {
    /// Triangles.
    pub triangles: Vec<Triangle>,
    /// Materials.
    pub materials: Vec<Material>,
}

/// Appends a quad (a, b, c, d counter-clockwise) split into `nu × nv` cells, 2 triangles each.
fn grid(out: &mut Vec<Triangle>, a: Vec3, b: Vec3, d: Vec3, nu: u32, nv: u32, material: u32) {
    let (eu, ev) = (b - a, d - a);
    for j in 0..nv {
        for i in 0..nu {
            let p = |u: u32, v: u32| a + eu * (u as f32 / nu as f32) + ev * (v as f32 / nv as f32);
            let (p00, p10, p11, p01) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            out.push(Triangle { v: [p00, p10, p11], material });
            out.push(Triangle { v: [p00, p11, p01], material });
        }
    }
}

fn quad(out: &mut Vec<Triangle>, a: Vec3, b: Vec3, d: Vec3, material: u32) {
    grid(out, a, b, d, 1, 1, material);
}

/// Scene 6: a 6 × 6 × 3 m room of 804 triangles. Floor (blue, 10 × 10 cells),
/// ceiling and three walls (light diffuse), one wall a perfect mirror (walls
/// 10 × 5 cells), and a 2 × 2 m shade panel (both faces) under the ceiling
/// that keeps the point light's direct light off the ceiling above it.
pub fn scene6() -> Generated {
    let mats = vec![
        Material::diffuse("floor", [0.1, 0.2, 0.8]),
        Material::diffuse("walls", [0.8, 0.8, 0.75]),
        Material { name: "mirror".into(), kind: MaterialKind::Mirror, color: [0.95, 0.95, 0.95], emission: [0.0; 3] },
        Material::diffuse("shade", [0.7, 0.7, 0.7]),
    ];
    let mut t = Vec::new();
    let v = Vec3::new;
    grid(&mut t, v(0.0, 0.0, 0.0), v(6.0, 0.0, 0.0), v(0.0, 0.0, 6.0), 10, 10, 0); // floor
    grid(&mut t, v(0.0, 3.0, 0.0), v(0.0, 3.0, 6.0), v(6.0, 3.0, 0.0), 10, 10, 1); // ceiling
    grid(&mut t, v(0.0, 0.0, 0.0), v(0.0, 0.0, 6.0), v(0.0, 3.0, 0.0), 10, 5, 2); // x = 0: mirror
    grid(&mut t, v(6.0, 0.0, 6.0), v(6.0, 0.0, 0.0), v(6.0, 3.0, 6.0), 10, 5, 1); // x = 6
    grid(&mut t, v(6.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(6.0, 3.0, 0.0), 10, 5, 1); // z = 0
    grid(&mut t, v(0.0, 0.0, 6.0), v(6.0, 0.0, 6.0), v(0.0, 3.0, 6.0), 10, 5, 1); // z = 6
    quad(&mut t, v(2.0, 2.8, 2.0), v(4.0, 2.8, 2.0), v(2.0, 2.8, 4.0), 3); // shade, top
    quad(&mut t, v(2.0, 2.8, 2.0), v(2.0, 2.8, 4.0), v(4.0, 2.8, 2.0), 3); // shade, bottom
    Generated { triangles: t, materials: mats }
}

/// Passage: 2 × 1 × 1 m, 30 triangles. A red room (x < 1) and a white room
/// (x > 1) divided by a wall with a 0.1 m wide, 0.5 m high opening, and a
/// short corridor (two side walls, 0.2 m long) through it.
pub fn passage() -> Generated {
    let mats = vec![Material::diffuse("red", [0.8, 0.1, 0.1]), Material::diffuse("white", [0.8, 0.8, 0.8])];
    let mut t = Vec::new();
    let v = Vec3::new;
    for (x0, m) in [(0.0f32, 0u32), (1.0, 1)] {
        let x1 = x0 + 1.0;
        quad(&mut t, v(x0, 0.0, 0.0), v(x1, 0.0, 0.0), v(x0, 0.0, 1.0), m); // floor
        quad(&mut t, v(x0, 1.0, 0.0), v(x0, 1.0, 1.0), v(x1, 1.0, 0.0), m); // ceiling
        quad(&mut t, v(x0, 0.0, 0.0), v(x0, 1.0, 0.0), v(x1, 0.0, 0.0), m); // z = 0
        quad(&mut t, v(x0, 0.0, 1.0), v(x1, 0.0, 1.0), v(x0, 1.0, 1.0), m); // z = 1
    }
    quad(&mut t, v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), v(0.0, 1.0, 0.0), 0); // x = 0 end wall
    quad(&mut t, v(2.0, 0.0, 0.0), v(2.0, 1.0, 0.0), v(2.0, 0.0, 1.0), 1); // x = 2 end wall
    // divider at x = 1 with the opening z in [0.45, 0.55], y in [0, 0.5]
    quad(&mut t, v(1.0, 0.0, 0.0), v(1.0, 0.0, 0.45), v(1.0, 1.0, 0.0), 0);
    quad(&mut t, v(1.0, 0.0, 0.55), v(1.0, 0.0, 1.0), v(1.0, 1.0, 0.55), 0);
    quad(&mut t, v(1.0, 0.5, 0.45), v(1.0, 0.5, 0.55), v(1.0, 1.0, 0.45), 0);
    // corridor side walls
    quad(&mut t, v(0.9, 0.0, 0.45), v(1.1, 0.0, 0.45), v(0.9, 0.5, 0.45), 1);
    quad(&mut t, v(0.9, 0.0, 0.55), v(0.9, 0.5, 0.55), v(1.1, 0.0, 0.55), 1);
    Generated { triangles: t, materials: mats }
}

/// Ring: 4 × 4 × 2 m. A 4 × 4 m diffuse ground quad and a mirror ring of
/// radius 1.5 m. `volumetric = false`: 138 triangles, an open band of 68
/// segments standing on the ground, 2 m high. `volumetric = true`: 522
/// triangles, a 5 cm thick ring of 65 segments (inner and outer walls, top and
/// bottom caps) lifted off the ground to y in [1, 2].
pub fn ring(volumetric: bool) -> Generated {
    let mats = vec![
        Material::diffuse("ground", [0.75, 0.75, 0.75]),
        Material { name: "ring".into(), kind: MaterialKind::Mirror, color: [0.9, 0.85, 0.6], emission: [0.0; 3] },
    ];
    let mut t = Vec::new();
    let v = Vec3::new;
    quad(&mut t, v(-2.0, 0.0, -2.0), v(-2.0, 0.0, 2.0), v(2.0, 0.0, -2.0), 0);
    let (segs, y0, y1, r0, r1) = if volumetric { (65, 1.0, 2.0, 1.5, 1.55) } else { (68, 0.0, 2.0, 1.5, 1.5) };
    let at = |i: u32, r: f32, y: f32| {
        let a = i as f32 / segs as f32 * std::f32::consts::TAU;
        v(r * a.cos(), y, r * a.sin())
    };
    for i in 0..segs {
        let j = (i + 1) % segs;
        let wall = |t: &mut Vec<Triangle>, r: f32, flip: bool| {
            let (a, b, c, d) = (at(i, r, y0), at(j, r, y0), at(j, r, y1), at(i, r, y1));
            if flip {
                t.push(Triangle { v: [a, c, b], material: 1 });
                t.push(Triangle { v: [a, d, c], material: 1 });
            } else {
                t.push(Triangle { v: [a, b, c], material: 1 });
                t.push(Triangle { v: [a, c, d], material: 1 });
            }
        };
        wall(&mut t, r0, false);
        if volumetric {
            wall(&mut t, r1, true);
            for y in [y0, y1] {
                let (a, b, c, d) = (at(i, r0, y), at(j, r0, y), at(j, r1, y), at(i, r1, y));
                t.push(Triangle { v: [a, b, c], material: 1 });
                t.push(Triangle { v: [a, c, d], material: 1 });
            }
        }
    }
    Generated { triangles: t, materials: mats }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn extent(g: &Generated) -> [f32; 3] {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for t in &g.triangles {
            for p in t.v {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let e = hi - lo;
        [e.x, e.z, e.y]
    }

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4)
    }

    #[test]
    fn counts_and_extents_match_table_a1() {
        let s6 = scene6();
        assert_eq!(s6.triangles.len(), 804);
        assert!(close(extent(&s6), [6.0, 6.0, 3.0]), "{:?}", extent(&s6));
        let p = passage();
        assert_eq!(p.triangles.len(), 30);
        assert!(close(extent(&p), [2.0, 1.0, 1.0]), "{:?}", extent(&p));
        let r = ring(false);
        assert_eq!(r.triangles.len(), 138);
        assert!(close(extent(&r), [4.0, 4.0, 2.0]), "{:?}", extent(&r));
        let rv = ring(true);
        assert_eq!(rv.triangles.len(), 522);
        assert!(close(extent(&rv), [4.0, 4.0, 2.0]), "{:?}", extent(&rv));
    }

    #[test]
    fn no_degenerate_triangles() {
        for g in [scene6(), passage(), ring(false), ring(true)] {
            assert!(g.triangles.iter().all(|t| t.double_area() > 1e-6));
        }
    }
}
