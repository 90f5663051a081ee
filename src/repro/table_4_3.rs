//! Thesis 000 Table 4.3: inner-node traversals, triangle-plane intersections
//! and barycentric calculations per ray with the numerical approximation of
//! §4.1.2 and with SIROH, relative to the SAH (seed 000, L1699–1709). Purely
//! functional counts: the native caster performs the stack-based kernel's
//! traversal step for step (tests/raytrace.rs), so it counts them here.

use crate::host::kdtree::{BuildParams, Heuristic, build};
use crate::host::raycast::{Caster, TraceStats, render};
use crate::host::scene::Scene;

/// A published row: scene, then (SAH absolute, numerical %, SIROH %) for
/// traversals, plane intersections and triangle (barycentric) intersections.
pub type Published = (&'static str, [(f64, f64, f64); 3]);

/// Table 4.3 as printed (L1699–1709).
pub const THESIS: [Published; 5] = [
    ("scene6", [(9.68, -24.9, -25.2), (7.59, -15.3, -14.3), (1.10, -7.3, -3.0)]),
    ("sponza", [(30.83, -0.5, -4.3), (7.95, 1.1, 25.5), (3.06, -12.3, -13.7)]),
    ("sibenik", [(40.44, -5.8, -5.6), (5.06, -11.0, -10.5), (2.04, -7.2, -4.0)]),
    ("fairy", [(41.30, 5.5, -1.1), (8.09, -5.7, -3.9), (2.35, -2.8, -6.5)]),
    ("conference", [(23.56, -13.0, -18.6), (12.99, -21.4, -17.4), (2.29, -6.1, 1.4)]),
];

/// Our counts for one scene: per heuristic (SAH, numerical, SIROH) the per-ray
/// traversals, plane intersections and barycentric calculations.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Scene.
    pub scene: String,
    /// Rays traced per heuristic (the same rays; counts differ only by trees).
    pub rays: [u64; 3],
    /// Per heuristic: [traversals, plane intersections, barycentric] per ray.
    pub per_ray: [[f64; 3]; 3],
}

/// Builds the three trees and traces `frames` frames of the flight at `res` × `res`.
pub fn measure(scene: &Scene, frames: u32, res: u32) -> Row {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let mut per_ray = [[0.0; 3]; 3];
    let mut rays = [0; 3];
    for (i, h) in [Heuristic::Sah, Heuristic::Numerical, Heuristic::Siroh].into_iter().enumerate() {
        let tree = build(&tris, BuildParams::thesis(h));
        let caster = Caster::new(scene, &tree);
        let mut st = TraceStats::default();
        for f in 0..frames.min(scene.flight.frames) {
            let mut cam = scene.flight.camera(&scene.camera, f);
            cam.resolution = [res, res];
            st.merge(&render(&caster, &cam, scene.flight.light_offset(f)).1);
        }
        let r = st.rays.max(1) as f64;
        per_ray[i] = [st.inner_nodes as f64 / r, st.plane_tests as f64 / r, st.barycentric_tests as f64 / r];
        rays[i] = st.rays;
    }
    Row { scene: scene.name.clone(), rays, per_ray }
}

/// The table in markdown beside the thesis.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| Scene | Trav. SAH | thesis | 4.1.2 | thesis | SIROH | thesis | Plane SAH | thesis | 4.1.2 | thesis | SIROH | thesis | Tri SAH | thesis | 4.1.2 | thesis | SIROH | thesis |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); 6];
    for r in rows {
        let th = THESIS.iter().find(|t| t.0 == r.scene);
        s.push_str(&format!("| {} |", r.scene));
        for q in 0..3 {
            let sah = r.per_ray[0][q];
            let num = (r.per_ray[1][q] / sah - 1.0) * 100.0;
            let sir = (r.per_ray[2][q] / sah - 1.0) * 100.0;
            cols[2 * q].push(num);
            cols[2 * q + 1].push(sir);
            let t = th.map(|t| t.1[q]);
            s.push_str(&format!(
                " {:.2} | {} | {:+.1}% | {} | {:+.1}% | {} |",
                sah,
                t.map_or("–".into(), |t| format!("{:.2}", t.0)),
                num,
                t.map_or("–".into(), |t| format!("{:+.1}%", t.1)),
                sir,
                t.map_or("–".into(), |t| format!("{:+.1}%", t.2)),
            ));
        }
        s.push('\n');
    }
    let th_cols: Vec<Vec<f64>> =
        (0..6).map(|c| THESIS.iter().map(|t| if c % 2 == 0 { t.1[c / 2].1 } else { t.1[c / 2].2 }).collect()).collect();
    for (label, sd) in [("Average", false), ("Std. Dev.", true)] {
        s.push_str(&format!("| {label} |"));
        for q in 0..3 {
            s.push_str(" | |");
            for c in [2 * q, 2 * q + 1] {
                let (m, d) = super::table_4_4::mean_sd(&cols[c]);
                let (tm, td) = super::table_4_4::mean_sd(&th_cols[c]);
                if sd {
                    s.push_str(&format!(" {d:.1}% | {td:.1}% |"));
                } else {
                    s.push_str(&format!(" {m:+.1}% | {tm:+.1}% |"));
                }
            }
        }
        s.push('\n');
    }
    s
}
