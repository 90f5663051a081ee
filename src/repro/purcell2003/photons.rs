//! Breadth-first photon tracing (seed 004 §2.1): an emission pass and one
//! pass per bounce, each writing its own frame of the photon arrays
//! (`kernels/purcell2003/photons.cu`), and the eye rays that give the
//! radiance estimate its query points.

use glam::Vec3;

use super::passes::{Bytes, Kernels, Passes};
use crate::host::camera::Camera;
use crate::host::scene::{Light, MaterialKind, Scene};
use crate::sim::{Arg, DevicePtr, SimError};

/// Phase name of photon tracing.
pub const TRACE_PHOTONS: &str = "trace photons";
/// Phase name of the eye rays.
pub const TRACE_RAYS: &str = "trace rays";

/// A scene as the kernels read it.
#[derive(Debug, Clone)]
pub struct Geometry {
    /// 12 floats per triangle: v0, e1, e2, the material index's bits, 2 unused.
    pub tris: Vec<f32>,
    /// Two float4 per material: (r, g, b, kind) and (ior, 0, 0, 0).
    pub mats: Vec<f32>,
    /// Emissive triangles (the area light); empty for a point light.
    pub lights: Vec<i32>,
    /// The point light's position (when `lights` is empty).
    pub point: Vec3,
    /// Power of one emitted photon when `n` are emitted: the light's power / `n` (set by [`Geometry::power_per_photon`]).
    pub light_power: [f32; 3],
    /// The point light's emission cone (a projection map): unit axis and the
    /// cosine of its half-angle, the smallest cone about the direction to the
    /// scene's bounding sphere that holds the sphere; (0, 0, 1, -1), the whole
    /// sphere, for an area light or a point light inside the sphere.
    pub cone: [f32; 4],
    /// What the shadow rays see of the light: an area light's emitted
    /// radiance (its first triangle's material), a point light's intensity.
    pub radiance: [f32; 3],
    /// Scene bounds.
    pub lo: Vec3,
    /// Scene bounds.
    pub hi: Vec3,
}

impl Geometry {
    /// The kernels' layout of `scene`. Its light: the area light (emissive
    /// triangles) when it has one, else its first point light.
    pub fn of(scene: &Scene) -> Geometry {
        let mut tris = Vec::with_capacity(scene.triangles.len() * 12);
        for t in &scene.triangles {
            let [a, b, c] = t.v;
            let (e1, e2) = (b - a, c - a);
            tris.extend_from_slice(&[a.x, a.y, a.z, e1.x, e1.y, e1.z, e2.x, e2.y, e2.z]);
            tris.extend_from_slice(&[f32::from_bits(t.material), 0.0, 0.0]);
        }
        let mut mats = Vec::new();
        for m in &scene.materials {
            let (kind, ior) = match m.kind {
                MaterialKind::Diffuse => (0.0, 1.0),
                MaterialKind::Mirror => (1.0, 1.0),
                MaterialKind::Glass { ior } => (2.0, ior),
                MaterialKind::Emitter => (3.0, 1.0),
            };
            mats.extend_from_slice(&[m.color[0], m.color[1], m.color[2], kind, ior, 0.0, 0.0, 0.0]);
        }
        let area: Vec<i32> = scene
            .lights
            .iter()
            .find_map(|l| match l {
                Light::Area { triangles } if !triangles.is_empty() => {
                    Some(triangles.iter().map(|&t| t as i32).collect())
                }
                _ => None,
            })
            .unwrap_or_default();
        let (mut point, mut power, mut radiance) = (Vec3::ZERO, [0.0f32; 3], [0.0f32; 3]);
        if area.is_empty() {
            if let Some((p, i)) = scene.lights.iter().find_map(|l| match l {
                Light::Point { position, intensity } => Some((*position, *intensity)),
                _ => None,
            }) {
                point = Vec3::from(p);
                radiance = i;
                // flux of an isotropic point light: 4 pi I
                power = i.map(|x| x * 4.0 * std::f32::consts::PI);
            }
        } else {
            let first = &scene.materials[scene.triangles[area[0] as usize].material as usize];
            radiance = first.emission.map(|e| e.max(0.0));
            // flux of a Lambertian emitter: pi * emission * area
            for &t in &area {
                let tr = &scene.triangles[t as usize];
                let m = &scene.materials[tr.material as usize];
                let a = 0.5 * (tr.v[1] - tr.v[0]).cross(tr.v[2] - tr.v[0]).length();
                for (k, p) in power.iter_mut().enumerate() {
                    *p += std::f32::consts::PI * m.emission[k].max(0.0) * a;
                }
            }
        }
        let (lo, hi) = scene.bounds();
        let mut cone = [0.0, 0.0, 1.0, -1.0];
        if area.is_empty() {
            let (c, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
            let to = c - point;
            let dist = to.length();
            if dist > radius {
                let a = to / dist;
                cone = [a.x, a.y, a.z, (1.0 - (radius / dist).powi(2)).sqrt()];
            }
        }
        Geometry { tris, mats, lights: area, point, light_power: power, cone, radiance, lo, hi }
    }

    /// Triangles.
    pub fn num_tris(&self) -> usize {
        self.tris.len() / 12
    }

    /// Power carried by each of `n` emitted photons: the light's power into
    /// the emission cone (its solid angle's share of the sphere, (1 - cos) / 2)
    /// over `n`.
    pub fn power_per_photon(&self, n: usize) -> [f32; 3] {
        let share = (1.0 - self.cone[3]) * 0.5;
        self.light_power.map(|p| p * share / n.max(1) as f32)
    }

    /// The rays' offset from their origin surface (scene-relative).
    pub fn eps(&self) -> f32 {
        (self.hi - self.lo).length().max(1e-3) * 1e-4
    }

    /// The `Scene` structure of the kernels.
    fn scene_arg(&self, n: usize) -> Arg {
        let eps = self.eps();
        let pw = self.power_per_photon(n);
        Bytes::default()
            .i32s(&[self.num_tris() as i32, self.lights.len() as i32])
            .f32s(&[eps, 0.0, self.point.x, self.point.y, self.point.z, 0.0, pw[0], pw[1], pw[2], 0.0])
            .f32s(&self.cone)
            .f32s(&[self.radiance[0], self.radiance[1], self.radiance[2], 0.0])
            .arg()
    }
}

/// The photon arrays on the device: `frames` frames of `n` photons, four float4 arrays.
#[derive(Debug, Clone, Copy)]
pub struct PhotonArrays {
    /// Photons per frame (emitted photons).
    pub n: usize,
    /// Frames: the emission and one per bounce.
    pub frames: usize,
    /// (x, y, z, stored).
    pub pos: DevicePtr,
    /// (r, g, b, alive).
    pub pow: DevicePtr,
    /// (incoming direction, 0).
    pub dir: DevicePtr,
    /// (outgoing direction, 0).
    pub out: DevicePtr,
}

impl PhotonArrays {
    /// Slots of the bounce frames (1..frames), where stored photons are.
    pub fn stored_slots(&self) -> (usize, usize) {
        (self.n, self.n * (self.frames - 1))
    }

    /// Photons stored (valid slots of the bounce frames), read back.
    pub fn count_stored(&self, passes: &Passes) -> usize {
        let (first, count) = self.stored_slots();
        let pos = passes.dev.read::<f32>(self.pos, 4 * (first + count));
        (first..first + count).filter(|&s| pos[4 * s + 3] != 0.0).count()
    }
}

/// Traces `n` photons through `bounces` bounces: one emission pass and one
/// pass per bounce, in phase [`TRACE_PHOTONS`]. `direct`: whether photons
/// that land on a diffuse surface straight from the light are stored (the
/// pipeline leaves them out: its shadow rays give direct light).
pub fn trace(
    passes: &mut Passes,
    geo: &Geometry,
    n: usize,
    bounces: usize,
    seed: u32,
    direct: bool,
) -> Result<PhotonArrays, SimError> {
    let frames = bounces + 1;
    let tris = passes.upload(&geo.tris)?;
    let mats = passes.upload(&geo.mats)?;
    let lights = passes.upload(&geo.lights)?;
    let total = 4 * n * frames;
    let pos = passes.dev.alloc_zeroed::<f32>(total);
    let pow = passes.dev.alloc_zeroed::<f32>(total);
    let dir = passes.dev.alloc_zeroed::<f32>(total);
    let out = passes.dev.alloc_zeroed::<f32>(total);
    let c = (geo.lo + geo.hi) * 0.5;
    let sc = geo.scene_arg(n);
    passes.launch_1d(
        TRACE_PHOTONS,
        Kernels::Photons,
        "emit",
        n,
        &[
            sc.clone(),
            Arg::Ptr(tris),
            Arg::Ptr(lights),
            Arg::Ptr(pos),
            Arg::Ptr(pow),
            Arg::Ptr(dir),
            Arg::Ptr(out),
            Arg::I32(n as i32),
            Arg::U32(seed),
            Arg::F32(c.x),
            Arg::F32(c.y),
            Arg::F32(c.z),
        ],
    )?;
    for b in 1..=bounces {
        passes.launch_1d(
            TRACE_PHOTONS,
            Kernels::Photons,
            "bounce",
            n,
            &[
                sc.clone(),
                Arg::Ptr(tris),
                Arg::Ptr(mats),
                Arg::Ptr(pos),
                Arg::Ptr(pow),
                Arg::Ptr(dir),
                Arg::Ptr(out),
                Arg::I32(n as i32),
                Arg::I32(b as i32),
                Arg::U32(seed),
                Arg::I32(i32::from(direct)),
            ],
        )?;
    }
    Ok(PhotonArrays { n, frames, pos, pow, dir, out })
}

/// Query points of the radiance estimate: per pixel the first diffuse hit
/// (x, y, z, 1; w = 0: none), its normal facing the eye and its albedo.
#[derive(Debug, Clone, Copy)]
pub struct Queries {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Hit points.
    pub query: DevicePtr,
    /// Normals.
    pub normal: DevicePtr,
    /// Albedos.
    pub albedo: DevicePtr,
}

/// The kernel `eye_rays`' camera: position, forward, right, up, tan(fov_y / 2), aspect.
pub fn camera_array(camera: &Camera) -> [f32; 14] {
    let (r, u, f) = camera.frame();
    let [w, h] = camera.resolution;
    let tan = (camera.fov_y.to_radians() * 0.5).tan();
    [
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
        tan,
        w as f32 / h as f32,
    ]
}

/// Eye rays through `camera`'s pixels (one per pixel), followed through up to
/// `depth` specular hits, in phase [`TRACE_RAYS`].
pub fn eye_rays(passes: &mut Passes, geo: &Geometry, camera: &Camera, depth: u32) -> Result<Queries, SimError> {
    let [w, h] = camera.resolution;
    let cam = camera_array(camera);
    let tris = passes.upload(&geo.tris)?;
    let mats = passes.upload(&geo.mats)?;
    let camp = passes.upload(&cam)?;
    let npix = (w * h) as usize;
    let query = passes.dev.alloc_zeroed::<f32>(4 * npix);
    let normal = passes.dev.alloc_zeroed::<f32>(4 * npix);
    let albedo = passes.dev.alloc_zeroed::<f32>(4 * npix);
    passes.launch_1d(
        TRACE_RAYS,
        Kernels::Photons,
        "eye_rays",
        npix,
        &[
            geo.scene_arg(1),
            Arg::Ptr(tris),
            Arg::Ptr(mats),
            Arg::Ptr(camp),
            Arg::I32(w as i32),
            Arg::I32(h as i32),
            Arg::I32(depth as i32),
            Arg::Ptr(query),
            Arg::Ptr(normal),
            Arg::Ptr(albedo),
        ],
    )?;
    Ok(Queries { width: w, height: h, query, normal, albedo })
}

/// Direct illumination at the query points `q`: `samples` shadow rays per
/// pixel to the light (kernel `shadow_rays`), in phase [`TRACE_RAYS`]; the
/// buffer of per-pixel radiance (r, g, b, 0).
pub fn shadow_rays(
    passes: &mut Passes,
    geo: &Geometry,
    q: &Queries,
    samples: u32,
    seed: u32,
) -> Result<DevicePtr, SimError> {
    let tris = passes.upload(&geo.tris)?;
    let lights = passes.upload(&geo.lights)?;
    let npix = (q.width * q.height) as usize;
    let direct = passes.dev.alloc_zeroed::<f32>(4 * npix);
    passes.launch_1d(
        TRACE_RAYS,
        Kernels::Photons,
        "shadow_rays",
        npix,
        &[
            geo.scene_arg(1),
            Arg::Ptr(tris),
            Arg::Ptr(lights),
            Arg::Ptr(q.query),
            Arg::Ptr(q.normal),
            Arg::Ptr(q.albedo),
            Arg::I32(npix as i32),
            Arg::I32(samples as i32),
            Arg::U32(seed),
            Arg::Ptr(direct),
        ],
    )?;
    Ok(direct)
}

/// The kernels' random number for (seed, item, pass, dimension), in [0, 1)
/// (`rng_unit` in photons.cu): lowbias32 hashes of the counters.
pub fn rng_unit(seed: u32, item: u32, pass: u32, dim: u32) -> f32 {
    let h = hash32(seed ^ hash32(item ^ hash32(pass.wrapping_mul(8).wrapping_add(dim))));
    (h >> 8) as f32 * (1.0 / 16777216.0)
}

/// lowbias32 (Chris Wellons' integer hash).
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846ca68b);
    x ^= x >> 16;
    x
}
