//! Reads `scenes/*.toml` scene descriptions (format: `docs/scenes.md`).
//! Every field is validated; errors name the file, the key and what was expected.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::camera::{Camera, Flight};
use super::procedural;
use super::scene::{
    Jitter, Light, Material, MaterialKind, Medium, Scene, Surface, Texture, ThesisScene, Translucent, Triangle,
};

/// A scene file that could not be loaded.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {}{msg}", if key == "-" { String::new() } else { format!("{key}: ") })]
pub struct SceneError {
    /// The file.
    pub file: String,
    /// The key (or `-` for the file as a whole).
    pub key: String,
    /// What was expected or what failed.
    pub msg: String,
}

/// The smallest positive Beckmann α a scene may give (`roughness`; 0 is a
/// smooth surface). Mitsuba 3 clamps α to it; below it the rough BSDF's
/// pdf turns NaN or infinite in f32.
pub const MIN_ROUGHNESS: f32 = 1e-4;

static SCENES_FLAG: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();

/// Sets the folder of `--scene-dir DIR`, searched before every other (once, before any work).
pub fn set_scene_dir(dir: PathBuf) {
    let _ = SCENES_FLAG.set(dir);
}

/// The folders a scene name (`sponza`) is looked up in, in order: the
/// `--scene-dir DIR` folder, `scenes/` in the current directory,
/// `$WARPLIGHT_HOME/scenes`, and the `scenes/` of the checkout warplight was
/// built from (so that `cargo install --path .` gives a binary that finds
/// them from anywhere while the checkout exists).
pub fn scene_dirs() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = SCENES_FLAG.get().cloned().into_iter().collect();
    v.push(PathBuf::from("scenes"));
    if let Some(h) = std::env::var_os("WARPLIGHT_HOME") {
        v.push(Path::new(&h).join("scenes"));
    }
    v.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"));
    v
}

/// A data file of the distribution (`tests/fixtures/h100_micro.json`,
/// `kernels/micro/micro.ptx`) named relative to the checkout: the path as
/// given when it exists (or is absolute), else under `$WARPLIGHT_HOME`, else
/// under the checkout warplight was built from; the path as given when none
/// has it, so that the error names it.
pub fn data_file(rel: &Path) -> PathBuf {
    if rel.is_absolute() || rel.exists() {
        return rel.to_path_buf();
    }
    let home = std::env::var_os("WARPLIGHT_HOME").map(|h| Path::new(&h).join(rel));
    home.into_iter()
        .chain([Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)])
        .find(|p| p.exists())
        .unwrap_or_else(|| rel.to_path_buf())
}

/// Resolves a scene name (`sponza`: `NAME.toml` in the first of
/// [`scene_dirs`] that has it) or a path (`scenes/sponza.toml`, anything with
/// an extension or that exists). A name found nowhere resolves to
/// `scenes/NAME.toml`, so that the error names the file.
pub fn resolve(name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.extension().is_some() || p.exists() {
        return p.to_path_buf();
    }
    let file = format!("{name}.toml");
    scene_dirs()
        .into_iter()
        .map(|d| d.join(&file))
        .find(|f| f.is_file())
        .unwrap_or_else(|| Path::new("scenes").join(file))
}

struct Cx<'a> {
    file: &'a str,
}

impl Cx<'_> {
    fn err<T>(&self, key: &str, msg: impl Into<String>) -> Result<T, SceneError> {
        Err(SceneError { file: self.file.into(), key: key.into(), msg: msg.into() })
    }

    fn num(&self, v: &toml::Value, key: &str) -> Result<f32, SceneError> {
        let x = match v {
            toml::Value::Float(f) => *f as f32,
            toml::Value::Integer(i) => *i as f32,
            _ => return self.err(key, "expected a number"),
        };
        // NaN and infinities (and floats past f32) made black images with exit 0
        if !x.is_finite() {
            return self.err(key, format!("{v} is not a finite number"));
        }
        Ok(x)
    }

    fn vec3(
        &self,
        t: &toml::Table,
        key: &str,
        prefix: &str,
        default: Option<[f32; 3]>,
    ) -> Result<[f32; 3], SceneError> {
        let k = format!("{prefix}{key}");
        match t.get(key) {
            None => default.map_or_else(|| self.err(&k, "missing; expected [x, y, z]"), Ok),
            Some(toml::Value::Array(a)) if a.len() == 3 => {
                Ok([self.num(&a[0], &k)?, self.num(&a[1], &k)?, self.num(&a[2], &k)?])
            }
            Some(_) => self.err(&k, "expected [x, y, z]"),
        }
    }

    fn float(&self, t: &toml::Table, key: &str, prefix: &str, default: f32) -> Result<f32, SceneError> {
        t.get(key).map_or(Ok(default), |v| self.num(v, &format!("{prefix}{key}")))
    }

    fn table<'t>(&self, t: &'t toml::Table, key: &str) -> Result<Option<&'t toml::Table>, SceneError> {
        match t.get(key) {
            None => Ok(None),
            Some(toml::Value::Table(x)) => Ok(Some(x)),
            Some(_) => self.err(key, "expected a table"),
        }
    }

    fn tables<'t>(&self, t: &'t toml::Table, key: &str) -> Result<Vec<&'t toml::Table>, SceneError> {
        match t.get(key) {
            None => Ok(Vec::new()),
            Some(toml::Value::Array(a)) => a
                .iter()
                .enumerate()
                .map(|(i, v)| v.as_table().map_or_else(|| self.err(&format!("{key}[{i}]"), "expected a table"), Ok))
                .collect(),
            Some(_) => self.err(key, format!("expected [[{key}]] tables")),
        }
    }
}

/// A diffuse material's texture maps as its scene file names them (thesis 003
/// §5.4): albedo, roughness and metalness maps, and a planar mapping for
/// triangles without texture coordinates.
#[derive(Debug, Default, Clone, PartialEq)]
struct Maps {
    albedo: Option<String>,
    roughness: Option<String>,
    metalness: Option<String>,
    /// `planar = { origin, u, v }`: texture coordinates ((p − origin)·u, (p − origin)·v).
    planar: Option<[[f32; 3]; 3]>,
}

/// The keys of a material's texture maps.
const MAP_KEYS: [&str; 4] = ["albedo_map", "roughness_map", "metalness_map", "planar"];

/// A material's texture maps (`albedo_map`, `roughness_map`, `metalness_map`,
/// `planar`; diffuse materials only).
fn maps(cx: &Cx, t: &toml::Table, p: &str, kind: MaterialKind) -> Result<Maps, SceneError> {
    if let Some(k) = MAP_KEYS.iter().find(|k| t.contains_key(**k))
        && kind != MaterialKind::Diffuse
    {
        return cx.err(&format!("{p}{k}"), "only a diffuse material has texture maps");
    }
    let file = |key: &str| -> Result<Option<String>, SceneError> {
        match t.get(key) {
            None => Ok(None),
            Some(v) => v.as_str().map(|f| Some(f.to_string())).map_or_else(
                || cx.err(&format!("{p}{key}"), "expected the file name of a PNG map (relative to the scene file)"),
                Ok,
            ),
        }
    };
    let planar = match t.get("planar") {
        None => None,
        Some(toml::Value::Table(pl)) => {
            let k = format!("{p}planar.");
            Some([cx.vec3(pl, "origin", &k, None)?, cx.vec3(pl, "u", &k, None)?, cx.vec3(pl, "v", &k, None)?])
        }
        Some(_) => {
            return cx.err(&format!("{p}planar"), "expected { origin = [x, y, z], u = [x, y, z], v = [x, y, z] }");
        }
    };
    Ok(Maps {
        albedo: file("albedo_map")?,
        roughness: file("roughness_map")?,
        metalness: file("metalness_map")?,
        planar,
    })
}

/// What a scene file says of a material beyond [`Material`]: what only
/// thesis 003's path tracer reads.
struct MaterialExtras {
    /// Beckmann roughness α and the anisotropic lobe's α_y ([`roughness_of`]).
    roughness: [f32; 2],
    /// `fresnel = "exact"`.
    exact: bool,
    /// A translucent material's subsurface scattering.
    translucent: Option<Translucent>,
    /// Texture maps.
    maps: Maps,
    /// A coated material's IOR (`kind = "coated"`, [`Scene::coat`]).
    coat: Option<f32>,
}

/// A material, its Beckmann roughness (`roughness`, mirrors and glass, and
/// the metal lobe of a diffuse material with a metalness map; 0 is smooth),
/// whether its Fresnel term is exact (`fresnel = "exact"`, glass and
/// translucent only; `"schlick"` the default), for a translucent material
/// (`kind = "translucent"`, a glass to every other renderer) its subsurface
/// scattering, its texture maps, and for a coated material (`kind =
/// "coated"`, thesis 003's dielectric over Ashikhmin and Shirley's diffuse, a
/// diffuse material to every other renderer) its coat's `ior`. `text` is the
/// file's text, for the lines the translucent keys' errors name.
fn material(cx: &Cx, t: &toml::Table, i: usize, text: &str) -> Result<(Material, MaterialExtras), SceneError> {
    let p = format!("material[{i}].");
    let name = match t.get("name").and_then(|v| v.as_str()) {
        Some(n) => n.to_string(),
        None => return cx.err(&format!("{p}name"), "missing"),
    };
    if let Some(k) = t.keys().find(|k| !MATERIAL_KEYS.contains(&k.as_str())) {
        return cx.err(&format!("{p}{k}"), format!("unknown key; a material takes {}", MATERIAL_KEYS.join(", ")));
    }
    let kind_name = t.get("kind").and_then(|v| v.as_str()).unwrap_or("diffuse");
    if t.contains_key("ior") && !matches!(kind_name, "glass" | "translucent" | "coated") {
        return cx.err(
            &format!("{p}ior"),
            format!(
                "a {kind_name} material has no index of refraction (glass, translucent and coated ones have; \
                 kind = \"coated\" is thesis 003's diffuse under a dielectric coat)"
            ),
        );
    }
    let kind = match kind_name {
        "diffuse" | "coated" => MaterialKind::Diffuse,
        "mirror" => MaterialKind::Mirror,
        "glass" | "translucent" => MaterialKind::Glass { ior: cx.float(t, "ior", &p, 1.5)? },
        "emitter" => MaterialKind::Emitter,
        other => {
            return cx.err(
                &format!("{p}kind"),
                format!("`{other}`; expected diffuse, coated, mirror, glass, translucent or emitter"),
            );
        }
    };
    let coat = if kind_name == "coated" { Some(coat_of(cx, t, &p)?) } else { None };
    let translucent = translucent(cx, t, i, text, kind_name == "translucent")?;
    if translucent.is_some() && t.contains_key("roughness") {
        return cx.err(&format!("{p}roughness"), "a translucent material's boundary is smooth: no roughness");
    }
    let (roughness, roughness_y) = roughness_of(cx, t, &p, kind)?;
    let maps = maps(cx, t, &p, kind)?;
    let metal_lobe = maps.metalness.is_some();
    if t.contains_key("roughness") && !matches!(kind, MaterialKind::Mirror | MaterialKind::Glass { .. }) && !metal_lobe
    {
        return cx.err(
            &format!("{p}roughness"),
            "only a mirror, glass or a diffuse material with a metalness_map has a roughness",
        );
    }
    if maps.roughness.is_some() && !metal_lobe {
        return cx
            .err(&format!("{p}roughness_map"), "a roughness map shapes the metal lobe only: give a metalness_map too");
    }
    if metal_lobe && maps.roughness.is_none() && roughness <= 0.0 {
        return cx.err(
            &format!("{p}metalness_map"),
            "the metal lobe needs a roughness_map or a roughness (a Beckmann alpha from 1e-4 to 1)",
        );
    }
    // α² underflows in f32 below about 1e-19 and the pdf squared overflows from
    // about 1e-11: NaN pixels under MIS. Mitsuba 3 clamps α to 1e-4.
    if roughness > 0.0 && roughness < MIN_ROUGHNESS {
        return cx.err(
            &format!("{p}roughness"),
            format!(
                "material `{name}`: {roughness:e} is below {MIN_ROUGHNESS:e}, the smallest Beckmann alpha \
                 (Mitsuba's floor too); use 0 for a smooth surface"
            ),
        );
    }
    if !(0.0..=1.0).contains(&roughness) {
        return cx.err(&format!("{p}roughness"), "expected a Beckmann alpha between 0 and 1");
    }
    let exact = match t.get("fresnel") {
        None => false,
        Some(_) if !matches!(kind, MaterialKind::Glass { .. }) => {
            return cx
                .err(&format!("{p}fresnel"), "only glass and translucent materials have a Fresnel term to choose");
        }
        Some(v) => match v.as_str() {
            Some("schlick") => false,
            Some("exact") => true,
            _ => return cx.err(&format!("{p}fresnel"), "expected \"schlick\" or \"exact\""),
        },
    };
    let m = Material {
        name,
        kind,
        color: cx.vec3(t, "color", &p, Some([0.8; 3]))?,
        emission: cx.vec3(t, "emission", &p, Some([0.0; 3]))?,
    };
    Ok((m, MaterialExtras { roughness: [roughness, roughness_y], exact, translucent, maps, coat }))
}

/// Every key a `[[material]]` table may have (each kind takes a part of them).
const MATERIAL_KEYS: [&str; 16] = [
    "name",
    "kind",
    "color",
    "emission",
    "ior",
    "roughness",
    "fresnel",
    "albedo_map",
    "roughness_map",
    "metalness_map",
    "planar",
    "sigma_s",
    "sigma_a",
    "albedo",
    "g",
    "translucency",
];

/// The keys a coated material may not have: its coat is smooth, its Fresnel
/// term Schlick's, and it has no texture maps (not built).
const NOT_COATED_KEYS: [&str; 6] = ["roughness", "fresnel", "albedo_map", "roughness_map", "metalness_map", "planar"];

/// A coated material's coat (`kind = "coated"`, thesis 003 §4.5, 003:L255-263):
/// its `ior` (default 1.5), from which Schlick's R0 comes.
fn coat_of(cx: &Cx, t: &toml::Table, p: &str) -> Result<f32, SceneError> {
    if let Some(k) = NOT_COATED_KEYS.iter().find(|k| t.contains_key(**k)) {
        return cx.err(
            &format!("{p}{k}"),
            "a coated material is a smooth dielectric coat (Schlick's Fresnel) over Ashikhmin and Shirley's diffuse: \
             no roughness, fresnel, texture maps or planar mapping",
        );
    }
    let ior = cx.float(t, "ior", p, 1.5)?;
    if !(ior > 0.0 && ior.is_finite()) {
        return cx.err(&format!("{p}ior"), format!("{ior}: expected the coat's index of refraction, > 0"));
    }
    Ok(ior)
}

/// A material's `roughness`: one Beckmann α (isotropic), or for a mirror or
/// a glass `[ax, ay]`, thesis 003's anisotropic lobe (§5.1, 003:L346-352) with α_x
/// along the first and α_y along the second axis of the tangent frame
/// (`docs/reproduction-lin2017.md`, "Anisotropic mirrors"). The second value
/// is 0 when the lobe is isotropic (a number, or two equal values).
fn roughness_of(cx: &Cx, t: &toml::Table, p: &str, kind: MaterialKind) -> Result<(f32, f32), SceneError> {
    let k = format!("{p}roughness");
    match t.get("roughness") {
        Some(toml::Value::Array(a)) => {
            if a.len() != 2 {
                return cx.err(&k, "expected a Beckmann alpha, or [ax, ay] for an anisotropic mirror or glass");
            }
            if !matches!(kind, MaterialKind::Mirror | MaterialKind::Glass { .. }) {
                return cx.err(
                    &k,
                    "an anisotropic roughness [ax, ay] is a mirror's or a glass's only; the metal lobe of a diffuse \
                     material takes one alpha",
                );
            }
            let (ax, ay) = (cx.num(&a[0], &k)?, cx.num(&a[1], &k)?);
            for v in [ax, ay] {
                if !(MIN_ROUGHNESS..=1.0).contains(&v) {
                    return cx.err(
                        &k,
                        format!("{v:e}: each alpha of [ax, ay] lies between {MIN_ROUGHNESS:e} and 1 (a smooth mirror has roughness 0)"),
                    );
                }
            }
            Ok((ax, if ax == ay { 0.0 } else { ay }))
        }
        _ => Ok((cx.float(t, "roughness", p, 0.0)?, 0.0)),
    }
}

/// The keys only a translucent material has.
const TRANSLUCENT_KEYS: [&str; 5] = ["sigma_s", "sigma_a", "albedo", "g", "translucency"];

/// The line of `key` in the `i`-th `[[material]]` table of `text` (1-based; the
/// table's header line if the key is not written there; 0 if the file has no
/// such `[[material]]` header), for the translucent keys' errors.
fn material_line(text: &str, i: usize, key: &str) -> usize {
    table_line(text, "[[material]]", i, key)
}

/// A translucent material's subsurface scattering (thesis 003 §5.3): `sigma_s`
/// (grey), `sigma_a` or `albedo` = σ_s / (σ_s + σ_a) (a number or [r, g, b]),
/// `g` (default 0), `translucency` (default 1). `None` for any other kind,
/// which may not give these keys.
fn translucent(cx: &Cx, t: &toml::Table, i: usize, text: &str, is: bool) -> Result<Option<Translucent>, SceneError> {
    let at = |key: &str| match material_line(text, i, key) {
        0 => format!("material[{i}].{key}"),
        n => format!("material[{i}].{key} (line {n})"),
    };
    if !is {
        return match TRANSLUCENT_KEYS.iter().find(|k| t.contains_key(**k)) {
            Some(k) => cx.err(&at(k), "only a translucent material (kind = \"translucent\") has it"),
            None => Ok(None),
        };
    }
    let rgb = |key: &str| -> Result<Option<[f32; 3]>, SceneError> {
        match t.get(key) {
            None => Ok(None),
            Some(toml::Value::Array(a)) if a.len() == 3 => {
                Ok(Some([cx.num(&a[0], &at(key))?, cx.num(&a[1], &at(key))?, cx.num(&a[2], &at(key))?]))
            }
            Some(toml::Value::Array(_)) => cx.err(&at(key), "expected a number or [r, g, b]"),
            Some(v) => cx.num(v, &at(key)).map(|x| Some([x; 3])),
        }
    };
    let Some(sigma_s) = t.get("sigma_s").map(|v| cx.num(v, &at("sigma_s"))).transpose()? else {
        return cx.err(&at("sigma_s"), "missing; a translucent material needs its scattering coefficient");
    };
    if sigma_s < 0.0 {
        return cx.err(&at("sigma_s"), format!("{sigma_s} is negative; expected a coefficient >= 0 (per unit length)"));
    }
    let sigma_a = match (rgb("sigma_a")?, rgb("albedo")?) {
        (Some(_), Some(_)) => return cx.err(&at("albedo"), "give either sigma_a or albedo, not both"),
        (None, None) => return cx.err(&at("sigma_a"), "missing; give sigma_a or albedo"),
        (Some(a), None) => {
            if let Some(x) = a.iter().find(|x| **x < 0.0) {
                return cx
                    .err(&at("sigma_a"), format!("{x} is negative; expected coefficients >= 0 (per unit length)"));
            }
            a
        }
        (None, Some(al)) => {
            if let Some(x) = al.iter().find(|x| !(**x > 0.0 && **x <= 1.0)) {
                return cx
                    .err(&at("albedo"), format!("{x}: expected an albedo sigma_s / (sigma_s + sigma_a) in (0, 1]"));
            }
            if sigma_s <= 0.0 {
                return cx.err(&at("albedo"), "an albedo needs sigma_s > 0 (sigma_a = sigma_s (1 - albedo) / albedo)");
            }
            al.map(|a| sigma_s * (1.0 - a) / a)
        }
    };
    let g = cx.float(t, "g", &format!("material[{i}]."), 0.0).map_err(|mut e| {
        e.key = at("g");
        e
    })?;
    if !(g > -1.0 && g < 1.0) {
        return cx.err(&at("g"), format!("{g}: the Henyey-Greenstein asymmetry must lie strictly between -1 and 1"));
    }
    let translucency = t.get("translucency").map(|v| cx.num(v, &at("translucency"))).transpose()?.unwrap_or(1.0);
    if !(0.0..=1.0).contains(&translucency) {
        return cx.err(&at("translucency"), format!("{translucency}: expected a probability in [0, 1]"));
    }
    let ior = cx.float(t, "ior", &format!("material[{i}]."), 1.5)?;
    if ior.is_nan() || ior <= 0.0 {
        return cx.err(&at("ior"), format!("{ior}: expected an index of refraction > 0"));
    }
    Ok(Some(Translucent { sigma_s, sigma_a, g, translucency }))
}

/// The line of `key` in the `[medium]` table of `text` (1-based; the table's header line if
/// the key is not written there), for the medium's errors.
fn medium_line(text: &str, key: &str) -> usize {
    table_line(text, "[medium]", 0, key)
}

/// The line of `key` in the `i`-th table headed `header` (`[medium]`,
/// `[[material]]`) of `text` (1-based; the header's line if the key is not
/// written there; 0 without such a table).
fn table_line(text: &str, header: &str, i: usize, key: &str) -> usize {
    let (mut seen, mut at) = (0usize, 0);
    for (n, l) in text.lines().enumerate() {
        let l = l.trim();
        if l.starts_with('[') {
            if at > 0 {
                break;
            }
            if l == header {
                if seen == i {
                    at = n + 1;
                }
                seen += 1;
            }
        } else if at > 0 && l.split('=').next().map(str::trim) == Some(key) {
            return n + 1;
        }
    }
    at
}

/// The most march steps across the medium's box (its diagonal over the step): the
/// kernel's `MEDIUM_MAX_STEPS` per ray segment.
pub const MAX_MEDIUM_STEPS: f32 = 1023.0;

/// A participating medium (`[medium]`, thesis 003 §5.2; `docs/scenes.md`).
fn medium(cx: &Cx, m: &toml::Table, text: &str) -> Result<Medium, SceneError> {
    let at = |key: &str| format!("medium.{key} (line {})", medium_line(text, key));
    let bad = |key: &str, msg: String| -> Result<Medium, SceneError> { cx.err(&at(key), msg) };
    for k in m.keys() {
        if !["sigma_a", "sigma_s", "g", "emission", "height_scale", "box", "step", "jitter"].contains(&k.as_str()) {
            return bad(
                k,
                format!("unknown key `{k}`; expected sigma_a, sigma_s, g, emission, height_scale, box, step or jitter"),
            );
        }
    }
    let num = |key: &str, default: Option<f32>| -> Result<f32, SceneError> {
        match (m.get(key), default) {
            (None, Some(d)) => Ok(d),
            (None, None) => cx.err(&at(key), "missing; expected a number"),
            (Some(v), _) => cx.num(v, &at(key)),
        }
    };
    let (sigma_a, sigma_s, g, step) =
        (num("sigma_a", None)?, num("sigma_s", None)?, num("g", Some(0.0))?, num("step", None)?);
    for (k, v) in [("sigma_a", sigma_a), ("sigma_s", sigma_s)] {
        if v < 0.0 {
            return bad(k, format!("{v} is negative; expected a coefficient >= 0 (per unit length)"));
        }
    }
    if !(g > -1.0 && g < 1.0) {
        return bad("g", format!("{g}: the Henyey-Greenstein asymmetry must lie strictly between -1 and 1"));
    }
    let emission = match m.get("emission") {
        None => [0.0; 3],
        Some(toml::Value::Array(a)) if a.len() == 3 => {
            [cx.num(&a[0], &at("emission"))?, cx.num(&a[1], &at("emission"))?, cx.num(&a[2], &at("emission"))?]
        }
        Some(_) => return bad("emission", "expected [r, g, b]".into()),
    };
    if emission.iter().any(|&e| e < 0.0) {
        return bad("emission", "expected emission >= 0".into());
    }
    let height_scale = m.get("height_scale").map(|v| cx.num(v, &at("height_scale"))).transpose()?;
    if let Some(h) = height_scale
        && h <= 0.0
    {
        return bad("height_scale", format!("{h}: expected a scale height > 0"));
    }
    let region = match m.get("box") {
        None => None,
        Some(toml::Value::Table(b)) => {
            let lo = cx.vec3(b, "lo", &at("box"), None)?;
            let hi = cx.vec3(b, "hi", &at("box"), None)?;
            if (0..3).any(|k| lo[k] >= hi[k]) {
                return bad("box", format!("lo {lo:?} must lie below hi {hi:?} on every axis"));
            }
            Some((lo, hi))
        }
        Some(_) => return bad("box", "expected { lo = [x, y, z], hi = [x, y, z] }".into()),
    };
    if step <= 0.0 {
        // finite: num() refuses NaN
        return bad("step", format!("{step}: expected a march step > 0"));
    }
    if let Some((lo, hi)) = region {
        let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f32>().sqrt();
        if diag / step > MAX_MEDIUM_STEPS {
            return bad(
                "step",
                format!("{step}: the box's diagonal {diag} needs more than {MAX_MEDIUM_STEPS} steps a ray"),
            );
        }
    }
    let jitter = match m.get("jitter").map(|v| v.as_str()) {
        None | Some(Some("stratified")) => Jitter::Stratified,
        Some(Some("random")) => Jitter::PerStep,
        Some(_) => {
            return bad("jitter", "expected \"stratified\" (one offset a ray) or \"random\" (one a step)".into());
        }
    };
    Ok(Medium { sigma_a, sigma_s, g, emission, height_scale, region, step, jitter })
}

/// Loads a scene description.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let file = path.display().to_string();
    let cx = Cx { file: &file };
    let text = std::fs::read_to_string(path).map_err(|e| {
        let mut msg = e.to_string();
        if e.kind() == std::io::ErrorKind::NotFound && path.starts_with("scenes") {
            let dirs: Vec<String> = scene_dirs().iter().map(|d| d.display().to_string()).collect();
            msg =
                format!("{msg} (no such scene in {}; give a path, --scene-dir DIR or WARPLIGHT_HOME)", dirs.join(", "));
        }
        SceneError { file: file.clone(), key: "-".into(), msg }
    })?;
    let t: toml::Table =
        toml::from_str(&text).map_err(|e| SceneError { file: file.clone(), key: "-".into(), msg: e.to_string() })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = t
        .get("name")
        .and_then(|v| v.as_str())
        .map(String::from)
        .unwrap_or_else(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
    let mut materials: Vec<Material> = Vec::new();
    let mut roughness: Vec<f32> = Vec::new();
    let mut roughness_y: Vec<f32> = Vec::new();
    let mut exact_fresnel: Vec<bool> = Vec::new();
    let mut translucent: Vec<Option<Translucent>> = Vec::new();
    let mut coat: Vec<Option<f32>> = Vec::new();
    let mut maps: Vec<Maps> = Vec::new();
    for (i, m) in cx.tables(&t, "material")?.into_iter().enumerate() {
        let (m, x) = material(&cx, m, i, &text)?;
        materials.push(m);
        roughness.push(x.roughness[0]);
        roughness_y.push(x.roughness[1]);
        exact_fresnel.push(x.exact);
        translucent.push(x.translucent);
        coat.push(x.coat);
        maps.push(x.maps);
    }
    let by_name = |ms: &[Material], n: &str| ms.iter().position(|m| m.name == n).map(|i| i as u32);
    let scale = cx.float(&t, "scale", "", 1.0)?;
    if scale == 0.0 {
        return cx.err("scale", "must not be zero");
    }
    let translate = Vec3::from(cx.vec3(&t, "translate", "", Some([0.0; 3]))?);
    let mut extra = ObjExtras::default();
    let tris = match (t.get("obj"), t.get("procedural")) {
        (Some(_), Some(_)) => return cx.err("obj", "give either `obj` or `procedural`, not both"),
        (None, None) => return cx.err("obj", "missing; expected `obj = \"file.obj\"` or `procedural = \"scene6\"`"),
        (None, Some(p)) => {
            let g = match p.as_str() {
                Some("scene6") => procedural::scene6(),
                Some("passage") => procedural::passage(),
                Some("ring") => procedural::ring(false),
                Some("ring-volumetric") => procedural::ring(true),
                _ => return cx.err("procedural", "expected scene6, passage, ring or ring-volumetric"),
            };
            // generated materials, unless the file defines one of the same name
            let names: Vec<String> = g.materials.iter().map(|m| m.name.clone()).collect();
            for m in g.materials {
                if by_name(&materials, &m.name).is_none() {
                    materials.push(m);
                }
            }
            g.triangles
                .into_iter()
                .map(|tr| {
                    let n = &names[tr.material as usize];
                    Triangle { v: tr.v, material: by_name(&materials, n).expect("generated material") }
                })
                .collect()
        }
        (Some(o), None) => {
            let Some(rel) = o.as_str() else { return cx.err("obj", "expected a file name") };
            load_obj(&cx, &dir.join(rel), &t, &mut materials, &mut extra)?
        }
    };
    let tris: Vec<Triangle> =
        tris.into_iter().map(|tr| Triangle { v: tr.v.map(|p| p * scale + translate), material: tr.material }).collect();
    texture_maps(&cx, &text, dir, &maps, &tris, &mut extra)?;
    for (i, r) in cx.tables(&t, "reflect")?.into_iter().enumerate() {
        let p = format!("reflect[{i}].");
        let Some(name) = r.get("material").and_then(|v| v.as_str()) else {
            return cx.err(&format!("{p}material"), "missing; expected the name of a material");
        };
        let Some(m) = by_name(&materials, name) else {
            return cx.err(&format!("{p}material"), format!("no material named `{name}`"));
        };
        if materials[m as usize].kind != MaterialKind::Diffuse {
            return cx.err(&format!("{p}material"), format!("`{name}` is not diffuse"));
        }
        let w = cx.vec3(r, "weight", &p, None)?;
        if w.iter().any(|&x| !(0.0..=1.0).contains(&x)) {
            return cx.err(&format!("{p}weight"), "expected weights between 0 and 1");
        }
        extra.surface(m as usize).reflect = w;
    }
    // a negative scale mirrors the geometry: its normals turn with it
    let normals =
        std::mem::take(&mut extra.normals).into_iter().map(|t| t.map(|n| n.map(|x| x * scale.signum()))).collect();
    let uvs = std::mem::take(&mut extra.uvs);
    let mut scene = Scene::assemble_with_vertices(&name, path, tris, uvs, normals, materials);
    scene.textures = extra.textures;
    scene.surfaces = extra.surfaces;
    scene.roughness = roughness;
    scene.roughness_y = roughness_y;
    scene.exact_fresnel = exact_fresnel;
    scene.translucent = translucent;
    scene.coat = coat;
    if let Some(e) = t.get("environment") {
        let Some(rel) = e.as_str() else { return cx.err("environment", "expected the file name of an OpenEXR map") };
        let file = dir.join(rel);
        if !file.is_file() {
            return cx.err("environment", format!("no such file {}", file.display()));
        }
        scene.environment = Some(file);
    }
    scene.medium = cx.table(&t, "medium")?.map(|m| medium(&cx, m, &text)).transpose()?;
    scene.variant = t.get("variant").and_then(|v| v.as_str()).unwrap_or("").to_string();
    if let Some(th) = cx.table(&t, "thesis")? {
        let triangles = match th.get("triangles").and_then(|v| v.as_integer()) {
            Some(n) if n > 0 => n as u64,
            _ => return cx.err("thesis.triangles", "expected a positive integer"),
        };
        scene.thesis = Some(ThesisScene { triangles, extent: cx.vec3(th, "extent", "thesis.", None)? });
    }
    for (i, l) in cx.tables(&t, "light")?.into_iter().enumerate() {
        let p = format!("light[{i}].");
        scene.lights.push(match l.get("kind").and_then(|v| v.as_str()).unwrap_or("point") {
            "point" => Light::Point {
                position: cx.vec3(l, "position", &p, None)?,
                intensity: cx.vec3(l, "intensity", &p, Some([1.0; 3]))?,
            },
            "directional" => Light::Directional {
                direction: cx.vec3(l, "direction", &p, None)?,
                radiance: cx.vec3(l, "radiance", &p, Some([1.0; 3]))?,
            },
            "area" => Light::Area { triangles: Vec::new() },
            other => return cx.err(&format!("{p}kind"), format!("`{other}`; expected point, directional or area")),
        });
    }
    // Area lights are the emissive triangles.
    let emissive: Vec<u32> = scene
        .triangles
        .iter()
        .enumerate()
        .filter(|(_, tr)| scene.materials[tr.material as usize].kind == MaterialKind::Emitter)
        .map(|(i, _)| i as u32)
        .collect();
    for l in &mut scene.lights {
        if let Light::Area { triangles } = l {
            *triangles = emissive.clone();
        }
    }
    if let Some(c) = cx.table(&t, "camera")? {
        let p = "camera.";
        let res = match c.get("resolution") {
            None => [512, 512],
            Some(toml::Value::Array(a)) if a.len() == 2 => {
                let w = a[0].as_integer().filter(|&x| x > 0);
                let h = a[1].as_integer().filter(|&x| x > 0);
                match (w, h) {
                    (Some(w), Some(h)) if (w as u64).saturating_mul(h as u64) > crate::limits::MAX_PIXELS => {
                        return cx.err(
                            "camera.resolution",
                            format!("{w} x {h} pixels is more than {} (16384 x 16384)", crate::limits::MAX_PIXELS),
                        );
                    }
                    (Some(w), Some(h)) => [w as u32, h as u32],
                    _ => return cx.err("camera.resolution", "expected [width, height] of positive integers"),
                }
            }
            Some(_) => return cx.err("camera.resolution", "expected [width, height]"),
        };
        let fov = cx.float(c, "fov", p, 60.0)?;
        if !(1.0..179.0).contains(&fov) {
            return cx.err("camera.fov", "expected a vertical field of view between 1 and 179 degrees");
        }
        let direction = cx.vec3(c, "direction", p, None)?;
        if Vec3::from(direction).length() == 0.0 {
            return cx.err("camera.direction", "must not be zero");
        }
        let up = cx.vec3(c, "up", p, Some([0.0, 1.0, 0.0]))?;
        if Vec3::from(direction).normalize().cross(Vec3::from(up)).length() < 1e-6 {
            return cx.err("camera.up", "must not be zero or parallel to the direction");
        }
        scene.camera =
            Camera { position: cx.vec3(c, "position", p, None)?, direction, up, fov_y: fov, resolution: res };
    }
    if let Some(f) = cx.table(&t, "flight")? {
        let p = "flight.";
        let frames = match f.get("frames") {
            None => 50,
            Some(v) => match v.as_integer() {
                Some(n) if n > 0 && n <= crate::limits::MAX_FLIGHT_FRAMES as i64 => n as u32,
                _ => {
                    return cx.err(
                        "flight.frames",
                        format!("expected a positive integer, at most {}", crate::limits::MAX_FLIGHT_FRAMES),
                    );
                }
            },
        };
        scene.flight = Flight {
            frames,
            forward: cx.float(f, "forward", p, 0.1)?,
            yaw_deg: cx.float(f, "yaw", p, 0.25)?,
            move_light: f.get("move_light").and_then(|v| v.as_bool()).unwrap_or(false),
            light_step: cx.vec3(f, "light_step", p, Some([0.03; 3]))?,
        };
    }
    Ok(scene)
}

/// What an OBJ brings beside triangles and materials.
#[derive(Default)]
struct ObjExtras {
    /// Texture maps, one per file.
    textures: Vec<Texture>,
    /// Per material index, its texture and specular part.
    surfaces: Vec<Surface>,
    /// Per triangle, its vertices' texture coordinates (zero where the OBJ gives
    /// none; emptied at the end when the scene has no texture).
    uvs: Vec<[[f32; 2]; 3]>,
    /// Per triangle, whether the OBJ gives its texture coordinates.
    has_uv: Vec<bool>,
    /// Per triangle, its vertices' normals (empty when the OBJ has none; all
    /// zero for a triangle of a group without them).
    normals: Vec<[[f32; 3]; 3]>,
}

impl ObjExtras {
    fn surface(&mut self, m: usize) -> &mut Surface {
        if self.surfaces.len() <= m {
            self.surfaces.resize(m + 1, Surface::default());
        }
        &mut self.surfaces[m]
    }

    /// The texture read from `file` (relative to `dir`, the OBJ's or the
    /// scene file's folder), read once; an error names `key`.
    fn texture(&mut self, cx: &Cx, dir: &Path, file: &str, key: &str) -> Result<u32, SceneError> {
        if let Some(i) = self.textures.iter().position(|t| t.name == file) {
            return Ok(i as u32);
        }
        let path = dir.join(file);
        let img = image::open(&path)
            .map_err(|e| SceneError { file: cx.file.into(), key: key.into(), msg: format!("{}: {e}", path.display()) })?
            .to_rgb8();
        let (width, height) = img.dimensions();
        let texels = img.pixels().map(|p| p[0] as u32 | (p[1] as u32) << 8 | (p[2] as u32) << 16 | 255 << 24).collect();
        self.textures.push(Texture { name: file.to_string(), width, height, texels });
        Ok(self.textures.len() as u32 - 1)
    }
}

/// Reads the scene file's texture maps (`maps`, per material of the file)
/// into `extra` and gives the triangles of a material with a `planar`
/// mapping their texture coordinates; refuses a textured material whose
/// triangles have no texture coordinates. Drops the texture coordinates when
/// the scene has no texture (thesis 000's kernels then read none).
fn texture_maps(
    cx: &Cx,
    text: &str,
    dir: &Path,
    maps: &[Maps],
    tris: &[Triangle],
    extra: &mut ObjExtras,
) -> Result<(), SceneError> {
    for (i, mp) in maps.iter().enumerate() {
        if *mp == Maps::default() {
            continue;
        }
        let at = |key: &str| format!("material[{i}].{key} (line {})", table_line(text, "[[material]]", i, key));
        let mut load = |file: &Option<String>, key: &str| -> Result<Option<u32>, SceneError> {
            file.as_deref().map(|f| extra.texture(cx, dir, f, &at(key))).transpose()
        };
        let (a, r, m) = (
            load(&mp.albedo, "albedo_map")?,
            load(&mp.roughness, "roughness_map")?,
            load(&mp.metalness, "metalness_map")?,
        );
        let sf = extra.surface(i);
        (sf.texture, sf.roughness_map, sf.metalness_map) = (a.or(sf.texture), r, m);
        if extra.uvs.len() != tris.len() {
            extra.uvs = vec![[[0.0; 2]; 3]; tris.len()];
            extra.has_uv = vec![false; tris.len()];
        }
        let mine = tris.iter().enumerate().filter(|(_, t)| t.material == i as u32).map(|(k, _)| k);
        if let Some([o, u, v]) = mp.planar {
            let (o, u, v) = (Vec3::from(o), Vec3::from(u), Vec3::from(v));
            for k in mine {
                extra.uvs[k] = tris[k].v.map(|p| [(p - o).dot(u), (p - o).dot(v)]);
            }
        } else if let Some(k) = mine.into_iter().find(|&k| !extra.has_uv[k]) {
            let line = table_line(text, "[[material]]", i, "name");
            return cx.err(
                &format!("material[{i}] (line {line})"),
                format!(
                    "has texture maps, but triangle {k} has no texture coordinates (no `vt` in the OBJ); give \
                     planar = {{ origin = [x, y, z], u = [x, y, z], v = [x, y, z] }}"
                ),
            );
        }
    }
    if extra.textures.is_empty() {
        extra.uvs.clear();
    }
    Ok(())
}

/// Loads an OBJ (polygons split as fans) with its MTL materials where present:
/// their diffuse texture maps (`map_Kd`) and texture coordinates, and the
/// specular part (`Ks`) of diffuse ones.
fn load_obj(
    cx: &Cx,
    path: &PathBuf,
    t: &toml::Table,
    materials: &mut Vec<Material>,
    extra: &mut ObjExtras,
) -> Result<Vec<Triangle>, SceneError> {
    let opts = tobj::LoadOptions { triangulate: true, single_index: false, ..Default::default() };
    if path.exists() && !path.is_file() {
        return cx.err("obj", format!("{} is not a regular file", path.display()));
    }
    if !path.exists() {
        return cx.err(
            "obj",
            format!(
                "{} does not exist (a scene not distributed with warplight? see the comments in the scene file)",
                path.display()
            ),
        );
    }
    let (models, mtl) = tobj::load_obj(path, &opts).map_err(|e| SceneError {
        file: cx.file.into(),
        key: "obj".into(),
        msg: format!("{}: {e}", path.display()),
    })?;
    let mtl = mtl.unwrap_or_default();
    // material overrides by OBJ group or MTL material name
    let mut overrides: HashMap<String, String> = HashMap::new();
    for (i, o) in cx.tables(t, "override")?.into_iter().enumerate() {
        let from = o.get("group").and_then(|v| v.as_str());
        let to = o.get("material").and_then(|v| v.as_str());
        match (from, to) {
            (Some(f), Some(m)) => {
                if !materials.iter().any(|x| x.name == m) {
                    return cx.err(&format!("override[{i}].material"), format!("no material named `{m}`"));
                }
                overrides.insert(f.to_string(), m.to_string());
            }
            _ => return cx.err(&format!("override[{i}]"), "expected group = \"name\" and material = \"name\""),
        }
    }
    let default = match t.get("default_material").and_then(|v| v.as_str()) {
        Some(d) => d.to_string(),
        None => {
            if !materials.iter().any(|m| m.name == "default") {
                materials.push(Material::diffuse("default", [0.75, 0.75, 0.75]));
            }
            "default".into()
        }
    };
    if !materials.iter().any(|m| m.name == default) {
        return cx.err("default_material", format!("no material named `{default}`"));
    }
    let obj_dir = path.parent().unwrap_or(Path::new("."));
    let mut index = |name: &str, mtl_mat: Option<&tobj::Material>| -> Result<u32, SceneError> {
        if let Some(i) = materials.iter().position(|m| m.name == name) {
            return Ok(i as u32);
        }
        let m = mtl_mat.expect("only MTL materials are added on demand");
        let kd = m.diffuse.unwrap_or([0.75; 3]);
        let ks = m.specular.unwrap_or([0.0; 3]);
        let ke = m.emissive.unwrap_or([0.0; 3]);
        // MTL: emissive (Ke) makes an emitter; purely specular (Kd = 0, Ks > 0) a mirror tinted by Ks;
        // otherwise diffuse, with its map_Kd as texture and, where its illumination model traces
        // reflections (illum 3 to 7), its Ks as the weight of a mirror reflection
        let (kind, color) = if ke.iter().any(|&x| x > 0.0) {
            (MaterialKind::Emitter, kd)
        } else if kd.iter().all(|&x| x < 0.01) && ks.iter().any(|&x| x > 0.0) {
            (MaterialKind::Mirror, ks)
        } else {
            (MaterialKind::Diffuse, kd)
        };
        materials.push(Material { name: name.to_string(), kind, color, emission: ke });
        let i = materials.len() - 1;
        if kind == MaterialKind::Diffuse {
            let texture = match &m.diffuse_texture {
                Some(f) => Some(extra.texture(cx, obj_dir, f, "obj")?),
                None => None,
            };
            let traced = m.illumination_model.is_some_and(|n| (3..=7).contains(&n));
            *extra.surface(i) = Surface { texture, reflect: if traced { ks } else { [0.0; 3] }, ..Default::default() };
        }
        Ok(i as u32)
    };
    let mut out = Vec::new();
    let mut uvs = Vec::new();
    let mut has_uvs = Vec::new();
    let mut normals = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let mtl_mat = mesh.material_id.and_then(|i| mtl.get(i));
        let mat_name = overrides
            .get(&model.name)
            .or_else(|| mtl_mat.and_then(|m| overrides.get(&m.name)))
            .cloned()
            .or_else(|| mtl_mat.map(|m| m.name.clone()))
            .unwrap_or_else(|| default.clone());
        let mi = index(&mat_name, mtl_mat)?;
        let p = |i: u32| {
            Vec3::new(
                mesh.positions[3 * i as usize],
                mesh.positions[3 * i as usize + 1],
                mesh.positions[3 * i as usize + 2],
            )
        };
        let uv = |i: u32| {
            let i = 2 * i as usize;
            mesh.texcoords.get(i..i + 2).map_or([0.0; 2], |c| [c[0], c[1]])
        };
        let has_uv = mesh.texcoord_indices.len() == mesh.indices.len();
        let vn = |i: u32| {
            let i = 3 * i as usize;
            mesh.normals.get(i..i + 3).map_or([0.0; 3], |c| [c[0], c[1], c[2]])
        };
        let has_vn = mesh.normal_indices.len() == mesh.indices.len();
        for (n, f) in mesh.indices.chunks_exact(3).enumerate() {
            out.push(Triangle { v: [p(f[0]), p(f[1]), p(f[2])], material: mi });
            normals.push(if has_vn {
                let c = &mesh.normal_indices[3 * n..3 * n + 3];
                [vn(c[0]), vn(c[1]), vn(c[2])]
            } else {
                [[0.0; 3]; 3]
            });
            has_uvs.push(has_uv);
            uvs.push(if has_uv {
                let c = &mesh.texcoord_indices[3 * n..3 * n + 3];
                [uv(c[0]), uv(c[1]), uv(c[2])]
            } else {
                [[0.0; 2]; 3]
            });
        }
    }
    // texture coordinates matter only where a texture is (`texture_maps` drops them otherwise)
    extra.uvs = uvs;
    extra.has_uv = has_uvs;
    // vertex normals only where the OBJ gives them on every face: for a face
    // without, tobj makes up the previous face's
    if normals.iter().any(|n| *n != [[0.0; 3]; 3]) && every_face_has_normals(path) {
        extra.normals = normals;
    }
    Ok(out)
}

/// Whether every face (`f`) of the OBJ at `path` names a normal at each
/// vertex (`v//vn` or `v/vt/vn`); false where the file cannot be read again.
/// A face line is `f` and its vertices, separated by any whitespace (OBJ
/// allows tabs).
fn every_face_has_normals(path: &Path) -> bool {
    let Ok(bytes) = std::fs::read(path) else { return false };
    String::from_utf8_lossy(&bytes)
        .lines()
        .map(str::split_whitespace)
        .all(|mut w| w.next() != Some("f") || w.all(|v| v.splitn(3, '/').nth(2).is_some_and(|n| !n.trim().is_empty())))
}
