//! Thesis 003's charts (issue 15, item 5): the convergence against the
//! committed Mitsuba reference (`warplight chart lin-convergence`) and the
//! per-level lane utilisation with and without compaction (`warplight chart
//! lin-compaction`). Each builder is run small and held to a property of the
//! light transport or of the SIMT counts that a wrong builder or renderer
//! would break, and its JSON is read back to the same data and charts.

use std::path::Path;

use warplight::host::path::{Integrator, Termination};
use warplight::host::scene_file;
use warplight::repro::lin2017::convergence::{self, Convergence, Options, Reference};
use warplight::repro::lin2017::lanes::{self, Compaction};

/// Whether two JSON values are the same up to the last bits of their numbers
/// (serde_json's float parsing is not always correctly rounded).
fn same_json(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            x == y || (x - y).abs() <= 1e-14 * x.abs().max(y.abs())
        }
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(p, q)| same_json(p, q)),
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same_json(v, w)))
        }
        _ => a == b,
    }
}

/// `data` written as JSON and read back is the same data with the same charts.
fn round_trips<T: serde::Serialize + serde::de::DeserializeOwned>(
    data: &T,
    charts: impl Fn(&T) -> Vec<warplight::chart::Scatter>,
) {
    let text = serde_json::to_string(data).unwrap();
    let back: T = serde_json::from_str(&text).expect("the data read back");
    assert!(same_json(&serde_json::to_value(&back).unwrap(), &serde_json::to_value(data).unwrap()), "{text}");
    let (a, b) = (charts(&back), charts(data));
    assert_eq!(a.len(), b.len());
    assert!(same_json(&serde_json::to_value(&a).unwrap(), &serde_json::to_value(&b).unwrap()));
}

fn scene(name: &str) -> warplight::host::scene::Scene {
    scene_file::load(&scene_file::resolve(name)).expect("the scene loads")
}

fn reference(name: &str) -> Reference {
    let prefix = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mitsuba").join(format!("{name}-32"));
    Reference::read(&prefix).expect("the committed reference reads")
}

/// Every unbiased integrator's RMS error on the rough-mirror box (Figs. 6/7's
/// scene) falls as spp^-1/2 (the slope of log error on log spp from 16 to 256
/// spp, the reference's noise taken out, within [-0.8, -0.3]); MLT's falls
/// while its mean luminance stays at its start-up's b; MIS under either
/// heuristic is no worse than the worse of its two strategies (pt: BSDF
/// sampling only; nee: light sampling at diffuse hits); the emulated frame
/// equals the native one bit for bit; the data survive JSON.
#[test]
fn convergence_falls_as_one_over_root_spp_and_mis_is_no_worse_than_its_strategies() {
    let s = scene("cornell-rough");
    let r = reference("cornell-rough");
    let (ref_rmse, ref_rel) = r.noise();
    assert!(ref_rmse > 0.0 && ref_rmse < 0.01, "{ref_rmse}");
    assert!(ref_rel > 0.0 && ref_rel < 0.01, "{ref_rel}");
    let o = Options {
        integrators: convergence::INTEGRATORS.to_vec(),
        terminations: vec![Termination::Roulette],
        frames: 64,
        emulated_frames: vec![],
        bounces: 16,
        seed: 7,
    };
    let c = convergence::measure(&s, &r, &o, &mut |_| {}).expect("measured");
    assert_eq!(c.reference_spp, 16 * 512 * 4);
    for curve in &c.curves {
        let spp: Vec<u32> = curve.native.iter().map(|p| p.spp).collect();
        assert_eq!(spp, [4, 8, 16, 32, 64, 128, 256], "{}", curve.integrator);
        let slope = curve.slope(16, c.reference_rmse).expect("a slope");
        eprintln!("{}: slope {slope:.3}, RMSE at 256 spp {:.4e}", curve.integrator, curve.native[6].rmse);
        if curve.integrator == "mlt" {
            // every MLT iteration splats luminance b in all (b F / Y, weights 1 - a and a):
            // the image's mean is b from the first frame, and its error b's (003:L330);
            // the RMS error still falls, towards that floor
            let m = curve.native[0].rel_mean;
            assert!(curve.native.iter().all(|p| (p.rel_mean - m).abs() <= 1e-5 * m.max(1e-3)), "{curve:?}");
            assert!(curve.native.windows(2).all(|w| w[1].rmse < w[0].rmse), "{curve:?}");
        } else {
            assert!((-0.8..=-0.3).contains(&slope), "{}: slope {slope}", curve.integrator);
        }
        // seconds are cumulative
        assert!(curve.native.windows(2).all(|w| w[1].seconds >= w[0].seconds), "{}", curve.integrator);
    }
    let at = |name: &str| c.curves.iter().find(|k| k.integrator == name).unwrap().at(256).unwrap().rmse;
    let worse = at("pt").max(at("nee"));
    for mis in ["mis", "mis-power"] {
        assert!(at(mis) <= worse, "{mis}: {} above max(pt, nee) = {worse}", at(mis));
    }
    round_trips(&c, Convergence::charts);
    assert_eq!(c.charts().len(), convergence::CHARTS.len());
}

/// The emulated points: counted warp instructions that grow with the
/// frames, and images equal to the native ones bit for bit.
#[test]
fn emulated_points_are_counted_and_equal_the_native_frames() {
    let s = scene("cornell-lambert");
    let r = reference("cornell-lambert");
    let o = Options {
        integrators: vec![Integrator::Nee],
        terminations: vec![Termination::Roulette],
        frames: 2,
        emulated_frames: vec![1, 2],
        bounces: 16,
        seed: 3,
    };
    let c = convergence::measure(&s, &r, &o, &mut |_| {}).expect("measured");
    let curve = &c.curves[0];
    assert!(curve.emulated_equals_native);
    let w: Vec<u64> = curve.emulated.iter().map(|p| p.warp_instructions.unwrap()).collect();
    assert!(w[0] > 0 && w[1] > w[0], "{w:?}");
    // the 2-frame emulated image is the native running image of 2 frames
    assert!((curve.emulated[1].rmse - curve.native[1].rmse).abs() <= 1e-6 * curve.native[1].rmse, "{curve:?}");
    // the instruction chart has the emulated points and the reference's floor
    let inst = &c.charts()[2];
    assert_eq!(inst.series[0].points.len(), 2);
    assert!(inst.series.last().unwrap().name.contains("reference"));
}

/// Russian roulette against a fixed depth (003:L269) on the Lambertian box:
/// both endings converge as spp^-1/2 to the same reference (both are
/// unbiased), each pair of curves is labelled apart, roulette adds variance
/// to pt's frames, and a fixed-depth frame costs more than twice the warp
/// instructions of a roulette frame; the emulated frames
/// of both builds equal their native twins. The committed charts' data,
/// written before the ending was recorded, read as roulette.
#[test]
fn roulette_and_fixed_depth_converge_alike_at_different_costs() {
    let s = scene("cornell-lambert");
    let r = reference("cornell-lambert");
    let o = Options {
        integrators: vec![Integrator::Pt, Integrator::Nee],
        terminations: Termination::ALL.to_vec(),
        frames: 64,
        emulated_frames: vec![1],
        bounces: 16,
        seed: 4,
    };
    let c = convergence::measure(&s, &r, &o, &mut |_| {}).expect("measured");
    let labels: Vec<String> = c.curves.iter().map(|k| k.label()).collect();
    assert_eq!(labels, ["pt", "pt, fixed-depth", "nee", "nee, fixed-depth"]);
    for curve in &c.curves {
        assert!(curve.emulated_equals_native, "{}", curve.label());
        let slope = curve.slope(16, c.reference_rmse).expect("a slope");
        assert!((-0.8..=-0.3).contains(&slope), "{}: slope {slope}", curve.label());
        assert!(curve.variance_seconds(c.reference_rmse).expect("a last point") > 0.0);
    }
    // roulette divides by q < 1 what survives: a path's variance can only
    // grow, pt's by more than a third here (58 % in the docs' run), nee's little
    let var = |k: &convergence::Curve| k.frame_variance.expect("independent frames");
    assert!(var(&c.curves[0]) > 1.35 * var(&c.curves[1]), "pt: {} against {}", var(&c.curves[0]), var(&c.curves[1]));
    assert!(var(&c.curves[3]) > 0.0 && var(&c.curves[2]) < 1.35 * var(&c.curves[3]));
    assert!(c.curves.iter().all(|k| k.frame_seconds.is_some_and(|s| s > 0.0) && k.frame_variance_seconds().is_some()));
    let warps = |k: &convergence::Curve| k.emulated[0].warp_instructions.unwrap();
    for k in [0, 2] {
        let (r, f) = (warps(&c.curves[k]), warps(&c.curves[k + 1]));
        assert!(f > 2 * r, "{}: {f} against {r}", c.curves[k].integrator);
    }
    assert_eq!(c.charts()[0].series[3].name, "nee, fixed-depth");
    round_trips(&c, Convergence::charts);
    let old: Convergence = serde_json::from_str(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/images/lin-convergence-cornell-lambert-data.json"),
        )
        .expect("committed data"),
    )
    .expect("reads");
    assert!(old.curves.iter().all(|k| k.termination == Termination::Roulette && k.label() == k.integrator));
}

/// One frame's variance over frames, by hand: a pixel whose channel is 1 and
/// 3 in two frames has variance 2 (unbiased), a constant pixel 0; one frame
/// has none. The mean of all cells: (2 + 0 + 0 + 15) / 6.
#[test]
fn the_frame_variance_is_the_unbiased_one_averaged_over_cells() {
    use warplight::host::image::FrameBuffer;
    use warplight::repro::lin2017::runs::pixel_variance;
    let f = |v: f32| FrameBuffer { width: 2, height: 1, pixels: vec![[v, 0.0, 0.0], [5.0, 5.0, 5.0]] };
    let (v, mean) = pixel_variance(&[f(1.0), f(3.0)]).expect("two frames");
    assert!((v - 2.0 / 6.0).abs() < 1e-12, "{v}");
    assert!((mean - 17.0 / 6.0).abs() < 1e-12, "{mean}");
    assert_eq!(pixel_variance(&[f(1.0)]), None);
}

/// A reference that does not exist is a typed error naming the file.
#[test]
fn a_missing_reference_names_its_file() {
    let e = Reference::read(Path::new("tests/fixtures/mitsuba/no-such-scene-32")).unwrap_err();
    assert!(e.to_string().contains("no-such-scene-32.exr"), "{e}");
}

/// Compaction raises the useful lanes at every level from 2 on that has
/// work for more than a warp (without it the ended paths idle their lanes),
/// never lowers them, and launches exactly the active paths; the paths
/// entering each level are the same in both forms; the data survive JSON.
#[test]
fn compaction_raises_lane_utilisation_from_level_two() {
    let c = lanes::measure(&scene("cornell-lambert"), 16, 12).expect("measured");
    assert_eq!(c.paths, 1024);
    assert_eq!(c.normal.len(), 12);
    assert_eq!(c.compact.len(), 12);
    let mut raised = 0;
    for (n, k) in c.normal.iter().zip(&c.compact) {
        eprintln!(
            "level {}: active {}, useful {:?} -> {:?}",
            n.level,
            n.active,
            n.useful_percent(),
            k.useful_percent()
        );
        assert_eq!(n.active, k.active, "level {}", n.level);
        assert_eq!(n.threads, c.paths, "normal launches every path at level {}", n.level);
        if n.level > 0 {
            assert_eq!(k.threads, k.active, "compaction launches the active paths alone at level {}", n.level);
            assert!(k.threads < n.threads, "level {}", n.level);
        }
        if let (Some(a), Some(b)) = (n.useful_percent(), k.useful_percent()) {
            assert!(b >= a, "level {}: {b} < {a}", n.level);
            if n.level >= 2 && n.active > 64 {
                assert!(b > a + 10.0, "level {}: {a} -> {b}", n.level);
                raised += 1;
            }
        }
    }
    assert!(raised >= 3, "{raised} levels raised");
    round_trips(&c, Compaction::charts);
}
