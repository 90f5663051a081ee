//! Runs thesis 000's ray-tracing kernels on the emulator over a scene's camera
//! flight and totals their counts per variant: what Tables 4.1 and 4.5–4.10
//! are made of. One frame of one variant is one [`Sample`] of counters named
//! as the fields of [`Totals`].

use std::collections::BTreeMap;

use crate::host::camera::Camera;
use crate::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use crate::host::rt_kernels::{self, Variant};
use crate::host::scene::Scene;
use crate::model::Profile;
use crate::repro::registry::{MeasureError, Tick, Workspace};
use crate::repro::results::{Results, Sample};
use crate::sim::{Device, SimConfig, SimError};

/// Totals of one variant over a flight.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Totals {
    /// Rays traced.
    pub rays: u64,
    /// Inner-node traversal steps.
    pub inner_nodes: u64,
    /// Inner-node fetches through the texture path.
    pub tex_node_fetches: u64,
    /// Local-memory stack pushes and pops.
    pub local_stack_accesses: u64,
    /// Warp instructions issued.
    pub warp_instructions: u64,
    /// Texture-cache lookups and hits of the gt200 profile.
    pub tex_lookups: u64,
    /// Texture-cache hits.
    pub tex_hits: u64,
    /// Memory transactions of the gt200 profile: global and local segment
    /// transactions plus texture-cache misses (for the timing model).
    pub mem_transactions: u64,
    /// Shadow rays among the rays.
    pub shadow_rays: u64,
    /// Reflection rays among the rays.
    pub reflection_rays: u64,
    /// Texels fetched from texture maps.
    pub texel_fetches: u64,
}

/// One scene's flight, per variant.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SceneRun {
    /// Scene name.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Frames of the flight used.
    pub frames: u32,
    /// Image side.
    pub resolution: u32,
    /// The variants, in the order measured.
    pub variants: Vec<Variant>,
    /// Their totals.
    pub totals: Vec<Totals>,
}

impl SceneRun {
    /// A per-ray quantity of every variant.
    pub fn per_ray(&self, f: impl Fn(&Totals) -> u64) -> Vec<f64> {
        self.totals.iter().map(|t| f(t) as f64 / t.rays.max(1) as f64).collect()
    }

    /// Inner-node traversals per ray (Table 4.5).
    pub fn inner_per_ray(&self) -> Vec<f64> {
        self.per_ray(|t| t.inner_nodes)
    }

    /// Instructions per ray by the thesis' rule: warp instructions × 32 / rays (Tables 4.7, 4.9).
    pub fn instr_per_ray(&self) -> Vec<f64> {
        self.per_ray(|t| 32 * t.warp_instructions)
    }
}

/// Runs `variants` over `frames` frames of the scene's flight at `res` × `res`
/// (SIROH trees, gt200 profile).
pub fn measure(
    scene: &Scene,
    frames: u32,
    res: u32,
    variants: &[Variant],
    tick: impl FnMut(u32, Variant),
) -> Result<SceneRun, SimError> {
    let tris: Vec<[glam::Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let tree = build(&tris, BuildParams::thesis(Heuristic::Siroh));
    measure_tree(scene, &tree, frames, res, variants, tick)
}

/// As [`measure`], over a given tree.
pub fn measure_tree(
    scene: &Scene,
    tree: &KdTree,
    frames: u32,
    res: u32,
    variants: &[Variant],
    mut tick: impl FnMut(u32, Variant),
) -> Result<SceneRun, SimError> {
    let mut totals = vec![Totals::default(); variants.len()];
    for f in 0..frames.min(scene.flight.frames) {
        for (i, v) in variants.iter().enumerate() {
            tick(f, *v);
            totals[i].add(&frame(scene, tree, f, res, *v)?);
        }
    }
    Ok(SceneRun {
        scene: scene.name.clone(),
        triangles: scene.triangles.len(),
        frames: frames.min(scene.flight.frames),
        resolution: res,
        variants: variants.to_vec(),
        totals,
    })
}

/// The camera of frame `f` of the flight at `res` × `res`.
pub fn camera(scene: &Scene, f: u32, res: u32) -> Camera {
    let mut cam = scene.flight.camera(&scene.camera, f);
    cam.resolution = [res, res];
    cam
}

/// One frame of one variant on the emulator (gt200 profile).
pub fn frame(scene: &Scene, tree: &KdTree, f: u32, res: u32, v: Variant) -> Result<Totals, SimError> {
    Ok(frame_timed(scene, tree, f, res, v)?.0)
}

/// As [`frame`], with the GTX 280 timing model's counters of the launch
/// ([`super::timing::counts_of`]).
pub fn frame_timed(
    scene: &Scene,
    tree: &KdTree,
    f: u32,
    res: u32,
    v: Variant,
) -> Result<(Totals, crate::timing::KernelCounts), SimError> {
    // a fresh device per frame: its memory holds one frame's buffers; the
    // watchdog's budget grows with the pixels
    let cam = camera(scene, f, res);
    // the GT200: no FFMA contraction, correctly rounded special functions
    let config = SimConfig { fmad: false, sfu: Profile::Gt200.sfu(), ..rt_kernels::sim_config(&cam) };
    let mut dev = Device::with_config(config);
    let module = rt_kernels::load(&mut dev)?;
    let k = rt_kernels::render(&mut dev, &module, scene, tree, &cam, scene.flight.light_offset(f), v, Profile::Gt200)?;
    let timing = super::timing::counts_of(&module.prog, &k.launch, &k.memory);
    let m = &k.memory.counters;
    let totals = Totals {
        rays: k.trace.rays,
        inner_nodes: k.trace.inner_nodes,
        tex_node_fetches: k.trace.tex_node_fetches,
        local_stack_accesses: k.trace.local_stack_accesses,
        warp_instructions: k.launch.totals.warp_instructions,
        tex_lookups: m.texture.sectors,
        tex_hits: m.texture.hits,
        mem_transactions: m.global_ld.sectors
            + m.global_st.sectors
            + m.local_ld.sectors
            + m.local_st.sectors
            + m.global_atom.sectors
            + m.texture.misses,
        shadow_rays: k.trace.shadow,
        reflection_rays: k.trace.reflection,
        texel_fetches: k.trace.texel_fetches,
    };
    Ok((totals, timing))
}

/// The counters' names, in [`Totals`]' field order.
pub const COUNTERS: [&str; 11] = [
    "rays",
    "inner_nodes",
    "tex_node_fetches",
    "local_stack_accesses",
    "warp_instructions",
    "tex_lookups",
    "tex_hits",
    "mem_transactions",
    "shadow_rays",
    "reflection_rays",
    "texel_fetches",
];

/// How many of [`COUNTERS`] every result file has; the later ones (ray kinds,
/// texel fetches) read as 0 from files written before they were counted.
const REQUIRED: usize = 8;

impl Totals {
    fn fields(&self) -> [u64; 11] {
        [
            self.rays,
            self.inner_nodes,
            self.tex_node_fetches,
            self.local_stack_accesses,
            self.warp_instructions,
            self.tex_lookups,
            self.tex_hits,
            self.mem_transactions,
            self.shadow_rays,
            self.reflection_rays,
            self.texel_fetches,
        ]
    }

    fn from_fields(f: [u64; 11]) -> Totals {
        Totals {
            rays: f[0],
            inner_nodes: f[1],
            tex_node_fetches: f[2],
            local_stack_accesses: f[3],
            warp_instructions: f[4],
            tex_lookups: f[5],
            tex_hits: f[6],
            mem_transactions: f[7],
            shadow_rays: f[8],
            reflection_rays: f[9],
            texel_fetches: f[10],
        }
    }

    /// Adds another frame's totals.
    pub fn add(&mut self, o: &Totals) {
        let (a, b) = (self.fields(), o.fields());
        *self = Totals::from_fields(std::array::from_fn(|i| a[i] + b[i]));
    }

    /// As named counters.
    pub fn counters(&self) -> BTreeMap<String, f64> {
        COUNTERS.iter().zip(self.fields()).map(|(n, v)| (n.to_string(), v as f64)).collect()
    }

    /// The totals of `variant` over the measured frames, or `None` when not measured.
    pub fn from_results(r: &Results, group: &str, scene: &str, variant: &str) -> Option<Totals> {
        let mut f = [0u64; 11];
        for (i, c) in COUNTERS.iter().enumerate() {
            f[i] = match r.sum(group, scene, variant, c) {
                Some(x) => x as u64,
                None if i >= REQUIRED => 0,
                None => return None,
            };
        }
        Some(Totals::from_fields(f))
    }
}

impl SceneRun {
    /// The run of `variants` (named by `names`) of `group` on `scene`, from raw measurements.
    pub fn from_results(
        r: &Results,
        group: &str,
        scene: &str,
        variants: &[Variant],
        names: &[&str],
    ) -> Option<SceneRun> {
        let info = r.scene(scene)?;
        let totals: Option<Vec<Totals>> = names.iter().map(|n| Totals::from_results(r, group, scene, n)).collect();
        Some(SceneRun {
            scene: scene.into(),
            triangles: info.triangles,
            frames: info.frames.iter().map(|f| f.len()).sum(),
            resolution: r.protocol.resolution,
            variants: variants.to_vec(),
            totals: totals?,
        })
    }
}

/// Runs `variants` on `tree` over the workspace's frames: one sample per
/// frame and variant, with the timing model's `timing_*` counters beside [`COUNTERS`].
pub fn samples(
    ws: &Workspace,
    tree: &KdTree,
    group: &str,
    variants: &[(Variant, &str)],
    tick: &mut dyn FnMut(Tick),
) -> Result<Vec<Sample>, MeasureError> {
    let mut out = Vec::new();
    for f in ws.frames.clone() {
        for (v, name) in variants {
            tick(Tick { frame: Some(f), variant: name });
            let (t, timing) = frame_timed(ws.scene, tree, f, ws.resolution, *v)?;
            let mut counters = t.counters();
            counters.extend(timing.counters());
            out.push(Sample {
                group: group.into(),
                scene: ws.scene.name.clone(),
                frame: Some(f),
                variant: name.to_string(),
                counters,
            });
        }
    }
    Ok(out)
}

/// Measurement group `fabianowski/traversal`: the §4.2 traversal variants on SIROH trees.
pub fn measure_traversal(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    ws.build(Heuristic::Siroh);
    let tree = ws.tree(Heuristic::Siroh);
    let v: Vec<(Variant, &str)> = Variant::ALL.iter().map(|v| (*v, v.name())).collect();
    samples(ws, tree, super::TRAVERSAL, &v, tick)
}

/// Measurement group `fabianowski/caches`: the §4.3 cache variants on SIROH trees.
pub fn measure_caches(ws: &mut Workspace, tick: &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError> {
    ws.build(Heuristic::Siroh);
    let tree = ws.tree(Heuristic::Siroh);
    let v: Vec<(Variant, &str)> = Variant::CACHES.iter().map(|v| (*v, v.name())).collect();
    samples(ws, tree, super::CACHES, &v, tick)
}

/// The table note on materials: per scene, the share of reflection rays and
/// the texel fetches per primary ray of `variant` of `group`, and which scenes
/// have neither (no specular materials, no texture maps) where the thesis'
/// did.
pub fn materials_note(r: &Results, group: &str, scenes: &[String], variant: &str) -> String {
    let mut with = Vec::new();
    let mut without = Vec::new();
    let mut uncounted = Vec::new();
    for s in scenes {
        let Some(t) = Totals::from_results(r, group, s, variant) else { continue };
        // a file written before the ray kinds and texel fetches were counted says nothing about materials
        if COUNTERS[REQUIRED..].iter().any(|c| r.sum(group, s, variant, c).is_none()) {
            uncounted.push(s.as_str());
            continue;
        }
        let px = r.scene(s).map_or(0, |i| i.frames.iter().map(|f| f.len() as u64).sum::<u64>())
            * u64::from(r.protocol.resolution).pow(2);
        if t.reflection_rays == 0 && t.texel_fetches == 0 {
            without.push(s.as_str());
        } else {
            with.push(format!(
                "{s} {:.1} % reflection rays, {:.2} texel fetches per pixel",
                100.0 * t.reflection_rays as f64 / t.rays.max(1) as f64,
                t.texel_fetches as f64 / px.max(1) as f64
            ));
        }
    }
    let mut note = String::from(
        "Materials (scene files as loaded; Sponza and Sibenik with their MTL materials and diffuse texture maps, one texel \
         array read through the texture path, nearest texel, docs/scenes.md): ",
    );
    if !with.is_empty() {
        note.push_str(&with.join("; "));
    }
    if !without.is_empty() {
        if !with.is_empty() {
            note.push_str(". ");
        }
        note.push_str(&format!(
            "No specular materials and no texture maps in {} (no reflection rays, no texture-map traffic{})",
            without.join(", "),
            if without.contains(&"conference") {
                "; Conference has neither in the thesis either (Table A.1: no textures)"
            } else {
                ""
            }
        ));
    }
    if !uncounted.is_empty() {
        if !with.is_empty() || !without.is_empty() {
            note.push_str(". ");
        }
        note.push_str(&format!(
            "Reflection rays and texel fetches not counted in this result file for {} (written before they were counted)",
            uncounted.join(", ")
        ));
    }
    note.push('.');
    note
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repro::protocol::Protocol;
    use crate::repro::results::SceneInfo;

    /// Results of one frame of `scene` whose counters are `counters` (all 1).
    fn results(scene: &str, counters: &[&str]) -> Results {
        let mut r = Results::new("abc", Protocol::quick(), vec![], vec!["g".into()]);
        r.scenes.push(SceneInfo {
            name: scene.into(),
            triangles: 1,
            thesis_triangles: None,
            flight_frames: 1,
            frames: vec![crate::repro::protocol::FrameRange::first(1)],
        });
        r.samples.push(Sample {
            group: "g".into(),
            scene: scene.into(),
            frame: Some(0),
            variant: "v".into(),
            counters: counters.iter().map(|c| (c.to_string(), 1.0)).collect(),
        });
        r
    }

    #[test]
    fn a_file_without_the_ray_kinds_says_so_instead_of_no_materials() {
        let old = results("sponza", &COUNTERS[..REQUIRED]);
        let note = materials_note(&old, "g", &["sponza".into()], "v");
        assert!(note.contains("not counted in this result file for sponza"), "{note}");
        assert!(!note.contains("No specular materials"), "{note}");
        let new = results("sponza", &COUNTERS);
        let note = materials_note(&new, "g", &["sponza".into()], "v");
        assert!(note.contains("sponza 100.0 % reflection rays"), "{note}");
        assert!(!note.contains("not counted"), "{note}");
    }
}
