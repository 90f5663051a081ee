//! `warplight scene info NAME`.

use std::path::PathBuf;

use crate::host::scene::{Light, MaterialKind, Scene};
use crate::host::scene_file;

/// Resolves a scene name (`sponza`) or path (`scenes/sponza.toml`): [`scene_file::resolve`].
pub fn scene_path(name: &str) -> PathBuf {
    scene_file::resolve(name)
}

/// Prints a scene's summary ([`summary`]).
pub fn info(name: &str) -> Result<(), Box<dyn std::error::Error>> {
    let s = scene_file::load(&scene_path(name))?;
    print!("{}", summary(&s));
    Ok(())
}

/// A channel triple as `[a, b, c]` with at most three decimals.
fn triple(c: [f32; 3]) -> String {
    let f = |x: f32| {
        let t = format!("{x:.3}");
        let t = t.trim_end_matches('0').trim_end_matches('.');
        if t.is_empty() || t == "-" { "0".to_string() } else { t.to_string() }
    };
    format!("[{}, {}, {}]", f(c[0]), f(c[1]), f(c[2]))
}

/// A scene's summary as `warplight scene info` prints it: triangles and
/// extent beside the thesis', materials (kind, colour, diffuse texture map,
/// the weight of the mirror reflection a hit adds — [`Scene::reflectance`] —
/// and triangles), texture maps with their sizes, lights, camera and flight.
pub fn summary(s: &Scene) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let e = s.extent();
    // writing to a String cannot fail
    let mut line = |t: String| {
        let _ = writeln!(o, "{t}");
    };
    line(format!("scene {} ({})", s.name, s.source.display()));
    match s.thesis {
        Some(t) => {
            let d = s.triangles.len() as f64 / t.triangles as f64 * 100.0 - 100.0;
            line(format!("  triangles  {:>9}   thesis {:>9}   ({d:+.1}%)", s.triangles.len(), t.triangles));
            line(format!(
                "  extent     {:.2} x {:.2} x {:.2} m   thesis {:.1} x {:.1} x {:.1} m",
                e[0], e[1], e[2], t.extent[0], t.extent[1], t.extent[2]
            ));
        }
        None => {
            line(format!("  triangles  {:>9}", s.triangles.len()));
            line(format!("  extent     {:.2} x {:.2} x {:.2} m", e[0], e[1], e[2]));
        }
    }
    if s.dropped_degenerate > 0 {
        line(format!("  dropped    {:>9} zero-area triangles", s.dropped_degenerate));
    }
    if !s.variant.is_empty() {
        line(format!("  variant    {}", s.variant));
    }
    let (lo, hi) = s.bounds();
    line(format!("  bounds     [{:.2}, {:.2}, {:.2}] .. [{:.2}, {:.2}, {:.2}]", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z));
    let mut per_material = vec![0usize; s.materials.len()];
    for t in &s.triangles {
        if let Some(n) = per_material.get_mut(t.material as usize) {
            *n += 1;
        }
    }
    let reflecting = (0..s.materials.len()).filter(|&m| s.reflectance(m as u32).iter().any(|&w| w > 0.0)).count();
    let textured = (0..s.materials.len()).filter(|&m| s.surface(m as u32).texture.is_some()).count();
    line(format!(
        "  materials  {} ({textured} textured, {reflecting} reflecting: a hit traces a mirror ray weighted per channel)",
        s.materials.len()
    ));
    let width = s.materials.iter().map(|m| m.name.chars().count()).max().unwrap_or(0).max(16);
    for (i, m) in s.materials.iter().enumerate() {
        let kind = match m.kind {
            MaterialKind::Diffuse => match s.coat(i as u32) {
                Some(ior) => format!("coated (ior {ior})"),
                None => "diffuse".to_string(),
            },
            MaterialKind::Mirror => "mirror".to_string(),
            MaterialKind::Glass { ior } => format!("glass (ior {ior})"),
            MaterialKind::Emitter => format!("emitter {}", triple(m.emission)),
        };
        let surface = s.surface(i as u32);
        let texture = match surface.texture.and_then(|t| s.textures.get(t as usize)) {
            Some(t) => format!("  texture {}", t.name),
            None => String::new(),
        };
        let r = s.reflectance(i as u32);
        let reflect = if r.iter().any(|&w| w > 0.0) { format!("  reflect {}", triple(r)) } else { String::new() };
        line(format!(
            "    {:<width$} {:<18} colour {}  {} triangles{texture}{reflect}",
            m.name,
            kind,
            triple(m.color),
            per_material[i]
        ));
    }
    let bytes: usize = s.textures.iter().map(|t| t.texels.len() * 4).sum();
    line(format!("  textures   {} ({:.1} MB of 32-bit texels)", s.textures.len(), bytes as f64 / 1e6));
    for t in &s.textures {
        let users: Vec<&str> = (0..s.materials.len())
            .filter(|&m| s.surface(m as u32).texture.is_some_and(|x| s.textures.get(x as usize) == Some(t)))
            .map(|m| s.materials[m].name.as_str())
            .collect();
        line(format!(
            "    {:<24} {:>5} x {:<5} {:>6.2} MB  used by {}",
            t.name,
            t.width,
            t.height,
            (t.texels.len() * 4) as f64 / 1e6,
            if users.is_empty() { "none".to_string() } else { users.join(", ") }
        ));
    }
    line(format!("  lights     {}", s.lights.len()));
    for l in &s.lights {
        match l {
            Light::Point { position, intensity } => line(format!("    point at {position:?}, intensity {intensity:?}")),
            Light::Directional { direction, radiance } => line(format!("    directional {direction:?}, {radiance:?}")),
            Light::Area { triangles } => line(format!("    area light of {} emissive triangles", triangles.len())),
        }
    }
    let c = &s.camera;
    line(format!(
        "  camera     at {:?} looking {:?}, up {:?}, fov {}°, {}x{}",
        c.position, c.direction, c.up, c.fov_y, c.resolution[0], c.resolution[1]
    ));
    let f = &s.flight;
    line(format!(
        "  flight     {} frames, +{} m and {}° right per frame, light {}",
        f.frames,
        f.forward,
        f.yaw_deg,
        if f.move_light { format!("moves {:?} m per frame", f.light_step) } else { "fixed".into() }
    ));
    o
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glam::Vec3;

    use super::summary;
    use crate::host::scene::{Material, MaterialKind, Scene, Surface, Texture, Triangle};

    /// A scene of three triangles: a textured diffuse material with a specular
    /// part, a mirror and a plain diffuse one.
    fn scene() -> Scene {
        let tri = |m| Triangle { v: [Vec3::ZERO, Vec3::X, Vec3::Y], material: m };
        let mats = vec![
            Material::diffuse("marble", [0.5, 0.25, 1.0]),
            Material { name: "glass".into(), kind: MaterialKind::Mirror, color: [0.8, 0.8, 0.8], emission: [0.0; 3] },
            Material::diffuse("plain", [1.0, 1.0, 1.0]),
        ];
        let mut s = Scene::assemble("t", Path::new("t.toml"), vec![tri(0), tri(0), tri(1)], mats);
        s.textures =
            vec![Texture { name: "textures/m.png".into(), width: 512, height: 256, texels: vec![0; 512 * 256] }];
        s.surfaces = vec![Surface { texture: Some(0), reflect: [0.25, 0.25, 0.125], ..Default::default() }];
        s
    }

    #[test]
    fn lists_textures_with_their_sizes_and_reflection_weights_per_material() {
        let out = summary(&scene());
        let line = |name: &str| out.lines().find(|l| l.trim_start().starts_with(name)).unwrap_or_default().to_string();
        assert!(out.contains("materials  3 (1 textured, 2 reflecting"), "{out}");
        let marble = line("marble");
        assert!(
            marble.contains("2 triangles")
                && marble.contains("texture textures/m.png")
                && marble.contains("reflect [0.25, 0.25, 0.125]"),
            "{marble}"
        );
        // a mirror reflects with its colour and has no texture
        let glass = line("glass");
        assert!(glass.contains("reflect [0.8, 0.8, 0.8]") && !glass.contains("texture"), "{glass}");
        let plain = line("plain");
        assert!(plain.contains("0 triangles") && !plain.contains("reflect") && !plain.contains("texture"), "{plain}");
        // 512 x 256 texels of 4 bytes
        assert!(out.contains("textures   1 (0.5 MB of 32-bit texels)"), "{out}");
        let tex = line("textures/m.png");
        assert!(tex.contains("512 x 256") && tex.contains("0.52 MB") && tex.ends_with("used by marble"), "{tex}");
    }

    #[test]
    fn a_scene_without_textures_says_so() {
        let mut s = scene();
        s.textures.clear();
        s.surfaces.clear();
        let out = summary(&s);
        assert!(
            out.contains("materials  3 (0 textured, 1 reflecting") && out.contains("textures   0 (0.0 MB"),
            "{out}"
        );
    }
}
