//! Thesis 000 Table 4.2 (b), qualitatively (seed 000, L1686–1697, L1682):
//! the thesis measured SIROH against the SAH in two third-party ray tracers
//! and found shadow rays slower with SIROH when the light is *outside* the
//! scene — rays starting outside violate SIROH's assumption of ray origins
//! inside the scene — and faster again with the light moved inside. The
//! renderers are not reproducible; the effect is. We trace shadow rays from a
//! point light to each primary hit (rays start at the light, as renderers that
//! trace shadow rays from the light do) over SAH and SIROH trees, with the
//! light inside and outside the scene's bounding box, and count inner-node
//! traversals per shadow ray with the native caster (step for step the
//! stack-based kernel).

use glam::Vec3;

use crate::host::camera::{Camera, Ray};
use crate::host::kdtree::{BuildParams, Heuristic, build};
use crate::host::raycast::{Caster, TraceStats};
use crate::host::scene::Scene;

/// Table 4.2 (b) as printed: setting, SAH fps, SIROH change (%). Fairy Forest
/// frame 160 in the Radius-CUDA ray tracer.
pub const THESIS_B: [(&str, f64, f64); 4] =
    [("Unshaded", 43.5, 2.4), ("Unshadowed", 43.3, 2.5), ("Light outside", 15.1, -3.8), ("Light inside", 14.0, 1.7)];

/// Where the two lights are, as fractions of the scene's extent from its centre.
pub const LIGHT_INSIDE: [f32; 3] = [0.1, 0.2, 0.05];
/// Above the scene, outside its bounding box.
pub const LIGHT_OUTSIDE: [f32; 3] = [0.3, 1.5, 0.2];

/// One scene: inner-node traversals per shadow ray, `[SAH, SIROH]` × `[inside, outside]`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    /// Scene.
    pub scene: String,
    /// Shadow rays traced per light.
    pub rays: u64,
    /// Traversals per shadow ray: `[heuristic][light]`.
    pub per_ray: [[f64; 2]; 2],
}

impl Row {
    /// SIROH's change against the SAH in traversals per shadow ray (%), per light
    /// (a positive change is more work: SIROH loses).
    pub fn siroh_change(&self) -> [f64; 2] {
        [0, 1].map(|k| (self.per_ray[1][k] / self.per_ray[0][k] - 1.0) * 100.0)
    }
}

fn light(scene: &Scene, frac: [f32; 3]) -> Vec3 {
    let (lo, hi) = scene.bounds();
    (lo + hi) * 0.5 + (hi - lo) * Vec3::from(frac)
}

/// Traversals per shadow ray from `light` to each primary hit of `cam`.
fn shadow_traversals(caster: &Caster, cam: &Camera, light: Vec3) -> (u64, f64) {
    let (mut prim, mut st) = (TraceStats::default(), TraceStats::default());
    for y in 0..cam.resolution[1] {
        for x in 0..cam.resolution[0] {
            let r = cam.ray(x, y);
            let Some(h) = caster.intersect(&r, caster.eps(), f32::INFINITY, false, &mut prim) else { continue };
            let to = r.origin + r.dir * h.t - light;
            let dist = to.length();
            let sr = Ray { origin: light, dir: to / dist }; // `intersect` counts the ray
            caster.intersect(&sr, caster.eps(), dist - caster.eps(), true, &mut st);
        }
    }
    (st.rays, st.inner_nodes as f64 / st.rays.max(1) as f64)
}

/// Builds SAH and SIROH trees and traces the shadow rays of frame 0 of the
/// flight at `res` × `res` for both lights.
pub fn measure(scene: &Scene, res: u32) -> Row {
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let mut cam = scene.flight.camera(&scene.camera, 0);
    cam.resolution = [res, res];
    let mut per_ray = [[0.0; 2]; 2];
    let mut rays = 0;
    for (i, h) in [Heuristic::Sah, Heuristic::Siroh].into_iter().enumerate() {
        let tree = build(&tris, BuildParams::thesis(h));
        let caster = Caster::new(scene, &tree);
        for (k, frac) in [LIGHT_INSIDE, LIGHT_OUTSIDE].into_iter().enumerate() {
            let (n, t) = shadow_traversals(&caster, &cam, light(scene, frac));
            per_ray[i][k] = t;
            rays = n;
        }
    }
    Row { scene: scene.name.clone(), rays, per_ray }
}

/// The table in markdown, with the thesis' Table 4.2 (b) for comparison.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| Scene | shadow rays | SAH, light inside | SIROH | SAH, light outside | SIROH |\n|---|---|---|---|---|---|\n",
    );
    let mut ch: [Vec<f64>; 2] = Default::default();
    for r in rows {
        let c = r.siroh_change();
        ch[0].push(c[0]);
        ch[1].push(c[1]);
        s.push_str(&format!(
            "| {} | {} | {:.2} | {:+.1}% | {:.2} | {:+.1}% |\n",
            r.scene, r.rays, r.per_ray[0][0], c[0], r.per_ray[0][1], c[1]
        ));
    }
    let (mi, mo) = (super::table_4_4::mean_sd(&ch[0]).0, super::table_4_4::mean_sd(&ch[1]).0);
    s.push_str(&format!("| Average | | | {mi:+.1}% | | {mo:+.1}% |\n"));
    s.push_str("\nTraversals per shadow ray (fewer is faster). The thesis (Radius-CUDA, Fairy Forest, frame rates, SIROH vs SAH): ");
    let th: Vec<String> = THESIS_B.iter().map(|t| format!("{} {:+.1}%", t.0.to_lowercase(), t.2)).collect();
    s.push_str(&th.join(", "));
    s.push_str(" - a frame-rate gain is a traversal reduction.\n");
    s
}
