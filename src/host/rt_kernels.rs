//! Runs thesis 000's ray-tracing kernels (`kernels/fabianowski2011/raytrace.cu`) on
//! the emulator: uploads the laid-out kd-tree, triangles, materials and camera,
//! launches 30 persistent CTAs of 256 threads, and reads back the image, the
//! primary hit of each pixel and the work traced.
//!
//! The work is counted by the emulator, not the kernel: the plain build
//! ([`Build::Plain`], what the tables run) has no tallies, and [`line_counts`]
//! reads rays (shadow and reflection rays among them), inner-node steps, leaf
//! visits, plane and barycentric tests, stack pushes (every push, as the
//! native caster counts them: to local memory or into stack caches I and
//! II's registers), local-memory stack accesses and texture-map texel
//! fetches off the per-instruction counters of the source
//! lines tagged `@count` in `raytrace.cu`; a node-cache observer
//! ([`NodeCacheFetches`]) tells inner nodes from leaves among the shared-memory
//! node fetches, so that the texture fetches of inner nodes follow. The
//! instrumented build ([`Build::Instrumented`]) tallies the same quantities in
//! the kernel, for the cross-check that both agree.

use glam::Vec3;

use super::camera::Camera;
use super::image::FrameBuffer;
use super::kdtree::KdTree;
use super::kdtree::layout::layout;
use super::raycast::{EPS_REL, TraceStats};
use super::scene::{Light, MaterialKind, Scene};
use crate::model::{Model, ModelStats, Profile};
use crate::ptx::ir::{MemSpace, Program};
use crate::sim::device::to_bytes;
use crate::sim::observer::{MemEvent, MemObserver, MemOp, ObserverFactory};
use crate::sim::{Arg, Device, LaunchConfig, LaunchStats, Module, SimConfig, SimError};

/// Traversal variants of the kernel family (thesis 000 §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Variant {
    /// Stack-based traversal, stack in local memory.
    Stack,
    /// Restart with the flags register (Alg. 4.1).
    Stackless,
    /// Alg. 4.2 with push-down.
    PushDown,
    /// Alg. 4.2 with a 4-entry short stack in shared memory.
    ShortStack,
    /// Alg. 4.2 with both.
    PushDownShortStack,
    /// Stack-based with node cache I (top 10 levels in shared memory).
    NodeCache1,
    /// Stack-based with stack cache I (the top entry in registers).
    StackCache1,
    /// Node cache I and stack cache I.
    NodeCache1StackCache1,
    /// Node cache II (top 8 levels with AABBs) and stack cache II (their indices in two registers).
    NodeCache2StackCache2,
    /// Stack cache III: speculative traversal, a leaf postponed until the next is found.
    StackCache3,
    /// Node cache I and stack cache III.
    NodeCache1StackCache3,
}

impl Variant {
    /// The traversal variants of §4.2 (Tables 4.5-4.7).
    pub const ALL: [Variant; 5] =
        [Variant::Stack, Variant::Stackless, Variant::PushDown, Variant::ShortStack, Variant::PushDownShortStack];

    /// The cache variants of §4.3 in the order of Tables 4.8-4.10's columns 1-7.
    pub const CACHES: [Variant; 7] = [
        Variant::Stack,
        Variant::NodeCache1,
        Variant::StackCache1,
        Variant::StackCache3,
        Variant::NodeCache1StackCache1,
        Variant::NodeCache2StackCache2,
        Variant::NodeCache1StackCache3,
    ];

    /// Every variant.
    pub const EVERY: [Variant; 11] = [
        Variant::Stack,
        Variant::Stackless,
        Variant::PushDown,
        Variant::ShortStack,
        Variant::PushDownShortStack,
        Variant::NodeCache1,
        Variant::StackCache1,
        Variant::NodeCache1StackCache1,
        Variant::NodeCache2StackCache2,
        Variant::StackCache3,
        Variant::NodeCache1StackCache3,
    ];

    /// Levels of the tree top laid out in heap order for this variant's node cache.
    pub fn heap_levels(self) -> u32 {
        match self {
            Variant::NodeCache1 | Variant::NodeCache1StackCache1 | Variant::NodeCache1StackCache3 => 10,
            Variant::NodeCache2StackCache2 => 8,
            _ => 0,
        }
    }

    /// The kernel's entry point.
    pub fn kernel(self) -> &'static str {
        match self {
            Variant::Stack => "trace_stack",
            Variant::Stackless => "trace_stackless",
            Variant::PushDown => "trace_pushdown",
            Variant::ShortStack => "trace_shortstack",
            Variant::PushDownShortStack => "trace_pushdown_shortstack",
            Variant::NodeCache1 => "trace_nc1",
            Variant::StackCache1 => "trace_sc1",
            Variant::NodeCache1StackCache1 => "trace_nc1_sc1",
            Variant::NodeCache2StackCache2 => "trace_nc2_sc2",
            Variant::StackCache3 => "trace_sc3",
            Variant::NodeCache1StackCache3 => "trace_nc1_sc3",
        }
    }

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Stack => "stack",
            Variant::Stackless => "stackless",
            Variant::PushDown => "push-down",
            Variant::ShortStack => "short-stack",
            Variant::PushDownShortStack => "push-down+short-stack",
            Variant::NodeCache1 => "node-cache-1",
            Variant::StackCache1 => "stack-cache-1",
            Variant::NodeCache1StackCache1 => "node-cache-1+stack-cache-1",
            Variant::NodeCache2StackCache2 => "node-cache-2+stack-cache-2",
            Variant::StackCache3 => "stack-cache-3",
            Variant::NodeCache1StackCache3 => "node-cache-1+stack-cache-3",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Variant> {
        Variant::EVERY.into_iter().find(|v| v.name() == s)
    }
}

/// The kernels' PTX, compiled in (`kernels/fabianowski2011/raytrace.ptx`): no tallies.
pub const PTX: &str = include_str!("../../kernels/fabianowski2011/raytrace.ptx");
/// The instrumented build's PTX (`raytrace_stats.cu`: the same source with its tallies compiled in).
pub const PTX_STATS: &str = include_str!("../../kernels/fabianowski2011/raytrace_stats.ptx");
/// The kernels' CUDA source, whose `@count` tags name the lines counted.
pub const SOURCE: &str = include_str!("../../kernels/fabianowski2011/raytrace.cu");
/// The source's path as the PTX's `.file` directive names it (suffix).
const SOURCE_FILE: &str = "kernels/fabianowski2011/raytrace.cu";

/// Which build of the kernels runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Build {
    /// The kernels as the thesis runs them; the emulator counts the work.
    Plain,
    /// The kernels with in-kernel tallies written to a stats buffer (the cross-check).
    Instrumented,
}

/// A counted source line: each `NAME` event executes exactly one `opcode`
/// instruction that `.loc` places on `line` (a comment `@count NAME OPCODE`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CountTag {
    /// 1-based line in `raytrace.cu`.
    pub line: u32,
    /// The event counted.
    pub name: String,
    /// The PTX opcode, as written, that stands for one event.
    pub opcode: String,
}

/// The `@count` tags of `source`, in line order.
pub fn count_tags(source: &str) -> Vec<CountTag> {
    source
        .lines()
        .enumerate()
        .filter_map(|(i, l)| {
            let (_, tag) = l.split_once("// @count ")?;
            let mut w = tag.split_whitespace();
            let (name, opcode) = (w.next()?, w.next()?);
            Some(CountTag { line: i as u32 + 1, name: name.into(), opcode: opcode.into() })
        })
        .collect()
}

/// Per tag name, the lanes that executed the tagged instruction (guard true),
/// summed over every PTX instruction on a tagged line of `raytrace.cu` whose
/// opcode is the tag's: the events the kernel performed.
pub fn line_counts(prog: &Program, stats: &LaunchStats, tags: &[CountTag]) -> std::collections::BTreeMap<String, u64> {
    tagged_counts(prog, &stats.profile, SOURCE_FILE, tags, |c| c.pred_on)
}

/// Per tag name, `select` of the per-instruction counters summed over every
/// PTX instruction that `.loc` places on a tagged line of the kernel source
/// `source_file` (a suffix of the PTX's `.file` path) and whose opcode is the
/// tag's; instructions no lane executed with its guard true are skipped.
/// `select = |c| c.pred_on` gives the events the kernel performed.
pub fn tagged_counts(
    prog: &Program,
    profile: &crate::sim::counters::InstProfile,
    source_file: &str,
    tags: &[CountTag],
    select: impl Fn(&crate::sim::counters::InstCounts) -> u64,
) -> std::collections::BTreeMap<String, u64> {
    let mut out: std::collections::BTreeMap<String, u64> = tags.iter().map(|t| (t.name.clone(), 0)).collect();
    for (f, pc, info, line) in prog.located_in(source_file) {
        let Some(c) = profile.per_fn.get(f).and_then(|counts| counts.get(pc)) else { continue };
        if c.pred_on == 0 {
            continue;
        }
        for t in tags.iter().filter(|t| t.line == line && t.opcode == info.opcode) {
            *out.entry(t.name.clone()).or_default() += select(c);
        }
    }
    out
}

/// Counts, lane by lane, the shared-memory loads of 8-byte nodes from the
/// node cache (`node_cache` in `raytrace.cu`) whose node is an inner node:
/// node fetches the cache served, so not through the texture path.
pub struct NodeCacheFetches<'a> {
    /// The model that observes the same launch.
    model: &'a Model,
    /// Offset of `node_cache` in shared memory, if the module has it.
    base: Option<u64>,
    /// Whether node `i` of the laid-out tree is an inner node.
    inner: std::sync::Arc<Vec<bool>>,
    /// Inner-node fetches served by the cache, over retired CTAs.
    served: std::sync::Mutex<u64>,
}

struct CacheObserver {
    model: Box<dyn MemObserver>,
    base: Option<u64>,
    inner: std::sync::Arc<Vec<bool>>,
    served: u64,
}

impl MemObserver for CacheObserver {
    fn access(&mut self, ev: &MemEvent) {
        self.model.access(ev);
        let Some(base) = self.base else { return };
        if ev.space != MemSpace::Shared || ev.op != MemOp::Load || ev.bytes != 8 {
            return;
        }
        for lane in 0..32 {
            if ev.mask & (1 << lane) == 0 {
                continue;
            }
            let a = ev.addrs[lane];
            if a >= base && a < base + 8 * self.inner.len() as u64 && (a - base).is_multiple_of(8) {
                self.served += self.inner[((a - base) / 8) as usize] as u64;
            }
        }
    }

    fn into_any(self: Box<Self>) -> Box<dyn std::any::Any> {
        self
    }

    fn as_any_mut(&mut self) -> Option<&mut dyn std::any::Any> {
        Some(self)
    }
}

impl<'a> NodeCacheFetches<'a> {
    /// Observes `prog`'s node cache over `nodes` (the laid-out tree, 8 bytes a node), alongside `model`.
    pub fn new(model: &'a Model, prog: &Program, nodes: &[u8]) -> Self {
        let base = prog.shared_vars.iter().find(|v| v.name == "node_cache").map(|v| v.offset as u64);
        let inner = nodes.chunks_exact(8).map(|n| u32::from_le_bytes([n[4], n[5], n[6], n[7]]) & 3 != 3).collect();
        NodeCacheFetches { model, base, inner: std::sync::Arc::new(inner), served: std::sync::Mutex::new(0) }
    }

    /// Inner-node fetches the cache served.
    pub fn served(&self) -> u64 {
        *self.served.lock().expect("node cache counter")
    }
}

/// The observer in `b`, for as long as `b` is borrowed.
fn shorten<'a>(b: &'a mut Box<dyn MemObserver>) -> &'a mut (dyn MemObserver + 'a) {
    &mut **b
}

impl ObserverFactory for NodeCacheFetches<'_> {
    fn create(&self, cta: u32) -> Box<dyn MemObserver> {
        Box::new(CacheObserver { model: self.model.create(cta), base: self.base, inner: self.inner.clone(), served: 0 })
    }

    fn retire(&self, obs: Box<dyn MemObserver>) {
        match obs.into_any().downcast::<CacheObserver>() {
            Ok(o) => {
                *self.served.lock().expect("node cache counter") += o.served;
                self.model.retire(o.model);
            }
            Err(_) => unreachable!("NodeCacheFetches made every observer of this launch"),
        }
    }

    fn end_round(&self, observers: &mut [(u32, &mut dyn MemObserver)]) {
        let mut inner: Vec<(u32, &mut dyn MemObserver)> = observers
            .iter_mut()
            .filter_map(|(cta, o)| {
                let c = o.as_any_mut()?.downcast_mut::<CacheObserver>()?;
                Some((*cta, shorten(&mut c.model)))
            })
            .collect();
        self.model.end_round(&mut inner);
    }

    fn set_fidelity(&self, level: crate::sim::Fidelity) {
        self.model.set_fidelity(level);
    }
}

/// CTAs of the persistent-threads launch (one per GTX 280 SM).
pub const CTAS: u32 = 30;
/// Threads per CTA.
pub const THREADS: u32 = 256;

/// Warp instructions per pixel the watchdog allows a kernel render: about
/// 20 times the most the thesis scenes need (under 800).
pub const WARP_INSTRUCTIONS_PER_PIXEL: u64 = 1 << 14;

/// The simulator settings for rendering `camera`'s image: the default, with
/// a watchdog that grows with the pixel count, so that large images are not
/// taken for runaway kernels.
pub fn sim_config(camera: &Camera) -> SimConfig {
    let mut c = SimConfig::default();
    let pixels = camera.resolution[0] as u64 * camera.resolution[1] as u64;
    let budget = pixels.saturating_mul(WARP_INSTRUCTIONS_PER_PIXEL);
    c.schedule.max_warp_instructions = c.schedule.max_warp_instructions.max(budget);
    c
}

/// What a kernel render produced.
#[derive(Debug, Clone)]
pub struct KernelRender {
    /// The image.
    pub image: FrameBuffer,
    /// Triangle hit by each pixel's primary ray (-1: none).
    pub hit_tri: Vec<i32>,
    /// Work counted by the emulator (per-line counters of the kernel's tagged
    /// lines), summed over pixels; all zero when `counted` is false.
    pub trace: TraceStats,
    /// Whether `trace` was counted: the `functional` fidelity level keeps no
    /// per-line counters, so a plain build's work counts are then unknown.
    pub counted: bool,
    /// The emulator's counters.
    pub launch: LaunchStats,
    /// The device profile's memory counters.
    pub memory: ModelStats,
}

/// The scene's materials as the kernels read them: per material
/// `color.rgb, kind` then `emission.rgb, 0`, kind 0 diffuse, 1 mirror (glass
/// too), 2 emitter.
pub fn material_table(scene: &Scene) -> Vec<f32> {
    let mut mats = Vec::with_capacity(8 * scene.materials.len());
    for m in &scene.materials {
        let kind = match m.kind {
            MaterialKind::Diffuse => 0.0,
            MaterialKind::Mirror | MaterialKind::Glass { .. } => 1.0,
            MaterialKind::Emitter => 2.0,
        };
        mats.extend_from_slice(&[m.color[0], m.color[1], m.color[2], kind]);
        mats.extend_from_slice(&[m.emission[0], m.emission[1], m.emission[2], 0.0]);
    }
    mats
}

/// The kernels' surface table: per material `reflection weight r, g, b`
/// ([`Scene::reflectance`]: a hit on it traces a reflection ray when one is
/// positive) and its texture's index as the bits of an `i32` (-1: none).
pub fn surface_table(scene: &Scene) -> Vec<f32> {
    let mut out = Vec::with_capacity(4 * scene.materials.len());
    for m in 0..scene.materials.len() as u32 {
        let w = scene.reflectance(m);
        let tex = match scene.materials[m as usize].kind {
            MaterialKind::Diffuse => scene.surface(m).texture.map_or(-1, |t| t as i32),
            _ => -1,
        };
        out.extend_from_slice(&[w[0], w[1], w[2], f32::from_bits(tex as u32)]);
    }
    out
}

/// The kernels' textures: per texture `[first texel, width, height, 0]`, and
/// every texture's texels in one array (the thesis stacks its maps in one
/// 3-D texture, seed 000 L3431).
pub fn texture_tables(scene: &Scene) -> (Vec<u32>, Vec<u32>) {
    let mut info = Vec::with_capacity(4 * scene.textures.len());
    let mut texels = Vec::new();
    for t in &scene.textures {
        info.extend_from_slice(&[texels.len() as u32, t.width, t.height, 0]);
        texels.extend_from_slice(&t.texels);
    }
    (info, texels)
}

/// The kernels' parameter block (`struct Params` in `raytrace.cu`): the
/// camera, the first point light moved by `light_offset` (none: `has_light`
/// 0), the tree's bounds, the ray epsilon and the image size.
pub fn params(scene: &Scene, tree: &KdTree, camera: &Camera, light_offset: Vec3) -> Vec<u8> {
    let (r, u, f) = camera.frame();
    let [w, h] = camera.resolution;
    let npix = w as usize * h as usize; // not w * h in u32: it wraps past 4 Gi pixels
    let light = scene.lights.iter().find_map(|l| match l {
        Light::Point { position, intensity } => Some((Vec3::from(*position) + light_offset, *intensity)),
        _ => None,
    });
    let (lp, li) = light.unwrap_or((Vec3::ZERO, [0.0; 3]));
    let eps = tree.bounds.size().length().max(1e-3) * EPS_REL;
    let mut params = to_bytes(&[
        camera.position[0],
        camera.position[1],
        camera.position[2],
        f.x,
        f.y,
        f.z,
        r.x,
        r.y,
        r.z,
        u.x,
        u.y,
        u.z,
        lp.x,
        lp.y,
        lp.z,
        li[0],
        li[1],
        li[2],
        tree.bounds.lo.x,
        tree.bounds.lo.y,
        tree.bounds.lo.z,
        tree.bounds.hi.x,
        tree.bounds.hi.y,
        tree.bounds.hi.z,
        eps,
        (camera.fov_y.to_radians() * 0.5).tan(),
        w as f32 / h as f32,
    ]);
    for v in [w as i32, h as i32, npix as i32, light.is_some() as i32] {
        params.extend_from_slice(&v.to_le_bytes());
    }
    params
}

/// Words per pixel of the instrumented build's stats buffer (`STATS_WORDS` in `raytrace.cu`).
pub const STATS_WORDS: usize = 11;

/// The device buffers of one kernel launch, in the kernels' argument order.
#[derive(Debug, Clone, Copy)]
pub struct Buffers {
    /// Every argument: params, nodes, refs, triangles, material per triangle,
    /// materials, surfaces, texture coordinates, texture table, texels,
    /// AABBs, job queue, colour, hit triangle, stats.
    pub args: [crate::sim::DevicePtr; 15],
}

impl Buffers {
    /// The colour buffer (4 floats a pixel).
    pub fn color(&self) -> crate::sim::DevicePtr {
        self.args[12]
    }

    /// The primary hit triangle of each pixel.
    pub fn hit(&self) -> crate::sim::DevicePtr {
        self.args[13]
    }

    /// The instrumented build's tallies ([`STATS_WORDS`] a pixel).
    pub fn stats(&self) -> crate::sim::DevicePtr {
        self.args[14]
    }

    /// As launch arguments.
    pub fn launch_args(&self) -> Vec<Arg> {
        self.args.iter().copied().map(Arg::Ptr).collect()
    }
}

/// Uploads what kernel `variant` reads to render `camera`'s view of `scene`
/// over `tree` (laid out as `lay`), and allocates its outputs.
pub fn upload_scene(
    dev: &mut Device,
    scene: &Scene,
    tree: &KdTree,
    lay: &crate::host::kdtree::layout::DeviceTree,
    camera: &Camera,
    light_offset: Vec3,
) -> Result<Buffers, SimError> {
    let npix = camera.resolution[0] as usize * camera.resolution[1] as usize;
    let tri_mat: Vec<u32> = scene.triangles.iter().map(|t| t.material).collect();
    let uvs: Vec<f32> = if scene.uvs.is_empty() {
        Vec::new()
    } else {
        (0..scene.triangles.len() as u32).flat_map(|t| scene.uv(t).into_iter().flatten()).collect()
    };
    let (tex_info, texels) = texture_tables(scene);
    let up = upload;
    Ok(Buffers {
        args: [
            up(dev, &params(scene, tree, camera, light_offset), "params")?,
            up(dev, &lay.nodes, "nodes")?,
            up(dev, &lay.tri_refs, "tri_refs")?,
            up(dev, &lay.triangles, "triangles")?,
            up(dev, &to_bytes(&tri_mat), "tri_mat")?,
            up(dev, &to_bytes(&material_table(scene)), "materials")?,
            up(dev, &to_bytes(&surface_table(scene)), "surfaces")?,
            up(dev, &to_bytes(&uvs), "uvs")?,
            up(dev, &to_bytes(&tex_info), "tex_info")?,
            up(dev, &to_bytes(&texels), "texels")?,
            up(dev, &lay.aabbs, "aabbs")?,
            up(dev, &[0; 4], JOB_QUEUE)?,
            dev.alloc_zeroed::<f32>(4 * npix),
            dev.alloc_zeroed::<i32>(npix),
            dev.alloc_zeroed::<u32>(STATS_WORDS * npix),
        ],
    })
}

/// Renders `camera`'s view with kernel `variant` under device profile `profile`.
#[allow(clippy::too_many_arguments)]
pub fn render(
    dev: &mut Device,
    module: &Module,
    scene: &Scene,
    tree: &KdTree,
    camera: &Camera,
    light_offset: Vec3,
    variant: Variant,
    profile: Profile,
) -> Result<KernelRender, SimError> {
    render_build(dev, module, Build::Plain, scene, tree, camera, light_offset, variant, profile)
}

/// As [`render`], with `module` loaded from `build` ([`load_build`]).
#[allow(clippy::too_many_arguments)]
pub fn render_build(
    dev: &mut Device,
    module: &Module,
    build: Build,
    scene: &Scene,
    tree: &KdTree,
    camera: &Camera,
    light_offset: Vec3,
    variant: Variant,
    profile: Profile,
) -> Result<KernelRender, SimError> {
    let tris: Vec<[Vec3; 3]> = scene.triangles.iter().map(|t| t.v).collect();
    let lay = layout(tree, &tris, variant.heap_levels());
    let [w, h] = camera.resolution;
    let npix = w as usize * h as usize;
    let bufs = upload_scene(dev, scene, tree, &lay, camera, light_offset)?;
    let model = Model::new(profile, &module.prog);
    let cache = NodeCacheFetches::new(&model, &module.prog, &lay.nodes);
    let args = bufs.launch_args();
    let launch =
        dev.launch_observed(module, variant.kernel(), LaunchConfig::linear(CTAS, THREADS), &args, Some(&cache))?;
    let rgba = dev.read::<f32>(bufs.color(), 4 * npix);
    let mut image = FrameBuffer::new(w, h);
    for (i, px) in rgba.chunks_exact(4).enumerate() {
        image.pixels[i] = [px[0], px[1], px[2]];
    }
    let mut trace = TraceStats::default();
    let counted = build == Build::Instrumented || dev.config().fidelity >= crate::sim::Fidelity::Instructions;
    match build {
        Build::Instrumented => {
            let st = dev.read::<u32>(bufs.stats(), STATS_WORDS * npix);
            for s in st.chunks_exact(STATS_WORDS) {
                trace.inner_nodes += s[0] as u64;
                trace.leaves += s[1] as u64;
                trace.plane_tests += s[2] as u64;
                trace.barycentric_tests += s[3] as u64;
                trace.rays += s[4] as u64;
                trace.tex_node_fetches += s[5] as u64;
                trace.local_stack_accesses += s[6] as u64;
                trace.shadow += s[7] as u64;
                trace.reflection += s[8] as u64;
                trace.texel_fetches += s[9] as u64;
                trace.pushes += s[10] as u64;
            }
        }
        Build::Plain if !counted => {}
        Build::Plain => {
            let c = line_counts(&module.prog, &launch, &count_tags(SOURCE));
            let get = |n: &str| c.get(n).copied().unwrap_or(0);
            trace.rays = get("rays");
            trace.inner_nodes = get("inner");
            trace.leaves = get("leaves");
            trace.plane_tests = get("planes");
            trace.barycentric_tests = get("barys");
            // `push`: a new entry to local memory; `spill`: stack cache I moving its
            // old head there; `regpush`: a new entry to registers (stack caches I, II)
            trace.local_stack_accesses = get("push") + get("spill") + get("pop");
            trace.pushes = get("push") + get("regpush");
            trace.shadow = get("shadow");
            trace.reflection = get("reflection");
            trace.texel_fetches = get("texels");
            trace.tex_node_fetches = trace.inner_nodes - cache.served().min(trace.inner_nodes);
        }
    }
    trace.primary = npix as u64;
    Ok(KernelRender {
        image,
        hit_tri: dev.read::<i32>(bufs.hit(), npix),
        trace,
        counted,
        launch,
        memory: model.finish(),
    })
}

/// Allocates a buffer named `name` holding `bytes` (at least 4 bytes, so that
/// an empty table still has an address) on `dev`.
pub fn upload(dev: &mut Device, bytes: &[u8], name: &str) -> Result<crate::sim::DevicePtr, SimError> {
    let p = dev.alloc_bytes(bytes.len().max(4) as u64, name);
    if !bytes.is_empty() {
        dev.write(p, bytes)?;
    }
    Ok(p)
}

/// The name of the kernels' job queue (a u32: the next pixel to claim, in
/// blocks of 32), which `render` reads for its progress.
pub const JOB_QUEUE: &str = "job_queue";

/// Loads the kernels' PTX (the plain build) on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    load_build(dev, Build::Plain)
}

/// Loads `build` of the kernels on `dev`.
pub fn load_build(dev: &mut Device, build: Build) -> Result<Module, SimError> {
    match build {
        Build::Plain => dev.load_ptx(PTX, "kernels/fabianowski2011/raytrace.ptx"),
        Build::Instrumented => dev.load_ptx(PTX_STATS, "kernels/fabianowski2011/raytrace_stats.ptx"),
    }
}
