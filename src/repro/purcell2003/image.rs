//! Images of the seed's scenes (Fig. 7): direct light from the shadow rays
//! plus the kNN-grid estimate of either map (indirect light and caustics,
//! the photon map visualised directly, no final gather: 004:L247), each
//! pixel albedo / π · Σ power / (π r²) + direct. The emulated pipeline
//! renders them; [`native_images`] recomputes the per-pixel passes in Rust
//! ([`super::native`]) over the same photon maps, bit for bit alike.

use super::bitonic;
use super::knn::{self, Map, Params, State};
use super::native::{self, MapData, QueryPoints};
use super::photons::Geometry;
use super::pipeline::{self, MAX_PASSES, Prepared};
use super::scenes::{EYE_DEPTH, Fixture, SEED};
use super::stencil;
use crate::host::camera::Camera;
use crate::host::image::FrameBuffer;
use crate::host::scene::Scene;
use crate::repro::registry::MeasureError;

/// An emulated render: the per-pixel inputs and results, and the maps' arrays.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The camera (its resolution the image's).
    pub camera: Camera,
    /// The scene's settings.
    pub fixture: Fixture,
    /// The estimate's parameters.
    pub params: Params,
    /// Query points read back.
    pub queries: QueryPoints,
    /// Direct light per pixel (shadow rays).
    pub direct: Vec<[f32; 4]>,
    /// Final search states on map A and map B.
    pub states: [Vec<State>; 2],
    /// Whether each estimate finished within the pass limit.
    pub finished: [bool; 2],
    /// Map A's and map B's arrays.
    pub maps: [MapData; 2],
    /// The grid.
    pub grid: super::grid::Grid,
    /// The progressive display on map A and map B: the running image after
    /// every pass (empty unless asked for: [`render_with`]).
    pub progress: [Vec<FrameBuffer>; 2],
    /// Share of the pixels finished after every pass, on map A and map B.
    pub finished_after: [Vec<f64>; 2],
    /// Thread instructions of building map A and map B (the emulator's counts).
    pub build_instructions: [u64; 2],
    /// Thread instructions of the estimate on map A and map B up to each pass.
    pub estimate_instructions: [Vec<u64>; 2],
}

fn read4(p: &super::passes::Passes, ptr: crate::sim::DevicePtr, n: usize) -> Vec<[f32; 4]> {
    p.dev.read::<f32>(ptr, 4 * n).chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()
}

/// Runs the emulated pipeline on `scene` with settings `f`, `width` pixels wide.
pub fn render(scene: &Scene, f: &Fixture, width: u32) -> Result<Rendered, MeasureError> {
    render_with(scene, f, width, false)
}

/// [`render`], keeping the running image after every pass when `progressive`.
pub fn render_with(scene: &Scene, f: &Fixture, width: u32, progressive: bool) -> Result<Rendered, MeasureError> {
    render_configured(scene, f, width, progressive, &|_| {})
}

/// [`render_with`] on a device whose settings `set` adjusts
/// ([`super::passes::Passes::configured`]).
pub fn render_configured(
    scene: &Scene,
    f: &Fixture,
    width: u32,
    progressive: bool,
    set: &dyn Fn(&mut crate::sim::SimConfig),
) -> Result<Rendered, MeasureError> {
    let Prepared { mut passes, fixture, photons, queries, grid, direct } =
        pipeline::prepare_configured(scene, f, width, set)?;
    let p = &mut passes;
    let params = pipeline::params(&fixture);
    let npix = (queries.width * queries.height) as usize;
    let qp = QueryPoints {
        query: read4(p, queries.query, npix),
        normal: read4(p, queries.normal, npix),
        albedo: read4(p, queries.albedo, npix),
    };
    let direct = read4(p, direct, npix);
    let slots = photons.n * photons.frames;
    let (w, h) = (queries.width, queries.height);
    let mut progress: [Vec<FrameBuffer>; 2] = [Vec::new(), Vec::new()];
    let mut finished_after: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    let share = |st: &[State]| st.iter().filter(|s| s.done).count() as f64 / st.len().max(1) as f64;
    let a = bitonic::build(p, grid, &photons)?;
    let build_a = p.take_phase(bitonic::BUILD_MAP).thread_instructions;
    let ea = knn::estimate_with(p, &Map::Bitonic(&a, &photons), &queries, &params, MAX_PASSES, &mut |_, st| {
        finished_after[0].push(share(st));
        if progressive {
            progress[0].push(image(w, h, &direct, &qp.albedo, st, &params));
        }
    })?;
    let map_a = MapData::Bitonic {
        first: p.dev.read::<u32>(a.first, grid.cells() + 1),
        sorted: p.dev.read::<u32>(a.sorted, 2 * a.n).chunks_exact(2).map(|e| [e[0], e[1]]).collect(),
        pos: read4(p, photons.pos, slots),
        pow: read4(p, photons.pow, slots),
        dir: read4(p, photons.dir, slots),
    };
    let b = stencil::build(p, grid, &photons, fixture.slots)?;
    let build_b = p.take_phase(bitonic::BUILD_MAP).thread_instructions;
    let eb = knn::estimate_with(p, &Map::Stencil(&b), &queries, &params, MAX_PASSES, &mut |_, st| {
        finished_after[1].push(share(st));
        if progressive {
            progress[1].push(image(w, h, &direct, &qp.albedo, st, &params));
        }
    })?;
    let n = grid.cells() * b.slots;
    let map_b = MapData::Stencil {
        slots: b.slots,
        stored: p.dev.read::<u32>(b.stored, grid.cells()),
        scale: p.dev.read::<f32>(b.scale, grid.cells()),
        pos: read4(p, b.pos, n),
        pow: read4(p, b.pow, n),
        dir: read4(p, b.dir, n),
    };
    Ok(Rendered {
        camera: pipeline::camera(scene, &fixture, width),
        fixture,
        params,
        queries: qp,
        direct,
        states: [ea.states, eb.states],
        finished: [ea.finished, eb.finished],
        maps: [map_a, map_b],
        grid,
        progress,
        finished_after,
        build_instructions: [build_a, build_b],
        estimate_instructions: [ea.instructions_after, eb.instructions_after],
    })
}

/// The per-pixel passes recomputed natively over `r`'s maps: query points,
/// direct light and the final states on map A and map B.
pub fn native_passes(scene: &Scene, r: &Rendered) -> (QueryPoints, Vec<[f32; 4]>, [Vec<State>; 2]) {
    let geo = Geometry::of(scene);
    let q = native::eye_rays(&geo, &r.camera, EYE_DEPTH);
    let direct = native::shadow_rays(&geo, &q, r.fixture.shadow_samples, SEED);
    let states = [0, 1].map(|m| native::estimate(&r.grid, &r.maps[m], &q, &r.params));
    (q, direct, states)
}

/// Radiance per pixel: direct + albedo / π · Σ power / (π r²) of `states`
/// (r = r_max where fewer than k photons were found).
pub fn image(w: u32, h: u32, direct: &[[f32; 4]], albedo: &[[f32; 4]], states: &[State], p: &Params) -> FrameBuffer {
    let flat: Vec<f32> = albedo.iter().flatten().copied().collect();
    let ind = knn::radiance_of(states, &flat, p);
    FrameBuffer {
        width: w,
        height: h,
        pixels: ind.iter().zip(direct).map(|(i, d)| [d[0] + i[0], d[1] + i[1], d[2] + i[2]]).collect(),
    }
}

/// The emulated images: map A (bitonic) and map B (stencil).
pub fn images(r: &Rendered) -> [FrameBuffer; 2] {
    let [w, h] = r.camera.resolution;
    [0, 1].map(|m| image(w, h, &r.direct, &r.queries.albedo, &r.states[m], &r.params))
}

/// The native images over `r`'s maps: map A and map B.
pub fn native_images(scene: &Scene, r: &Rendered) -> [FrameBuffer; 2] {
    let [w, h] = r.camera.resolution;
    let (q, direct, states) = native_passes(scene, r);
    [0, 1].map(|m| image(w, h, &direct, &q.albedo, &states[m], &r.params))
}

/// One pass of the progressive display against the converged image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassError {
    /// The pass (from 1).
    pub pass: u64,
    /// Pixels finished.
    pub finished: f64,
    /// Relative RMS error of the running image against the final one
    /// (linear radiance; sqrt(Σ (a − b)²) / sqrt(Σ b²) over the channels).
    pub rel_rmse: f64,
    /// Share of pixels whose displayed colour (8-bit sRGB, clamped at 1:
    /// the display saturates) is not yet the final one.
    pub displayed_off: f64,
    /// Share of the pixels that saturate in the final image (a channel ≥ 1)
    /// whose displayed colour is already final.
    pub saturated_final: f64,
}

/// The running images `progress` against the last one, pass by pass;
/// `finished_after[i]`: pixels finished after pass i + 1.
pub fn convergence(progress: &[FrameBuffer], finished_after: &[f64]) -> Vec<PassError> {
    let Some(last) = progress.last() else { return Vec::new() };
    let disp = |f: &FrameBuffer| f.to_srgb8(0.0);
    let final8 = disp(last);
    let sat: Vec<bool> = last.pixels.iter().map(|p| p.iter().any(|&c| c >= 1.0)).collect();
    let nsat = sat.iter().filter(|&&s| s).count().max(1) as f64;
    let norm: f64 = last.pixels.iter().flatten().map(|&c| (c as f64).powi(2)).sum::<f64>().sqrt().max(1e-30);
    progress
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let d8 = disp(f);
            let off = d8.chunks_exact(3).zip(final8.chunks_exact(3)).map(|(a, b)| a != b).collect::<Vec<bool>>();
            let err: f64 = f
                .pixels
                .iter()
                .zip(&last.pixels)
                .flat_map(|(a, b)| (0..3).map(move |c| (a[c] as f64 - b[c] as f64).powi(2)))
                .sum::<f64>()
                .sqrt();
            PassError {
                pass: i as u64 + 1,
                finished: finished_after.get(i).copied().unwrap_or(f64::NAN),
                rel_rmse: err / norm,
                displayed_off: off.iter().filter(|&&o| o).count() as f64 / off.len().max(1) as f64,
                saturated_final: sat.iter().zip(&off).filter(|(s, o)| **s && !**o).count() as f64 / nsat,
            }
        })
        .collect()
}

/// The convergence of both maps' progressive displays as a chart (JSON for
/// `warplight chart scatter`): per pass, the share of pixels finished, the
/// share whose displayed colour is not yet final, and the relative RMS error.
pub fn convergence_chart(scene: &str, r: &Rendered) -> crate::chart::Scatter {
    let mut series = Vec::new();
    for (m, name) in ["bitonic", "stencil"].iter().enumerate() {
        let c = convergence(&r.progress[m], &r.finished_after[m]);
        let pts = |f: &dyn Fn(&PassError) -> f64| c.iter().map(|p| (p.pass as f64, f(p))).collect::<Vec<_>>();
        series.push(crate::chart::Series {
            name: format!("{name}: pixels not finished"),
            points: pts(&|p| 1.0 - p.finished),
        });
        series.push(crate::chart::Series {
            name: format!("{name}: displayed colour not final"),
            points: pts(&|p| p.displayed_off),
        });
        series.push(crate::chart::Series { name: format!("{name}: relative RMS error"), points: pts(&|p| p.rel_rmse) });
    }
    crate::chart::Scatter {
        title: format!("{scene}: full vs visual convergence of the progressive display (004:L182)"),
        x_label: "radiance-estimate passes".into(),
        y_label: "share of pixels / relative error".into(),
        log_x: false,
        log_y: false,
        connect: true,
        series,
    }
}

/// `warplight render --method purcell`: the scene's Fig. 7 images on both
/// maps, `-o out.png` writing `out-bitonic.png` and `out-stencil.png`;
/// `--variant native` recomputes the per-pixel passes natively (and says
/// whether they equal the emulated ones bit for bit); `--json FILE` writes
/// the progressive display's convergence chart (`warplight chart scatter`);
/// `--variant error` writes the error charts instead ([`run_error_charts`]).
pub fn run_cli(
    a: &crate::cli::render::RenderArgs,
    scene: &Scene,
    cam: &Camera,
    profile: crate::model::Profile,
) -> Result<(), Box<dyn std::error::Error>> {
    let f = pipeline::fixture_of(scene).map_err(|e| e.to_string())?;
    let width = cam.resolution[0];
    let native = match a.variant.as_str() {
        "native" => true,
        "emulated" => false,
        "error" => return run_error_charts(a, scene, &f, width, profile),
        v => return Err(format!("--method purcell --variant {v}: expected native, emulated or error").into()),
    };
    let t = std::time::Instant::now();
    // the emulated kernels run on the command's profile, FMA contraction and fidelity
    let set = |c: &mut crate::sim::SimConfig| {
        c.fidelity = a.fidelity;
        profile.configure(c, a.fmad);
    };
    let r = render_configured(scene, &f, width, a.json.is_some(), &set).map_err(|e| e.to_string())?;
    let mut out = images(&r);
    let mut alike = None;
    if native {
        let n = native_images(scene, &r);
        alike = Some(n == out);
        out = n;
    }
    let stem = a.output.with_extension("");
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("png");
    for (m, name) in ["bitonic", "stencil"].iter().enumerate() {
        let file = std::path::PathBuf::from(format!("{}-{name}.{ext}", stem.display()));
        crate::cli::render::write_image(&out[m], &file, a.exposure)?;
        println!(
            "{}: {} map, {}x{}, {} passes of the estimate{}: {}",
            scene.name,
            name,
            out[m].width,
            out[m].height,
            r.finished_after[m].len(),
            if r.finished[m] { "" } else { " (cut off)" },
            file.display()
        );
    }
    if let Some(x) = alike {
        println!(
            "native per-pixel passes: {}",
            if x { "bit for bit the emulated images" } else { "DIFFER from the emulated images" }
        );
    }
    if let Some(j) = &a.json {
        let chart = convergence_chart(&scene.name, &r);
        crate::files::write_atomically(j, serde_json::to_string_pretty(&chart)?.as_bytes())?;
        println!("convergence chart data: {}", j.display());
    }
    println!("{:.1} s", t.elapsed().as_secs_f64());
    Ok(())
}

/// Photon counts of the error chart, as multiples of the stated count.
pub const ERROR_FACTORS: [f64; 4] = [0.125, 0.25, 0.5, 1.0];
/// The error charts' reference: 64 times the stated photons and 8 times the
/// stated k, natively ([`super::reference`]; `docs/fixtures.md`).
pub const ERROR_REFERENCE: super::error::ReferenceSpec = super::error::ReferenceSpec { photons: 64.0, k: 8.0 };

/// `warplight render --method purcell --variant error -o out.png`: the error
/// of both maps against a native reference ([`ERROR_REFERENCE`]), at
/// [`ERROR_FACTORS`] times the stated photons (`out-photons.svg`), and pass
/// by pass at the stated count over counted instructions (`out-time.svg`)
/// and over passes (`out-passes.svg`), each chart's data beside it as JSON,
/// and the reference's own error and the displays' settling in
/// `out-summary.json` ([`super::error`]). The emulated renders run on the
/// command's profile, FMA contraction and fidelity, as [`run_cli`]'s do.
pub fn run_error_charts(
    a: &crate::cli::render::RenderArgs,
    scene: &Scene,
    f: &Fixture,
    width: u32,
    profile: crate::model::Profile,
) -> Result<(), Box<dyn std::error::Error>> {
    let t = std::time::Instant::now();
    let set = |c: &mut crate::sim::SimConfig| {
        c.fidelity = a.fidelity;
        profile.configure(c, a.fmad);
    };
    let c = super::error::charts(scene, f, width, (&ERROR_FACTORS, ERROR_REFERENCE), &set, &mut |x| {
        eprintln!("{}: {x} ({:.0} s)", scene.name, t.elapsed().as_secs_f64());
    })
    .map_err(|e| e.to_string())?;
    let (emitted, stored, k) = c.reference;
    let summary = serde_json::json!({
        "scene": scene.name,
        "resolution": pipeline::camera(scene, f, width).resolution,
        "reference": { "spec": c.spec, "emitted": emitted, "stored": stored, "k": k,
            "noise_against_second_reference": c.reference_noise,
            "error_of_quarter_photons_half_k": c.reference_step,
            "estimate_share_of_norm": c.indirect_share },
        "final_error": {
            "bitonic": c.photons.series[0].points, "stencil": c.photons.series[1].points },
        "settling": c.settling,
        "seconds": t.elapsed().as_secs_f64(),
    });
    let charts = [("photons", c.photons.clone()), ("time", c.time.clone()), ("passes", c.passes.clone())];
    let written = crate::chart::write_charts(&a.output.with_extension(""), charts, &summary)?;
    for (title, svg, json) in &written.charts {
        println!("{title}: {} and {}", svg.display(), json.display());
    }
    let file = written.summary;
    println!(
        "reference: {emitted} emitted, {stored} stored, k = {k}; against a second reference {:.4}, \
         a quarter of the photons and half the k {:.4}; summary {}; {:.1} s",
        c.reference_noise,
        c.reference_step,
        file.display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
