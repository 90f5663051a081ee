//! `warplight scene info NAME`.

use std::path::PathBuf;

use crate::host::scene::{Light, MaterialKind};
use crate::host::scene_file;

/// Resolves a scene name (`sponza`) or path (`scenes/sponza.toml`): [`scene_file::resolve`].
pub fn scene_path(name: &str) -> PathBuf {
    scene_file::resolve(name)
}

/// Prints a scene's summary.
pub fn info(name: &str) -> Result<(), Box<dyn std::error::Error>> {
    let s = scene_file::load(&scene_path(name))?;
    let e = s.extent();
    println!("scene {} ({})", s.name, s.source.display());
    match s.thesis {
        Some(t) => {
            let d = s.triangles.len() as f64 / t.triangles as f64 * 100.0 - 100.0;
            println!("  triangles  {:>9}   thesis {:>9}   ({d:+.1}%)", s.triangles.len(), t.triangles);
            println!(
                "  extent     {:.2} x {:.2} x {:.2} m   thesis {:.1} x {:.1} x {:.1} m",
                e[0], e[1], e[2], t.extent[0], t.extent[1], t.extent[2]
            );
        }
        None => {
            println!("  triangles  {:>9}", s.triangles.len());
            println!("  extent     {:.2} x {:.2} x {:.2} m", e[0], e[1], e[2]);
        }
    }
    if s.dropped_degenerate > 0 {
        println!("  dropped    {:>9} zero-area triangles", s.dropped_degenerate);
    }
    if !s.variant.is_empty() {
        println!("  variant    {}", s.variant);
    }
    let (lo, hi) = s.bounds();
    println!("  bounds     [{:.2}, {:.2}, {:.2}] .. [{:.2}, {:.2}, {:.2}]", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    println!("  materials  {}", s.materials.len());
    for (i, m) in s.materials.iter().enumerate() {
        let n = s.triangles.iter().filter(|t| t.material as usize == i).count();
        let kind = match m.kind {
            MaterialKind::Diffuse => "diffuse".to_string(),
            MaterialKind::Mirror => "mirror".to_string(),
            MaterialKind::Glass { ior } => format!("glass (ior {ior})"),
            MaterialKind::Emitter => format!("emitter {:?}", m.emission),
        };
        println!("    {:<16} {:<18} colour {:?}  {n} triangles", m.name, kind, m.color);
    }
    println!("  lights     {}", s.lights.len());
    for l in &s.lights {
        match l {
            Light::Point { position, intensity } => println!("    point at {position:?}, intensity {intensity:?}"),
            Light::Directional { direction, radiance } => println!("    directional {direction:?}, {radiance:?}"),
            Light::Area { triangles } => println!("    area light of {} emissive triangles", triangles.len()),
        }
    }
    let c = &s.camera;
    println!(
        "  camera     at {:?} looking {:?}, up {:?}, fov {}°, {}x{}",
        c.position, c.direction, c.up, c.fov_y, c.resolution[0], c.resolution[1]
    );
    let f = &s.flight;
    println!(
        "  flight     {} frames, +{} m and {}° right per frame, light {}",
        f.frames,
        f.forward,
        f.yaw_deg,
        if f.move_light { format!("moves {:?} m per frame", f.light_step) } else { "fixed".into() }
    );
    Ok(())
}
