//! Each scene's first flight frame, rendered by the native reference ray caster
//! at 96 × 96, matches the committed image in reference_images/ (8-bit sRGB,
//! at most one step of difference per channel).

use std::path::Path;

use warplight::host::image::FrameBuffer;
use warplight::host::kdtree::{BuildParams, Heuristic, build};
use warplight::host::raycast::{Caster, render};
use warplight::host::scene_file;

fn check(name: &str) {
    let scene = scene_file::load(Path::new(&format!("scenes/{name}.toml"))).unwrap();
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Sah));
    let caster = Caster::new(&scene, &tree);
    let mut cam = scene.flight.camera(&scene.camera, 0);
    cam.resolution = [96, 96];
    let (fb, st) = render(&caster, &cam, scene.flight.light_offset(0));
    assert_eq!(st.primary, 96 * 96);
    let got = fb.to_srgb8(0.0);
    let reference = FrameBuffer::read_png(Path::new(&format!("reference_images/{name}.png"))).unwrap();
    let want = reference.to_srgb8(0.0);
    assert_eq!(got.len(), want.len());
    let worst = got.iter().zip(&want).map(|(a, b)| (*a as i32 - *b as i32).abs()).max().unwrap();
    assert!(worst <= 1, "{name}: a channel differs by {worst} steps");
    assert!(got.iter().any(|&b| b > 40), "{name}: the image is not black");
}

#[test]
fn small_scenes_match_their_references() {
    for s in ["cornell-box", "scene6", "passage", "ring", "ring-volumetric"] {
        check(s);
    }
}

#[test]
fn large_scenes_match_their_references() {
    for s in ["sponza", "sibenik", "conference"] {
        check(s);
    }
}
