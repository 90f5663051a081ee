//! Thesis 003's Fig. 6 (003:L286-288): MIS at 10 frames against BSDF
//! sampling alone at 100, the error per region (`warplight tables
//! lin:fig6`). The recorded errors and verdicts, and the checks following
//! the evidence.

mod lin2017_tables;
use lin2017_tables::{assert_recorded, checks_of, load, table_named};
use warplight::host::camera::Camera;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::repro::lin2017::fig_6::{self, MIS_BSDF, SCENE};
use warplight::repro::registry::Workspace;
use warplight::repro::results::Sample;
use warplight::repro::table::Table;

fn table_of(samples: &[Sample]) -> Table {
    table_named("lin:fig6", MIS_BSDF, samples)
}

/// Per row (MIS at 10 frames, BSDF sampling at 100): RMS error on the back
/// wall, on the floor and ceiling, over the image.
const RECORDED: [[f64; 3]; 2] = [[0.0543, 0.1651, 0.1135], [0.1204, 0.0825, 0.0884]];

#[test]
fn fig6_records_its_errors_and_checks() {
    let scene = load(SCENE);
    let mut ws = Workspace::new(&scene, 0..1, 32);
    let mut samples = fig_6::measure(&mut ws, &mut |_| {}).expect("measure");
    let t = table_of(&samples);
    let holds = checks_of(&t);
    assert_recorded(&t, &RECORDED, |g, w| (g - w).abs() < 5e-5);
    assert_eq!(holds, [true, true, true]);

    // the two estimators' errors swapped: both claims fail
    for s in &mut samples {
        s.variant = match s.variant.as_str() {
            "mis" => "bsdf".into(),
            "bsdf" => "mis".into(),
            other => other.into(),
        };
    }
    assert_eq!(table_of(&samples).checks.iter().map(|c| c.holds).collect::<Vec<_>>(), [false, false, true]);
}

/// The regions are the materials the camera sees first: every back-wall
/// pixel's ray hits the rough mirror, and the regions are where the box is.
#[test]
fn regions_are_the_first_hits_materials() {
    let scene = load(SCENE);
    let camera = Camera { resolution: [16, 16], ..scene.camera };
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    let r = fig_6::regions(&scene, &camera, &tree);
    // at 16 x 16: the ceiling along the top, the back wall in the middle,
    // the floor at the bottom left (the short box at the bottom centre), the red wall on the left
    let at = |x: u32, y: u32| r[(y * 16 + x) as usize];
    assert_eq!(at(8, 0), Some(1), "top: the ceiling");
    assert_eq!(at(8, 4), Some(0), "middle: the back wall");
    assert_eq!(at(2, 15), Some(1), "bottom left: the floor");
    assert_eq!(at(8, 15), None, "bottom centre: the short box");
    assert_eq!(at(0, 8), None, "left: the red wall");
    assert_eq!(r.iter().filter(|&&x| x == Some(0)).count(), 66);
}
