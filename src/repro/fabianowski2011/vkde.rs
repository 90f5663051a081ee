//! Thesis 000 §5.2: variable kernel density estimation (VKDE) with kernels
//! built from photon differentials, on the emulator
//! (`kernels/fabianowski2011/vkde.cu`) and natively.
//!
//! **Construction** ([`construct`], §5.2.1–5.2.2, L2375–2448): at a stored
//! interaction, p is the parameter with the longer position differential D_p;
//! the interaction is discarded if the footprint height ‖D_p'‖|sin α| is below
//! f‖D_p‖ (eq. 5.33, f = 1/20); both differentials are dampened by the same
//! factor ‖D_p‖^(1/4)/‖D_p‖ (the printed formula divides vectors; extract
//! erratum 7); the semiprincipal axes are M = s Δp g D_p, m1 = s Δp g D_p' and
//! m2 = ‖m1‖ n̂ (m1 reoriented so that M, m1, m2 are right-handed); every axis
//! longer than h_max is clamped to h_max; the flux is stored as
//! Φ' = Φ/‖M × m1‖ (π A⁻¹ Φ with A = π‖M × m1‖) and m' = ‖m1‖ m̂ with
//! m = m1 × m2 replaces m1, m2. The kernel's AABB has the half-extents
//! √(M_i² + m1_i² + m2_i²) (L2412–2430 with extract erratum 6).
//!
//! **Estimation** ([`estimate`]): ‖d‖² = q² + ‖qM − δ‖²/‖m'‖² with
//! δ = x − z_j and q = (m'·δ)/(m'·M) (L2398–2408 with extract erratum 4); a
//! kernel contributes if ‖d‖² < 1 and its normal faces the query's side,
//! weighted by the uniform (1/π) or Epanechnikov ((1 − ‖d‖²)·2/π) kernel
//! (L1291): L_r(x) = (ρ/π) Σ_j K(‖d_j‖) Φ'_j for a diffuse reflectance ρ.
//!
//! **Photon map**: the kernels are gathered through a BVH over their AABBs
//! ([`PhotonMap`]), the structure chapter 6 introduces for VKDE because a
//! kd-tree over kernels of nonzero extent references one from many leaves
//! (L2547). Here it is the simplest such BVH: built on the host by object
//! median splits on the longest axis of the centroids' bounds, leaves of at
//! most [`LEAF_SIZE`] kernels, the complete 32-byte node (AABB and two
//! references, L986) and Alg. 3.5's strict point test. The VVH and LBVH
//! builders and the compact layout of chapter 6 are not here.
//!
//! **Normals** (fixture 8 of the extract): the thesis recovers n_j as
//! normalize(m' × M) (L2410), but with m2 = ‖m1‖n̂, m' × M = (m1·M) n̂
//! ([`recovered_normal`]): it flips with the sign of m1·M and vanishes for an
//! unskewed footprint, so the 9-float record cannot give the normal. The
//! kernel record stores n̂ (three more floats) and the back-face test is
//! n_j · n_x > 0.
//!
//! Both sides perform the same float operations in the same order (no
//! contraction, correctly rounded division and square root), so the emulated
//! kernels' records and estimates equal the native ones bit for bit
//! (`tests/vkde.rs`).

use std::cmp::Ordering::{Equal, Greater, Less};
use std::f32::consts::{FRAC_1_PI, FRAC_2_PI};

use super::photons::{Photon, PhotonError, SLOT, cross, delta_p, dot, len, scale};
use crate::sim::device::to_bytes;
use crate::sim::{Arg, Device, LaunchConfig, LaunchStats, Module, SimError};

/// The kernels' PTX (clang-16), compiled in.
pub const PTX: &str = include_str!("../../../kernels/fabianowski2011/vkde.ptx");
/// Entry: kernel construction, one thread per stored slot.
pub const CONSTRUCT: &str = "construct_kernels";
/// Entry: VKDE at query points, one thread per query.
pub const ESTIMATE: &str = "estimate_vkde";
/// The discard threshold f of eq. 5.33 (L2470: "threshold f = 1/20").
pub const F_DISCARD: f32 = 1.0 / 20.0;
/// The clamp of the semiprincipal axes (L2470: "h_max = 1").
pub const H_MAX: f32 = 1.0;
/// Most kernels in a photon-map leaf.
pub const LEAF_SIZE: usize = 8;
/// Floats of a constructed slot in the construction kernel's output.
pub const RECORD: usize = 24;
/// Floats of a kernel in the estimation kernel's input.
pub const KERNEL_FLOATS: usize = 16;
/// Floats of a query point.
pub const QUERY_FLOATS: usize = 12;
/// Floats of an estimate.
pub const ESTIMATE_FLOATS: usize = 8;
/// Entries of the traversal stack in the estimation kernel (bounds the tree's depth).
pub const STACK: usize = 64;
/// Threads per CTA of the launches.
pub const THREADS: u32 = 256;
/// At most this many CTAs; threads loop over their work.
pub const MAX_CTAS: u32 = 30;

/// The parameters of kernel construction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Photons emitted (sets the global Δp = √(4π/n), eq. 5.11).
    pub emitted: usize,
    /// Spread factor s (Table 5.1, per scene).
    pub spread: f32,
    /// Largest semiprincipal axis length h_max.
    pub h_max: f32,
    /// Discard threshold f.
    pub f: f32,
}

impl Settings {
    /// The thesis' settings for `emitted` photons and spread `spread` (f = 1/20, h_max = 1).
    pub fn thesis(emitted: usize, spread: f32) -> Settings {
        Settings { emitted, spread, h_max: H_MAX, f: F_DISCARD }
    }
}

/// A kernel built at a stored interaction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kernel {
    /// Centre z_j.
    pub z: [f32; 3],
    /// Semimajor axis M.
    pub major: [f32; 3],
    /// Semiminor axis m1 in the surface (reoriented, clamped).
    pub minor: [f32; 3],
    /// m' = ‖m1‖ (m1 × m2)/‖m1 × m2‖, stored instead of m1 and m2.
    pub m_prime: [f32; 3],
    /// Flux over the footprint's cut area, Φ' = Φ/‖M × m1‖.
    pub flux: [f32; 3],
    /// Unit surface normal on the photon's side.
    pub normal: [f32; 3],
    /// AABB corner z − e.
    pub lo: [f32; 3],
    /// AABB corner z + e.
    pub hi: [f32; 3],
    /// ‖M × m1‖ (the cut area over π; chapter 6's n_auto sums π times this).
    pub area: f32,
    /// Whether an axis was clamped to h_max.
    pub clamped: bool,
}

/// What construction made of a stored interaction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Construction {
    /// A degenerate footprint (eq. 5.33).
    Discarded,
    /// A kernel.
    Stored(Kernel),
}

impl Construction {
    /// The record as the construction kernel writes it (24 floats' bits):
    /// [0,3) z, [3,6) M, [6,9) m', [9,12) Φ', [12,15) n, [15,18) lo,
    /// [18,21) hi, 21 state (1 stored, 2 discarded), 22 clamped, 23 ‖M × m1‖.
    pub fn bits(&self) -> Vec<u32> {
        let mut v = vec![0u32; RECORD];
        match self {
            Construction::Discarded => v[21] = 2,
            Construction::Stored(k) => {
                for (i, a) in [k.z, k.major, k.m_prime, k.flux, k.normal, k.lo, k.hi].iter().enumerate() {
                    for c in 0..3 {
                        v[3 * i + c] = a[c].to_bits();
                    }
                }
                v[21] = 1;
                v[22] = if k.clamped { 1.0f32 } else { 0.0 }.to_bits();
                v[23] = k.area.to_bits();
            }
        }
        v
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Builds the kernel of interaction `p` (§5.2.1–5.2.2; see the module doc).
pub fn construct(p: &Photon, s: &Settings) -> Construction {
    let dp = delta_p(s.emitted);
    let (l1, l2) = (len(p.dz[0]), len(p.dz[1]));
    // p: the parameter with the longer position differential (ties: p1)
    let (a, b, la) = if l2 > l1 { (p.dz[1], p.dz[0], l2) } else { (p.dz[0], p.dz[1], l1) };
    // eq. 5.33: the footprint height |D_p'| |sin alpha| = |D_p x D_p'| / |D_p|
    let height = len(cross(a, b)) / la;
    // (negated, so that a NaN height discards)
    if !matches!(height.partial_cmp(&(s.f * la)), Some(Greater | Equal)) {
        return Construction::Discarded;
    }
    // dampening: |D_p|^(1/4) / |D_p| on both differentials, then the spanning vectors and the spread
    let g = la.sqrt().sqrt() / la;
    let k = dp * g * s.spread;
    let mut major = scale(a, k);
    let mut minor = scale(b, k);
    let n = p.normal;
    // M, m1, m2 = |m1| n right-handed
    if dot(cross(major, minor), n) < 0.0 {
        minor = scale(minor, -1.0);
    }
    let (lm, l1m) = (len(major), len(minor));
    let mut clamped = false;
    if lm > s.h_max {
        major = scale(major, s.h_max / lm);
        clamped = true;
    }
    let mut r1 = l1m;
    if l1m > s.h_max {
        minor = scale(minor, s.h_max / l1m);
        r1 = s.h_max;
        clamped = true;
    }
    let m2 = scale(n, r1);
    let area = len(cross(major, minor));
    let flux = [p.flux[0] / area, p.flux[1] / area, p.flux[2] / area];
    let m = cross(minor, m2);
    let m_prime = scale(m, r1 / len(m));
    let e: [f32; 3] = std::array::from_fn(|i| (major[i] * major[i] + minor[i] * minor[i] + m2[i] * m2[i]).sqrt());
    Construction::Stored(Kernel {
        z: p.z,
        major,
        minor,
        m_prime,
        flux,
        normal: n,
        lo: sub(p.z, e),
        hi: [p.z[0] + e[0], p.z[1] + e[1], p.z[2] + e[2]],
        area,
        clamped,
    })
}

/// The normal the thesis recovers from the 9-float record, m' × M (before
/// normalising, L2410). It equals (m1·M) n̂: zero for an unskewed kernel.
pub fn recovered_normal(k: &Kernel) -> [f32; 3] {
    cross(k.m_prime, k.major)
}

/// ‖d‖² of `x` in kernel `k` from its nine floats z, m', M (L2408 with the
/// extract's erratum 4): q = (m'·δ)/(m'·M), ‖d‖² = q² + ‖qM − δ‖²/‖m'‖².
pub fn d2(z: [f32; 3], m_prime: [f32; 3], major: [f32; 3], x: [f32; 3]) -> f32 {
    let d = sub(x, z);
    let q = dot(m_prime, d) / dot(m_prime, major);
    let r = [major[0] * q - d[0], major[1] * q - d[1], major[2] * q - d[2]];
    q * q + dot(r, r) / dot(m_prime, m_prime)
}

/// The smoothing kernel K (L1291), for ‖d‖ < 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Shape {
    /// K = 1/π.
    Uniform,
    /// K = (1 − ‖d‖²)/(π/2).
    Epanechnikov,
}

impl Shape {
    /// The kernel's value at ‖d‖² = `d2` (< 1).
    pub fn weight(self, d2: f32) -> f32 {
        match self {
            Shape::Uniform => FRAC_1_PI,
            Shape::Epanechnikov => (1.0 - d2) * FRAC_2_PI,
        }
    }

    /// The kernels' code for it.
    pub fn code(self) -> i32 {
        match self {
            Shape::Uniform => 0,
            Shape::Epanechnikov => 1,
        }
    }

    /// By name: `uniform`, `epanechnikov`.
    pub fn parse(s: &str) -> Option<Shape> {
        match s {
            "uniform" => Some(Shape::Uniform),
            "epanechnikov" => Some(Shape::Epanechnikov),
            _ => None,
        }
    }
}

/// A query point: a diffuse surface point seen by a primary or reflection ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Query {
    /// Position x.
    pub x: [f32; 3],
    /// Unit normal facing the ray.
    pub n: [f32; 3],
    /// Reflectance ρ (k_d, times the mirror's tint for a reflection hit): L = (ρ/π) Σ K Φ'.
    pub weight: [f32; 3],
}

impl Query {
    /// The query's floats as the estimation kernels read them: [x, 1, n, 0, ρ, 0].
    pub fn floats(q: Option<&Query>) -> [f32; QUERY_FLOATS] {
        match q {
            None => [0.0; QUERY_FLOATS],
            Some(q) => {
                [q.x[0], q.x[1], q.x[2], 1.0, q.n[0], q.n[1], q.n[2], 0.0, q.weight[0], q.weight[1], q.weight[2], 0.0]
            }
        }
    }
}

/// A density estimate at a query point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Estimate {
    /// Reflected radiance L_r (RGB).
    pub radiance: [f32; 3],
    /// Interactions contributing (‖d‖ < 1, facing side).
    pub contributions: u32,
    /// Nodes whose AABB was tested (n_T).
    pub nodes: u32,
    /// Interactions retrieved from leaves (n_I).
    pub retrieved: u32,
}

impl Estimate {
    /// The fields' bits, for exact comparison.
    pub fn bits(&self) -> [u32; 6] {
        let r = self.radiance.map(f32::to_bits);
        [r[0], r[1], r[2], self.contributions, self.nodes, self.retrieved]
    }

    /// From an estimation kernel's eight floats.
    pub fn from_floats(s: &[f32]) -> Estimate {
        Estimate {
            radiance: [s[0], s[1], s[2]],
            contributions: s[3].to_bits(),
            nodes: s[4].to_bits(),
            retrieved: s[5].to_bits(),
        }
    }
}

/// A node of the photon map (32 bytes on the device: lo, hi, a, b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// AABB lower corner.
    pub lo: [f32; 3],
    /// AABB upper corner.
    pub hi: [f32; 3],
    /// Inner: left child; leaf: first kernel.
    pub a: u32,
    /// Inner: right child; leaf: count | [`LEAF_BIT`].
    pub b: u32,
}

/// The bit of [`Node::b`] that marks a leaf.
pub const LEAF_BIT: u32 = 0x8000_0000;

/// A BVH photon map over kernels (see the module doc).
#[derive(Debug, Clone, Default)]
pub struct PhotonMap {
    /// Nodes, the root first.
    pub nodes: Vec<Node>,
    /// The kernels in leaf order.
    pub kernels: Vec<Kernel>,
    /// Depth (a lone leaf: 1).
    pub depth: usize,
}

impl PhotonMap {
    /// Builds the map over `kernels` (object median split on the centroids'
    /// longest axis, ties by index, leaves of at most [`LEAF_SIZE`]).
    pub fn build(kernels: &[Kernel]) -> PhotonMap {
        let mut map = PhotonMap::default();
        if kernels.is_empty() {
            return map;
        }
        let mut idx: Vec<u32> = (0..kernels.len() as u32).collect();
        map.depth = map.split(kernels, &mut idx, 0, 1);
        map
    }

    fn split(&mut self, all: &[Kernel], idx: &mut [u32], first: usize, depth: usize) -> usize {
        let me = self.nodes.len();
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        let mut clo = [f32::INFINITY; 3];
        let mut chi = [f32::NEG_INFINITY; 3];
        for &i in idx.iter() {
            let k = &all[i as usize];
            for c in 0..3 {
                lo[c] = lo[c].min(k.lo[c]);
                hi[c] = hi[c].max(k.hi[c]);
                clo[c] = clo[c].min(k.z[c]);
                chi[c] = chi[c].max(k.z[c]);
            }
        }
        self.nodes.push(Node { lo, hi, a: 0, b: 0 });
        if idx.len() <= LEAF_SIZE {
            self.nodes[me].a = first as u32;
            self.nodes[me].b = idx.len() as u32 | LEAF_BIT;
            self.kernels.extend(idx.iter().map(|&i| all[i as usize]));
            return depth;
        }
        let ext = [chi[0] - clo[0], chi[1] - clo[1], chi[2] - clo[2]];
        let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
            0
        } else if ext[1] >= ext[2] {
            1
        } else {
            2
        };
        idx.sort_by(|&p, &q| all[p as usize].z[axis].total_cmp(&all[q as usize].z[axis]).then(p.cmp(&q)));
        let mid = idx.len() / 2;
        let (l, r) = idx.split_at_mut(mid);
        let left = self.nodes.len();
        let dl = self.split(all, l, first, depth + 1);
        let right = self.nodes.len();
        let dr = self.split(all, r, first + mid, depth + 1);
        self.nodes[me].a = left as u32;
        self.nodes[me].b = right as u32;
        dl.max(dr)
    }

    /// The nodes as the estimation kernel reads them.
    pub fn node_bytes(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(32 * self.nodes.len());
        for n in &self.nodes {
            v.extend(to_bytes(&[n.lo[0], n.lo[1], n.lo[2], n.hi[0], n.hi[1], n.hi[2]]));
            v.extend(to_bytes(&[n.a, n.b]));
        }
        v
    }

    /// The kernels as the estimation kernel reads them: [z, M, m', Φ', n, 0].
    pub fn kernel_floats(&self) -> Vec<f32> {
        let mut v = Vec::with_capacity(KERNEL_FLOATS * self.kernels.len());
        for k in &self.kernels {
            for a in [k.z, k.major, k.m_prime, k.flux, k.normal] {
                v.extend_from_slice(&a);
            }
            v.push(0.0);
        }
        v
    }
}

/// The stored kernels of `photons` (each photon's 2nd and 3rd interaction), with counts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Constructed {
    /// The kernels, in slot order.
    pub kernels: Vec<Kernel>,
    /// Stored interactions (kernels and discarded ones).
    pub interactions: usize,
    /// Discarded by eq. 5.33.
    pub discarded: usize,
    /// Kernels with a clamped axis.
    pub clamped: usize,
}

impl Constructed {
    /// Collects the constructions of the slots in order.
    pub fn collect<'a>(c: impl Iterator<Item = &'a Construction>) -> Constructed {
        let mut out = Constructed::default();
        for c in c {
            out.interactions += 1;
            match c {
                Construction::Discarded => out.discarded += 1,
                Construction::Stored(k) => {
                    out.clamped += k.clamped as usize;
                    out.kernels.push(*k);
                }
            }
        }
        out
    }
}

/// The native reference of construction over every stored slot, in slot order.
pub fn construct_all(photons: &[[Option<Photon>; 2]], s: &Settings) -> Vec<Construction> {
    photons.iter().flatten().flatten().map(|p| construct(p, s)).collect()
}

/// The native estimate at `q` with `shape` (the estimation kernel's traversal, step for step).
pub fn estimate(map: &PhotonMap, q: &Query, shape: Shape) -> Estimate {
    let mut e = Estimate::default();
    if map.nodes.is_empty() {
        return e;
    }
    let x = q.x;
    let mut sum = [0.0f32; 3];
    let mut stack = [0u32; STACK];
    let mut size = 1;
    while size > 0 {
        size -= 1;
        let nd = &map.nodes[stack[size] as usize];
        e.nodes += 1;
        // Alg. 3.5: strict inequalities
        if !(nd.lo[0] < x[0]
            && nd.lo[1] < x[1]
            && nd.lo[2] < x[2]
            && nd.hi[0] > x[0]
            && nd.hi[1] > x[1]
            && nd.hi[2] > x[2])
        {
            continue;
        }
        if nd.b & LEAF_BIT == 0 {
            stack[size] = nd.b;
            stack[size + 1] = nd.a;
            size += 2;
            continue;
        }
        for k in &map.kernels[nd.a as usize..(nd.a + (nd.b & !LEAF_BIT)) as usize] {
            e.retrieved += 1;
            if dot(k.normal, q.n).partial_cmp(&0.0) != Some(Greater) {
                continue;
            }
            let d = d2(k.z, k.m_prime, k.major, x);
            if d.partial_cmp(&1.0) != Some(Less) {
                continue;
            }
            let w = shape.weight(d);
            for (s, f) in sum.iter_mut().zip(k.flux) {
                *s += w * f;
            }
            e.contributions += 1;
        }
    }
    e.radiance = std::array::from_fn(|c| q.weight[c] * FRAC_1_PI * sum[c]);
    e
}

/// The photon slots as the construction kernel reads them (the photon kernel's output layout).
pub fn slot_floats(photons: &[[Option<Photon>; 2]]) -> Vec<f32> {
    let mut v = Vec::new();
    for p in photons.iter().flatten().flatten() {
        let b = p.bits();
        v.extend(b[..21].iter().map(|x| f32::from_bits(*x)));
        v.extend([f32::from_bits(p.tri), f32::from_bits(p.interaction), 1.0]);
    }
    debug_assert_eq!(v.len() % SLOT, 0);
    v
}

/// Loads the VKDE kernels' PTX on `dev`.
pub fn load(dev: &mut Device) -> Result<Module, SimError> {
    dev.load_ptx(PTX, "kernels/fabianowski2011/vkde.ptx")
}

fn ctas(n: usize) -> u32 {
    (n.div_ceil(THREADS as usize) as u32).clamp(1, MAX_CTAS)
}

/// Runs the construction kernel over the stored interactions of `photons`.
pub fn construct_kernel(
    dev: &mut Device,
    module: &Module,
    photons: &[[Option<Photon>; 2]],
    s: &Settings,
) -> Result<(Vec<Construction>, LaunchStats), PhotonError> {
    construct_kernel_observed(dev, module, photons, s, None)
}

/// As [`construct_kernel`], the launch observed by `model` when given.
pub fn construct_kernel_observed(
    dev: &mut Device,
    module: &Module,
    photons: &[[Option<Photon>; 2]],
    s: &Settings,
    model: Option<&crate::model::Model>,
) -> Result<(Vec<Construction>, LaunchStats), PhotonError> {
    let slots = slot_floats(photons);
    let n = slots.len() / SLOT;
    if n > i32::MAX as usize {
        return Err(PhotonError::TooMany(n));
    }
    let mut params = to_bytes(&[delta_p(s.emitted), s.spread, s.h_max, s.f]);
    params.extend_from_slice(&(n as i32).to_le_bytes());
    let up = crate::host::rt_kernels::upload;
    let pp = up(dev, &params, "params")?;
    let inp = up(dev, &to_bytes(&slots), "slots")?;
    let out = dev.alloc_zeroed::<f32>(RECORD * n.max(1));
    let args: Vec<Arg> = [pp, inp, out].into_iter().map(Arg::Ptr).collect();
    let observer = model.map(|m| m as &dyn crate::sim::ObserverFactory);
    let launch = dev.launch_observed(module, CONSTRUCT, LaunchConfig::linear(ctas(n), THREADS), &args, observer)?;
    let raw = dev.read::<f32>(out, RECORD * n);
    Ok((raw.chunks_exact(RECORD).map(record).collect(), launch))
}

fn record(r: &[f32]) -> Construction {
    if r[21].to_bits() == 2 {
        return Construction::Discarded;
    }
    let v = |a: usize| [r[a], r[a + 1], r[a + 2]];
    let (major, m_prime, normal) = (v(3), v(6), v(12));
    // m1 is not in the record: m1 = n x m' up to rounding (m' = m1 x n for m1 in the surface)
    let minor = cross(normal, m_prime);
    Construction::Stored(Kernel {
        z: v(0),
        major,
        minor,
        m_prime,
        flux: v(9),
        normal,
        lo: v(15),
        hi: v(18),
        area: r[23],
        clamped: r[22] == 1.0,
    })
}

/// Runs the estimation kernel at `queries` (`None`: no diffuse surface seen; estimate 0).
pub fn estimate_kernel(
    dev: &mut Device,
    module: &Module,
    map: &PhotonMap,
    queries: &[Option<Query>],
    shape: Shape,
) -> Result<(Vec<Estimate>, LaunchStats), PhotonError> {
    estimate_kernel_observed(dev, module, map, queries, shape, None)
}

/// As [`estimate_kernel`], the launch observed by `model` when given (a memory model for the timing model).
pub fn estimate_kernel_observed(
    dev: &mut Device,
    module: &Module,
    map: &PhotonMap,
    queries: &[Option<Query>],
    shape: Shape,
    model: Option<&crate::model::Model>,
) -> Result<(Vec<Estimate>, LaunchStats), PhotonError> {
    let n = queries.len();
    if n > i32::MAX as usize {
        return Err(PhotonError::TooMany(n));
    }
    let q: Vec<f32> = queries.iter().flat_map(|q| Query::floats(q.as_ref())).collect();
    let mut params = to_bytes(&[n as i32, shape.code(), map.nodes.len() as i32]);
    params.extend_from_slice(&0i32.to_le_bytes());
    let up = crate::host::rt_kernels::upload;
    let pp = up(dev, &params, "params")?;
    let nodes = up(dev, &map.node_bytes(), "nodes")?;
    let kernels = up(dev, &to_bytes(&map.kernel_floats()), "kernels")?;
    let qb = up(dev, &to_bytes(&q), "queries")?;
    let out = dev.alloc_zeroed::<f32>(ESTIMATE_FLOATS * n.max(1));
    let args: Vec<Arg> = [pp, nodes, kernels, qb, out].into_iter().map(Arg::Ptr).collect();
    let observer = model.map(|m| m as &dyn crate::sim::ObserverFactory);
    let launch = dev.launch_observed(module, ESTIMATE, LaunchConfig::linear(ctas(n), THREADS), &args, observer)?;
    let raw = dev.read::<f32>(out, ESTIMATE_FLOATS * n);
    Ok((raw.chunks_exact(ESTIMATE_FLOATS).map(Estimate::from_floats).collect(), launch))
}
