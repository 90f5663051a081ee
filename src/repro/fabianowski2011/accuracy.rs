//! Accuracy of chapter 5's density estimators against a converged reference
//! (issue 13, item 6). The thesis compares its images by eye (§5.2.3, Fig.
//! 5.3); here VKDE with the uniform kernel, VKDE with the Epanechnikov kernel
//! and the kNN baseline are measured against one reference per scene, at a
//! ladder of photon counts ([`LADDER`], fractions of Table 5.1's emissions).
//!
//! - **Renders**: the photon, construction and estimation kernels on the
//!   emulator (`photons.cu`, `vkde.cu`, `knn.cu`; bit for bit the native
//!   references, `tests/vkde.rs`), the scene's spread s and kNN's k_kNN of
//!   Table 5.1 at every count (the thesis' settings: s and k do not change
//!   with the photons), the indirect estimate at the primary and reflection
//!   hits of frame 0 (the direct light is the same in every image and left out).
//! - **Reference** ([`reference`]): the native photon tracer and VKDE with
//!   the Epanechnikov kernel, [`REFERENCE_BATCHES`] independent batches of
//!   [`REFERENCE_FACTOR`] × the largest render's photons each (photon indices
//!   from [`REFERENCE_FIRST`], disjoint from the renders'), averaged: each
//!   batch's kernels are √[`REFERENCE_FACTOR`] times narrower than the largest
//!   render's (less bias), the average of the batches has 1/√batches of a
//!   batch's noise. Its own noise is measured from the batches' spread
//!   ([`Reference::noise`]); its dependence on the estimator by a kNN
//!   reference over the same photons ([`Reference::knn`]).
//!
//!   Why not a path tracer: the renders estimate a specific light transport,
//!   the 2nd and 3rd surface interactions of photons from a point light with
//!   the thesis' roulette, glass traced as a mirror and flat normals; a path
//!   tracer would have to reproduce exactly that transport, and any mismatch
//!   would show as error of every estimator alike. The photon tracer with
//!   many more photons converges to exactly the quantity the estimators
//!   estimate, so the error measured is the estimators' (bias and noise).
//! - **Time**: the GTX 280 timing model (`docs/timing-model.md`, no parameter
//!   from the thesis) on the emulator's counters of the kernels under the
//!   gt200 memory model: photon tracing, kernel construction (VKDE only) and
//!   the estimate, the estimate scaled from the run's pixels to a 512 × 512
//!   frame, each stage one persistent launch as in Table 6.6
//!   ([`super::table_6_6::predicted_ms`]). The host builds of the gathering
//!   structures (the kernels' BVH, the kd-tree) are not charged.
//! - **Error**: RMSE of the indirect radiance over the pixels' RGB, and the
//!   mean relative error of the pixels' luminance ([`mean_relative_error`]).

use rayon::prelude::*;
use serde::Serialize;

use super::knn::{self, KdMap};
use super::photons::{self, Emission, Photon};
use super::vkde::{self, Constructed, Estimate, PhotonMap, Query, Settings, Shape};
use super::{photon_image, table_5_1, table_6_6, timing};
use crate::chart::{Scatter, Series};
use crate::host::camera::Camera;
use crate::host::kdtree::KdTree;
use crate::host::raycast::Caster;
use crate::host::scene::Scene;
use crate::model::{Model, Profile};
use crate::repro::registry::MeasureError;
use crate::sim::Device;
use crate::timing::KernelCounts;

/// The renders' photon counts as fractions of the scene's emissions (Table 5.1's).
pub const LADDER: [f64; 4] = [1.0 / 64.0, 1.0 / 16.0, 1.0 / 4.0, 1.0];
/// Photons of one reference batch, times the largest render's.
pub const REFERENCE_FACTOR: usize = 4;
/// Independent batches averaged into the reference.
pub const REFERENCE_BATCHES: usize = 16;
/// The first photon index of the reference's batches (the renders use 0..n).
pub const REFERENCE_FIRST: u32 = 1 << 28;
/// The kNN reference's k (the most the kernels' heap holds).
pub const REFERENCE_KNN: usize = knn::K_MAX;
/// The side of the square frame the time is scaled to (the thesis' 512 × 512).
pub const FRAME_SIDE: f64 = timing::THESIS_RESOLUTION as f64;
/// Pixels whose reference luminance is below this fraction of the mean are
/// left out of the mean relative error (their relative error is unbounded).
pub const RELATIVE_FLOOR: f64 = 0.01;

/// The estimators compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Method {
    /// VKDE, uniform kernel.
    VkdeUniform,
    /// VKDE, Epanechnikov kernel.
    VkdeEpanechnikov,
    /// The k nearest interactions (uniform kernel), k_kNN.
    Knn,
}

impl Method {
    /// All three, in the charts' order.
    pub const ALL: [Method; 3] = [Method::VkdeUniform, Method::VkdeEpanechnikov, Method::Knn];

    /// The chart's series name.
    pub fn name(self) -> &'static str {
        match self {
            Method::VkdeUniform => "VKDE uniform",
            Method::VkdeEpanechnikov => "VKDE Epanechnikov",
            Method::Knn => "kNN",
        }
    }
}

/// RMSE of `a` against `b` over the pixels' three channels.
pub fn rmse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let n = (3 * b.len()).max(1) as f64;
    let s: f64 = a.iter().zip(b).flat_map(|(x, y)| (0..3).map(move |c| (x[c] as f64 - y[c] as f64).powi(2))).sum();
    (s / n).sqrt()
}

fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// The mean over pixels of |Y_a − Y_b| / Y_b (Y: luminance), over the pixels
/// whose reference luminance Y_b is at least [`RELATIVE_FLOOR`] × the mean
/// of the pixels with Y_b > 0; `NaN` when no pixel qualifies.
pub fn mean_relative_error(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let lit: Vec<f64> = b.iter().map(luminance).filter(|&y| y > 0.0).collect();
    let floor = RELATIVE_FLOOR * lit.iter().sum::<f64>() / lit.len().max(1) as f64;
    let (mut s, mut n) = (0.0, 0usize);
    for (x, y) in a.iter().zip(b) {
        let yb = luminance(y);
        if yb > 0.0 && yb >= floor {
            s += (luminance(x) - yb).abs() / yb;
            n += 1;
        }
    }
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// The stored interactions of photons `first .. first + e.n` of `e` (each
/// with `e`'s flux, Φ / e.n), traced natively in parallel.
pub fn trace_native(caster: &Caster, e: &Emission, first: u32) -> Vec<[Option<Photon>; 2]> {
    (0..e.n as u32).into_par_iter().map(|i| photons::trace_one(caster, e, first + i)).collect()
}

/// The native maps of `photons`: the kernels (VKDE) and the kd-tree (kNN).
pub fn native_maps(photons: &[[Option<Photon>; 2]], s: &Settings) -> (Constructed, PhotonMap, KdMap) {
    let cons: Vec<_> = photons.par_iter().flatten().flatten().map(|p| vkde::construct(p, s)).collect();
    let constructed = Constructed::collect(cons.iter());
    let bvh = PhotonMap::build(&constructed.kernels);
    (constructed, bvh, KdMap::build(photons))
}

/// The native estimate of `method` at every query (`k`: kNN's).
pub fn estimate_native(bvh: &PhotonMap, kd: &KdMap, q: &[Option<Query>], method: Method, k: usize) -> Vec<Estimate> {
    q.par_iter()
        .map(|q| {
            q.map_or_else(Estimate::default, |q| match method {
                Method::VkdeUniform => vkde::estimate(bvh, &q, Shape::Uniform),
                Method::VkdeEpanechnikov => vkde::estimate(bvh, &q, Shape::Epanechnikov),
                Method::Knn => knn::estimate(kd, &q, k, vkde::H_MAX, Shape::Uniform),
            })
        })
        .collect()
}

/// A converged reference: the mean of independent batches' estimates.
#[derive(Debug, Clone)]
pub struct Reference {
    /// Per pixel, the mean of the batches' VKDE Epanechnikov estimates.
    pub image: Vec<[f32; 3]>,
    /// Per pixel, the mean of the batches' kNN estimates (k = [`REFERENCE_KNN`]).
    pub knn: Vec<[f32; 3]>,
    /// Photons a batch emitted.
    pub batch_photons: usize,
    /// Batches averaged.
    pub batches: usize,
    /// Stored interactions over all batches.
    pub interactions: usize,
    /// The RMSE of the mean from the batches' spread: sqrt(Σ var / (B (B − 1))) over pixels and channels.
    pub noise: f64,
    /// Mean contributions per query point of a batch's VKDE estimate.
    pub contributions: f64,
}

/// The reference of `scene` at `queries`: `batches` batches of
/// `batch_photons` photons traced natively from photon index `first` on,
/// each its own estimate with spread `spread` (and Δp of its own photons).
#[allow(clippy::too_many_arguments)]
pub fn reference(
    scene: &Scene,
    tree: &KdTree,
    queries: &[Option<Query>],
    spread: f32,
    batch_photons: usize,
    batches: usize,
    first: u32,
    progress: &mut dyn FnMut(&str),
) -> Result<Reference, MeasureError> {
    let caster = Caster::new(scene, tree);
    let e = Emission::of(scene, batch_photons)?;
    let s = Settings { h_max: vkde::H_MAX, ..Settings::thesis(batch_photons, spread) };
    let n = queries.len();
    let (mut sum, mut sq, mut knn_sum) = (vec![[0f64; 3]; n], vec![[0f64; 3]; n], vec![[0f64; 3]; n]);
    let (mut interactions, mut contributions) = (0usize, 0u64);
    for b in 0..batches {
        progress(&format!("reference batch {}/{batches}: {batch_photons} photons", b + 1));
        let start = first + (b * batch_photons) as u32;
        let photons = trace_native(&caster, &e, start);
        let (constructed, bvh, kd) = native_maps(&photons, &s);
        drop(photons);
        interactions += constructed.interactions;
        let est = estimate_native(&bvh, &kd, queries, Method::VkdeEpanechnikov, 0);
        contributions += est.iter().map(|e| e.contributions as u64).sum::<u64>();
        let kn = estimate_native(&bvh, &kd, queries, Method::Knn, REFERENCE_KNN);
        for (((s, q), k), (e, kn)) in sum.iter_mut().zip(&mut sq).zip(&mut knn_sum).zip(est.iter().zip(&kn)) {
            for c in 0..3 {
                let x = e.radiance[c] as f64;
                s[c] += x;
                q[c] += x * x;
                k[c] += kn.radiance[c] as f64;
            }
        }
    }
    let bf = batches.max(1) as f64;
    let mean = |s: &[[f64; 3]]| s.iter().map(|p| p.map(|x| (x / bf) as f32)).collect::<Vec<_>>();
    let var: f64 = sum
        .iter()
        .zip(&sq)
        .flat_map(|(s, q)| (0..3).map(move |c| (q[c] - s[c] * s[c] / bf) / (bf - 1.0).max(1.0)))
        .sum();
    let noise = (var / bf / (3 * n).max(1) as f64).max(0.0).sqrt();
    let queried = queries.iter().flatten().count().max(1) as f64;
    Ok(Reference {
        image: mean(&sum),
        knn: mean(&knn_sum),
        batch_photons,
        batches,
        interactions,
        noise,
        contributions: contributions as f64 / bf / queried,
    })
}

/// One render of the ladder: one photon count, one estimator.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// The estimator.
    pub method: Method,
    /// Photons emitted.
    pub photons: usize,
    /// Stored interactions.
    pub interactions: usize,
    /// Mean contributions per query point (kNN: the interactions within its radius).
    pub contributions: f64,
    /// RMSE of the indirect radiance against the reference.
    pub rmse: f64,
    /// Mean relative luminance error against the reference.
    pub relative: f64,
    /// Modelled milliseconds of a 512 × 512 frame on the GTX 280: tracing, construction (VKDE), estimate.
    pub ms: [f64; 3],
    /// Warp instructions the emulator counted: tracing, construction (VKDE), estimate (at the run's pixels).
    pub warp_instructions: [f64; 3],
}

impl Point {
    /// The modelled frame time, all stages.
    pub fn total_ms(&self) -> f64 {
        self.ms.iter().sum()
    }
}

/// The kernels of the renders, loaded once.
pub struct Kernels {
    dev: Device,
    photons: crate::sim::Module,
    vkde: crate::sim::Module,
    knn: crate::sim::Module,
}

impl Kernels {
    /// Loads the photon, VKDE and kNN kernels on a device of the default configuration.
    pub fn load() -> Result<Kernels, crate::sim::SimError> {
        let mut dev = Device::new();
        let photons = photons::load(&mut dev)?;
        let vkde = vkde::load(&mut dev)?;
        let knn = knn::load(&mut dev)?;
        Ok(Kernels { dev, photons, vkde, knn })
    }
}

fn ms(c: &KernelCounts) -> f64 {
    table_6_6::predicted_ms(c).unwrap_or(f64::NAN)
}

/// The renders of `photons` photons with `spread` and kNN's `k` on the
/// emulator at `queries`, each method against `reference`.
pub fn emulated_points(
    k: &mut Kernels,
    scene: &Scene,
    tree: &KdTree,
    queries: &[Option<Query>],
    (photons, spread, knn_k): (usize, f32, usize),
    reference: &[[f32; 3]],
) -> Result<Vec<Point>, MeasureError> {
    let e = Emission::of(scene, photons)?;
    let s = Settings { h_max: vkde::H_MAX, ..Settings::thesis(photons, spread) };
    let dev = &mut k.dev;
    let model = Model::new(Profile::Gt200, &k.photons.prog);
    let traced = photons::trace_kernel_observed(dev, &k.photons, scene, tree, &e, Some(&model))?;
    let trace = timing::counts_of(&k.photons.prog, &traced.launch, &model.finish());
    let model = Model::new(Profile::Gt200, &k.vkde.prog);
    let (cons, cl) = vkde::construct_kernel_observed(dev, &k.vkde, &traced.photons, &s, Some(&model))?;
    let construct = timing::counts_of(&k.vkde.prog, &cl, &model.finish());
    let constructed = Constructed::collect(cons.iter());
    let bvh = PhotonMap::build(&constructed.kernels);
    let kd = KdMap::build(&traced.photons);
    let scale = FRAME_SIDE * FRAME_SIDE / queries.len().max(1) as f64;
    let queried = queries.iter().flatten().count().max(1) as f64;
    let mut out = Vec::new();
    for method in Method::ALL {
        let (est, counts) = match method {
            Method::VkdeUniform | Method::VkdeEpanechnikov => {
                let shape = if method == Method::VkdeUniform { Shape::Uniform } else { Shape::Epanechnikov };
                let model = Model::new(Profile::Gt200, &k.vkde.prog);
                let (est, l) = vkde::estimate_kernel_observed(dev, &k.vkde, &bvh, queries, shape, Some(&model))?;
                (est, timing::counts_of(&k.vkde.prog, &l, &model.finish()))
            }
            Method::Knn => {
                let model = Model::new(Profile::Gt200, &k.knn.prog);
                let search = (knn_k, vkde::H_MAX, Shape::Uniform);
                let (est, l) = knn::estimate_kernel_observed(dev, &k.knn, &kd, queries, search, Some(&model))?;
                (est, timing::counts_of(&k.knn.prog, &l, &model.finish()))
            }
        };
        let vk = method != Method::Knn;
        let img: Vec<[f32; 3]> = est.iter().map(|e| e.radiance).collect();
        let con = if vk { construct } else { KernelCounts::default() };
        out.push(Point {
            method,
            photons,
            interactions: constructed.interactions,
            contributions: est.iter().map(|e| e.contributions as f64).sum::<f64>() / queried,
            rmse: rmse(&img, reference),
            relative: mean_relative_error(&img, reference),
            ms: [ms(&trace), if vk { ms(&con) } else { 0.0 }, ms(&counts.scaled(scale))],
            warp_instructions: [trace.warp_instructions, con.warp_instructions, counts.warp_instructions],
        });
    }
    Ok(out)
}

/// The charts of one scene and the numbers beside them.
#[derive(Debug, Clone, Serialize)]
pub struct Accuracy {
    /// The scene.
    pub scene: String,
    /// The image's pixels (width, height).
    pub resolution: [u32; 2],
    /// Query points among them.
    pub queries: usize,
    /// Table 5.1's emissions, spread s and k_kNN used.
    pub settings: (usize, f32, usize),
    /// Every render.
    pub points: Vec<Point>,
    /// Photons a reference batch emitted, batches, interactions stored over all.
    pub reference: (usize, usize, usize),
    /// The reference's RMSE from its batches' spread, and over its RMS.
    pub reference_noise: (f64, f64),
    /// RMSE and mean relative error of the kNN reference against the VKDE one (estimator dependence).
    pub reference_knn: (f64, f64),
    /// The reference's RMS (the RMSE of a black image).
    pub reference_rms: f64,
    /// Mean contributions per query point of a reference batch.
    pub reference_contributions: f64,
}

impl Accuracy {
    /// The four charts: (file suffix, chart): RMSE and mean relative error
    /// against photons emitted and against modelled time.
    pub fn charts(&self) -> Vec<(&'static str, Scatter)> {
        let series = |x: &dyn Fn(&Point) -> f64, y: &dyn Fn(&Point) -> f64| {
            Method::ALL
                .iter()
                .map(|&m| Series {
                    name: m.name().into(),
                    points: self.points.iter().filter(|p| p.method == m).map(|p| (x(p), y(p))).collect(),
                })
                .collect::<Vec<_>>()
        };
        let what = format!(
            "{}: indirect light at {}x{} against a reference of {} x {} photons",
            self.scene, self.resolution[0], self.resolution[1], self.reference.1, self.reference.0
        );
        let chart = |x_label: &str, y_label: &str, s| Scatter {
            title: what.clone(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: true,
            log_y: true,
            connect: true,
            series: s,
        };
        let photons = "photons emitted";
        let time = "modelled ms of a 512 x 512 frame on the GTX 280 (trace + construction + estimate)";
        let (rmse, rel) = ("RMSE (radiance)", "mean relative luminance error");
        vec![
            ("rmse-photons", chart(photons, rmse, series(&|p| p.photons as f64, &|p| p.rmse))),
            ("rmse-time", chart(time, rmse, series(&|p| p.total_ms(), &|p| p.rmse))),
            ("relative-photons", chart(photons, rel, series(&|p| p.photons as f64, &|p| p.relative))),
            ("relative-time", chart(time, rel, series(&|p| p.total_ms(), &|p| p.relative))),
        ]
    }
}

/// Measures the accuracy of `scene` seen by `cam` (frame 0's light): the
/// ladder on the emulator, the reference natively. Parameters: Table 5.1's
/// for its scenes, else the render command's defaults.
pub fn measure(scene: &Scene, cam: &Camera, progress: &mut dyn FnMut(&str)) -> Result<Accuracy, MeasureError> {
    let (photons, spread) = photon_image::render_parameters(&scene.name);
    let knn_k = table_5_1::THESIS
        .row(&scene.name)
        .map_or(photon_image::DEFAULT_K, |r| r.cells[6].value() as usize)
        .min(knn::K_MAX);
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = crate::host::kdtree::build(
        &tris,
        crate::host::kdtree::BuildParams::thesis(crate::host::kdtree::Heuristic::Siroh),
    );
    let caster = Caster::new(scene, &tree);
    let q = photon_image::queries(&caster, cam);
    let refr =
        reference(scene, &tree, &q, spread, REFERENCE_FACTOR * photons, REFERENCE_BATCHES, REFERENCE_FIRST, progress)?;
    let mut k = Kernels::load()?;
    let mut points = Vec::new();
    for f in LADDER {
        let n = ((photons as f64 * f).round() as usize).max(1);
        progress(&format!("emulated renders with {n} photons"));
        points.extend(emulated_points(&mut k, scene, &tree, &q, (n, spread, knn_k), &refr.image)?);
    }
    let black = vec![[0f32; 3]; q.len()];
    let rms = rmse(&black, &refr.image);
    Ok(Accuracy {
        scene: scene.name.clone(),
        resolution: cam.resolution,
        queries: q.iter().flatten().count(),
        settings: (photons, spread, knn_k),
        points,
        reference: (refr.batch_photons, refr.batches, refr.interactions),
        reference_noise: (refr.noise, refr.noise / rms),
        reference_knn: (rmse(&refr.knn, &refr.image), mean_relative_error(&refr.knn, &refr.image)),
        reference_rms: rms,
        reference_contributions: refr.contributions,
    })
}

/// `warplight render --method photon-map --variant error -o OUT.png`: the
/// accuracy of `scene` seen by `cam` ([`measure`]), written as
/// `OUT-{rmse,relative}-{photons,time}.svg` with each chart's JSON beside it
/// (`warplight chart scatter` redraws them) and `OUT-summary.json`.
pub fn run_cli(scene: &Scene, cam: &Camera, output: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let t = std::time::Instant::now();
    let a = measure(scene, cam, &mut |x| eprintln!("{}: {x} ({:.0} s)", scene.name, t.elapsed().as_secs_f64()))
        .map_err(|e| e.to_string())?;
    let mut v = serde_json::to_value(&a)?;
    v["seconds"] = serde_json::json!(t.elapsed().as_secs_f64());
    let written = crate::chart::write_charts(&output.with_extension(""), a.charts(), &v)?;
    for (_, svg, _) in &written.charts {
        println!("{}", svg.display());
    }
    for p in &a.points {
        println!(
            "{:>8} photons {:<18} k {:>7.1}  RMSE {:.4e}  rel {:.4}  {:.2} ms",
            p.photons,
            p.method.name(),
            p.contributions,
            p.rmse,
            p.relative,
            p.total_ms()
        );
    }
    println!(
        "reference: {} x {} photons, RMS {:.4e}, noise {:.4e} ({:.2} %), kNN reference RMSE {:.4e} rel {:.4}; \
         summary {}; {:.1} s",
        a.reference.1,
        a.reference.0,
        a.reference_rms,
        a.reference_noise.0,
        100.0 * a.reference_noise.1,
        a.reference_knn.0,
        a.reference_knn.1,
        written.summary.display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_by_hand() {
        let b = [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert_eq!(rmse(&b, &b), 0.0);
        // one channel off by 3 of six: sqrt(9 / 6)
        let a = [[4.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert!((rmse(&a, &b) - 1.5f64.sqrt()).abs() < 1e-12);
        // luminance 1 and 2; a grey 1.5 and 3 are both 50 % off
        let a = [[1.5, 1.5, 1.5], [3.0, 3.0, 3.0]];
        assert!((mean_relative_error(&a, &b) - 0.5).abs() < 1e-6);
        // a black reference pixel and one below the floor are left out
        let b = [[0.0; 3], [1e-4, 1e-4, 1e-4], [1.0, 1.0, 1.0]];
        let a = [[5.0; 3], [1.0; 3], [1.25, 1.25, 1.25]];
        assert!((mean_relative_error(&a, &b) - 0.25).abs() < 1e-6);
        assert!(mean_relative_error(&a, &[[0.0; 3]; 3]).is_nan());
    }
}
