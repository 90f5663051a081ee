#!/usr/bin/env python3
"""Renders a Mitsuba 3 reference of a warplight scene for the path tracer's
statistical test (tests/lin2017_reference.rs).

Exports the scene exactly as warplight's path tracer sees it: the OBJ's
polygons as triangle fans, per material (MTL Kd, or an override of the scene
file), Lambertian BSDFs made two-sided (warplight's diffuse reflects on both
sides; Mitsuba's `diffuse` on the front only), emitters one-sided (the
winding's normal, as warplight) with a black BSDF, the pinhole camera with
the same vertical field of view, and the longest path (max_depth = bounces + 1).

Mirrors: a smooth mirror (warplight: the colour times the mirror direction)
is Mitsuba's `conductor` with `material = "none"` (Fresnel 1) and
`specular_reflectance` the colour. A rough mirror (`roughness` = Beckmann
alpha; warplight: Cook-Torrance with Beckmann's D, Walter et al.'s
approximation of Smith's G, Schlick's F with R0 the colour) is
`roughconductor` with `distribution = "beckmann"`, the same `alpha`,
`material = "none"` and `specular_reflectance` the colour: Mitsuba's
Beckmann D and its G1 (the same rational approximation) are the same
functions; its F is the colour at every angle, Schlick's only when R0 = 1,
so a rough mirror whose colour is not white is refused (not comparable).
Both are made two-sided (warplight's mirrors reflect on both sides).
Mitsuba samples visible normals, warplight D cos: the same BSDF, other
pdfs, equal in expectation. An anisotropic mirror (`roughness = [ax, ay]`,
thesis 003 §5.1) is `roughconductor` with `alpha_u` = ax and `alpha_v` = ay
(an anisotropic rough glass likewise `roughdielectric`)
(its G1 takes the projected roughness, as warplight's): warplight lays α_x
along b1 of Duff et al.'s basis around each triangle's winding normal, and
Mitsuba along its shading frame's s, which follows dp/du; so the tool gives
the material's triangles texture coordinates (u, v) = (p . b1, p . b2), whose
dp/du is b1, and checks after loading that s is b1 on every such triangle
(`check_tangents`). Glass with the thesis' Schlick Fresnel (the
default) is refused: Mitsuba's dielectrics use the exact Fresnel equations,
not comparable. A glass whose scene file says `fresnel = "exact"` (warplight:
the exact equations, path.cu's fresnel_exact()) is Mitsuba's `dielectric`
(smooth) or `roughdielectric` (`distribution = "beckmann"`, the same
`alpha`), `int_ior` its IOR, `ext_ior` 1, both specular weights the colour.
Neither is two-sided: both renderers take the side from the winding's normal.
warplight scales refracted radiance by eta^2 only at rough glass; in a closed
object the factors of entering and leaving cancel, so only closed glass
objects are comparable (the tool does not check that).

Environment: a scene's `environment` (an equirectangular map, thesis 003
§5.4) is Mitsuba's `envmap` with the identity `to_world`: warplight's lookup
(kernels/lin2017/path.cu, env()) is written to Mitsuba's conventions (y up,
u = atan2(x, -z) / 2 pi, v = acos(y) / pi, texel columns centred half a
texel right of u = 0, rows on the grid v = row / (H - 1), bilinear, periodic
in u). Before rendering, the tool checks that: `lookup()` below, the same
formula in numpy, against the loaded emitter's eval() in 4,096 random
directions and the 4 horizontal axes (`--check-envmap` checks only). A scene without
an area light is allowed when it has an environment.

The pixel filter: warplight jitters a tent-distributed sample (radius one
subpixel) in each of the 2 x 2 subpixels of a pixel (smallpt's filter).
Mitsuba renders the same at twice the resolution with a tent filter of
radius 1 (film pixel = subpixel) and the film's border sampled, and this
tool averages each 2 x 2 block: the same pixel estimate in expectation.

Participating media (thesis 003 §5.2): a scene's `[medium]` (homogeneous:
no `height_scale`, no `emission`; Mitsuba's homogeneous medium does not
emit and an exponential density would need a grid volume, so those are
refused) is a `homogeneous` medium (`sigma_t` = sigma_a + sigma_s, `albedo`
= sigma_s / sigma_t, an `hg` phase function with the same g) inside a `cube`
with a `null` BSDF over the medium's box (the scene's bounds when it gives
none), and the integrator is `volpath`. warplight's march is single
scattering from direct light only, with the indirect in-scattering
neglected (003:L379); Mitsuba's volpath computes every order of scattering.
They compute the same light transport only at one bounce: warplight's
`--bounces 1` (the camera ray's in-scattered direct light, the direct light
at the first surface, both attenuated by Beer's law, and the light seen
directly) is Mitsuba's `max_depth = 2` (paths of at most one scattering
event, in the medium or at a surface). Give `--bounces 1` for a medium.
The medium's box must not be crossed between a scattering and the light:
with the smog 1 cm inside the walls and below the light, Mitsuba's
in-scattering near the light came out 3 to 70 times below warplight's, and
an independent numerical integration of the single-scattering integral
along those camera rays (numpy, f64) agreed with warplight (0.0323 against
0.0349, 0.724 against 0.775 red, pixel centre against pixel mean) and not
with Mitsuba (0.0005, 0.266): at max_depth 2, volpath apparently loses a
phase-sampled ray that passes the null boundary on its way to the light,
while its MIS weights still count that technique. The committed scene's box
therefore encloses the whole room (1 cm outside its walls).
Translucent materials (thesis 003 §5.3, warplight's `kind = "translucent"`,
path.cu's translucent()): a smooth `dielectric` (the IOR; only with
`fresnel = "exact"` and `translucency = 1`: the diffuse branch of the
thesis' 3-way switch is not exported) whose `interior` is `homogeneous`
with sigma_t = sigma_s' + sigma_a, albedo sigma_s' / sigma_t and `hg` g,
where sigma_s' = (1 - g) sigma_s is the reduced coefficient the thesis
draws its free paths with; the integrator is `volpath`. warplight scatters
at most once per stay inside; Mitsuba at every order. Both count a path by
its interactions (surface events and medium scatterings; max_depth =
bounces + 1), and a stay with two scatterings needs entry, two
scatterings and exit, 4 interactions before the light: at `--bounces 3`
(max_depth 4) and below, both count exactly the same paths (none, one
scattering per stay; the unscattered legs' transmittance). `--all-orders`
lifts the limit for the high-albedo comparison (not the same estimand).
Texture maps (thesis 003 §5.4): a diffuse material with `albedo_map`,
`roughness_map` and `metalness_map` is, in warplight's path tracer, the
blend (1 - m) albedo / pi + m f_CT of a Lambertian lobe and a Cook-Torrance
conductor with Beckmann alpha = roughness texel / 255 (at least 1e-4) and
Schlick's F with R0 = lerp(white, albedo, m), m the metalness texel, picked
per hit with probability m (texture_hit in kernels/lin2017/path.cu); 8-bit
maps, linear (no sRGB decoding), nearest texel, repeated. It is exported as
`twosided` over a `blendbsdf` whose `weight` is the metalness map, of a
`diffuse` with the albedo map as reflectance and a `roughconductor`
(`beckmann`, `material = "none"`, `alpha` a float map of the same alphas)
with specular reflectance 1: every map a `bitmap` with `filter_type =
"nearest"`, `raw = true`, wrapped by repetition. Mitsuba's conductor
reflects its colour at every angle, Schlick's only when R0 = 1: the tool
refuses a map set whose metal (metalness > 0) is not white in the albedo
map, and a colour other than white. The texture coordinates are the scene
file's `planar` mapping, written as the OBJ's `vt` (Mitsuba flips v on
load, so its row floor((1 - v) H) is warplight's); before rendering, the
tool checks Mitsuba's nearest lookup against warplight's texel rule at
4,096 random coordinates per map (`check_bitmap()`).
Variance: the reference is rendered in B independent batches (seeds
0..B-1); the mean image is their mean and the variance image the batch
variance divided by B (the variance of the mean).

Needs `pip install mitsuba numpy` (not needed by the build or CI).
Usage (the committed fixtures were made by):
  python3 tools/mitsuba/reference.py scenes/cornell-lambert.toml \
      --size 32 --batches 16 --spp 1024 --bounces 16 \
      --out tests/fixtures/mitsuba/cornell-lambert-32
  python3 tools/mitsuba/reference.py scenes/cornell-rough.toml \
      --size 32 --batches 16 --spp 512 --bounces 16 \
      --out tests/fixtures/mitsuba/cornell-rough-32
  python3 tools/mitsuba/reference.py scenes/smog-room.toml \
      --size 32 --batches 16 --spp 256 --bounces 1 \
      --out tests/fixtures/mitsuba/smog-room-32
  python3 tools/mitsuba/reference.py scenes/env-spheres.toml \
      --size 32 --batches 16 --spp 1024 --bounces 16 \
      --out tests/fixtures/mitsuba/env-spheres-32
  python3 tools/mitsuba/reference.py scenes/env-glass.toml \
      --size 32 --batches 16 --spp 1024 --bounces 16 \
      --out tests/fixtures/mitsuba/env-glass-32
  python3 tools/mitsuba/reference.py scenes/sss-balls.toml \
      --size 32 --batches 16 --spp 512 --bounces 3 \
      --out tests/fixtures/mitsuba/sss-balls-32
  python3 tools/mitsuba/reference.py scenes/sss-milk.toml \
      --size 32 --batches 8 --spp 32 --bounces 999 --all-orders \
      --out tests/fixtures/mitsuba/sss-milk-all-orders-32
  python3 tools/mitsuba/reference.py scenes/bunny-jade-exact.toml \
      --size 32 --batches 16 --spp 4096 --bounces 3 \
      --out tests/fixtures/mitsuba/bunny-jade-exact-32
  python3 tools/mitsuba/reference.py scenes/cornell-scratched-white.toml \
      --size 32 --batches 16 --spp 256 --bounces 16 \
      --out tests/fixtures/mitsuba/cornell-scratched-white-32
writes OUT.exr (mean), OUT-var.exr (variance of the mean) and OUT.json.
"""

import argparse
import json
import math
import os
import sys
import tempfile
import time
import tomllib

import numpy as np


def parse_mtl(path):
    mats, cur = {}, None
    for line in open(path, encoding="utf-8"):
        w = line.split("#")[0].split()
        if not w:
            continue
        if w[0] == "newmtl":
            cur = w[1]
            mats[cur] = {}
        elif cur and w[0] in ("Kd", "Ks", "Ke"):
            mats[cur][w[0]] = [float(x) for x in w[1:4]]
    return mats


def parse_obj(path):
    """(groups in order: (group name, material name, [triangles]), mtllib path)."""
    verts, groups, mtllib = [], [], None
    group, mat = "default", None
    cur = None
    for line in open(path, encoding="utf-8"):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            verts.append([float(x) for x in w[1:4]])
        elif w[0] == "mtllib":
            mtllib = os.path.join(os.path.dirname(path), w[1])
        elif w[0] == "usemtl":
            mat, cur = w[1], None
        elif w[0] in ("g", "o"):
            group, cur = w[1], None
        elif w[0] == "f":
            idx = []
            for t in w[1:]:
                i = int(t.split("/")[0])
                idx.append(i - 1 if i > 0 else len(verts) + i)
            if cur is None:
                cur = (group, mat, [])
                groups.append(cur)
            for k in range(1, len(idx) - 1):   # a fan, as tobj splits polygons
                cur[2].append([verts[idx[0]], verts[idx[k]], verts[idx[k + 1]]])
    return groups, mtllib


def load_scene(toml_path):
    sc = tomllib.load(open(toml_path, "rb"))
    base = os.path.dirname(toml_path)
    groups, mtllib = parse_obj(os.path.join(base, sc["obj"]))
    mtl = parse_mtl(mtllib) if mtllib else {}
    own = {m["name"]: m for m in sc.get("material", [])}
    over = {o["group"]: o["material"] for o in sc.get("override", [])}
    shapes = {}   # material name -> (kind, colour, emission, triangles, roughness, glass: (ior, fresnel))
    for g, m, tris in groups:
        # as warplight's loader: a group without an MTL material takes the scene's default_material
        name = over.get(g) or (over.get(m) if m else None) or m or sc.get("default_material", "default")
        rough, glass = 0.0, None
        if name in own:
            d = own[name]
            kind, color, em = d.get("kind", "diffuse"), d.get("color", [0.8] * 3), d.get("emission", [0.0] * 3)
            rough = d.get("roughness", 0.0)
            glass = (float(d.get("ior", 1.5)), d.get("fresnel", "schlick"), d if kind == "translucent" else None)
            if isinstance(rough, list):   # anisotropic: alpha_v rides in glass's slot (a 4th entry for glass)
                rough, alpha_v = float(rough[0]), float(rough[1])
                glass = {"alpha_v": alpha_v} if kind == "mirror" else glass + (alpha_v,)
            rough = float(rough)
            if any(k in d for k in ("albedo_map", "roughness_map", "metalness_map")):
                kind, glass = "textured", textured(toml_path, name, d)
        else:
            d = mtl.get(name, {})
            kd, ks, ke = d.get("Kd", [0.75] * 3), d.get("Ks", [0.0] * 3), d.get("Ke", [0.0] * 3)
            if any(x > 0 for x in ke):
                kind, color, em = "emitter", kd, ke
            elif all(x < 0.01 for x in kd) and any(x > 0 for x in ks):
                kind, color, em = "mirror", ks, ke
            else:
                kind, color, em = "diffuse", kd, ke
        if kind == "glass" and glass[1] != "exact":
            sys.exit(f"{toml_path}: glass {name} uses Schlick's Fresnel (the thesis'), Mitsuba's dielectrics the exact "
                     "equations; not exported (fresnel = \"exact\" is comparable)")
        if kind == "translucent" and glass[1] != "exact":
            sys.exit(f"{toml_path}: translucent {name} uses Schlick's Fresnel (the thesis'); only fresnel = \"exact\" "
                     "is Mitsuba's dielectric")
        if kind == "translucent" and float(own[name].get("translucency", 1.0)) != 1.0:
            sys.exit(f"{toml_path}: translucent {name} has translucency < 1: its diffuse branch of the Fresnel "
                     "switch is not exported (only translucency = 1, a dielectric around a medium)")
        if kind == "coated":
            sys.exit(f"{toml_path}: material {name} is coated: Mitsuba 3 has no Ashikhmin-Shirley diffuse under a "
                     "Schlick switch (its plastic differs); the lobe is checked analytically, tests/lin2017_coated.rs")
        if kind not in ("diffuse", "emitter", "mirror", "glass", "translucent", "textured"):
            sys.exit(f"{toml_path}: material {name} is {kind}: its Fresnel term (Schlick's) is not Mitsuba's; not exported")
        if kind == "mirror" and rough > 0 and any(c != 1.0 for c in color):
            sys.exit(f"{toml_path}: rough mirror {name} has colour {color}: Schlick's F equals Mitsuba's only for R0 = 1")
        # zero-area triangles are dropped, as warplight's loader does
        keep = [t for t in tris if np.linalg.norm(np.cross(np.subtract(t[1], t[0]), np.subtract(t[2], t[0]))) > 0]
        shapes.setdefault(name, (kind, color, em, [], rough, glass))[3].extend(keep)
    return sc, shapes


def duff_basis(n):
    """Duff et al.'s orthonormal basis around the unit n, in f32 as path.cu's basis()."""
    n = np.asarray(n, dtype=np.float32)
    sign = np.float32(1) if n[2] >= 0 else np.float32(-1)
    a = np.float32(-1) / (sign + n[2])
    b = n[0] * n[1] * a
    b1 = np.array([1 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]], dtype=np.float32)
    b2 = np.array([b, sign + n[1] * n[1] * a, -n[1]], dtype=np.float32)
    return b1, b2


def winding_normal(t):
    n = np.cross(np.subtract(t[1], t[0]), np.subtract(t[2], t[0]))
    return n / np.linalg.norm(n)


def alpha_v(glass):
    """An anisotropic material's alpha_v (a mirror's dict, a glass's 4th entry), else None."""
    if isinstance(glass, dict):
        return glass.get("alpha_v")
    if isinstance(glass, tuple) and len(glass) == 4:
        return glass[3]
    return None


def check_tangents(mi, scene, aniso_tris):
    """Shoots a ray at each anisotropic triangle's centroid along -n and
    returns the largest |s - b1| of Mitsuba's shading frame; exits above 1e-4."""
    worst = 0.0
    for t in aniso_tris:
        n = winding_normal(t)
        c = np.mean(np.asarray(t, dtype=float), axis=0)
        si = scene.ray_intersect(mi.Ray3f(mi.Point3f(*(c + 1e-3 * n)), mi.Vector3f(*(-n))))
        b1, _ = duff_basis(n)
        worst = max(worst, float(np.max(np.abs(np.array(si.sh_frame.s, dtype=float) - b1))))
    print(f"tangent check: {len(aniso_tris)} triangles, largest |s - b1| {worst:.2e}", file=sys.stderr)
    if worst > 1e-4:
        sys.exit(f"Mitsuba's tangent differs from warplight's b1 ({worst:.3g}): the anisotropic lobe would turn")
    return worst


def read_png(path):
    """An 8-bit PNG as a H x W x C uint8 array (Mitsuba's reader, no conversion)."""
    import mitsuba as mi
    return np.array(mi.Bitmap(path), dtype=np.uint8).reshape(*mi.Bitmap(path).size()[::-1], -1)


def textured(toml_path, name, d):
    """A textured material's maps (absolute paths) and planar mapping;
    exits where it is not comparable (see the docstring)."""
    base = os.path.dirname(toml_path)
    maps = {k: os.path.join(base, d[k]) for k in ("albedo_map", "roughness_map", "metalness_map") if k in d}
    if len(maps) != 3:
        sys.exit(f"{toml_path}: textured material {name}: only the full set (albedo, roughness, metalness maps) is exported")
    if "planar" not in d:
        sys.exit(f"{toml_path}: textured material {name}: only a planar mapping is exported (no OBJ vt)")
    if any(c != 1.0 for c in d.get("color", [0.8] * 3)):
        sys.exit(f"{toml_path}: textured material {name}: a colour other than white is not exported")
    albedo, metal = read_png(maps["albedo_map"]), read_png(maps["metalness_map"])
    if albedo.shape[:2] != metal.shape[:2] or np.any(albedo[metal[..., 0] > 0] != 255):
        sys.exit(f"{toml_path}: textured material {name}: the metal (metalness > 0) is not white in the albedo map: "
                 "Schlick's F equals Mitsuba's conductor only for R0 = 1")
    pl = d["planar"]
    return {"maps": maps, "planar": (pl["origin"], pl["u"], pl["v"])}


def texel_rule(img, u, v):
    """warplight's texel (host::scene::Texture::index): nearest, repeated, v = 0 the bottom row."""
    h, w = img.shape[:2]
    x = np.floor(np.float32(u) * np.float32(w)).astype(np.int64) % w
    y = np.floor((np.float32(1) - np.float32(v)) * np.float32(h)).astype(np.int64) % h
    return img[y, x]


def check_bitmap(mi, path, data):
    """The largest difference between Mitsuba's nearest `bitmap` (raw, as
    exported) at (u, 1 - v) (its OBJ loader flips v) and warplight's texel
    rule at (u, v), over 4,096 random coordinates in [-1, 2); exits when above 1e-6."""
    tex = mi.load_dict({"type": "bitmap", "filename": path, "filter_type": "nearest", "raw": True})
    rng = np.random.default_rng(2)
    uv = rng.uniform(-1, 2, size=(4096, 2)).astype(np.float32)
    ours = texel_rule(data, uv[:, 0], uv[:, 1])
    worst = 0.0
    for k in range(len(uv)):
        si = mi.SurfaceInteraction3f()
        si.uv = mi.Point2f(float(uv[k, 0]), float(np.float32(1) - uv[k, 1]))
        theirs = np.array(tex.eval(si) if data.shape[2] == 3 else [tex.eval_1(si)], dtype=np.float64)
        want = ours[k] / 255.0 if data.dtype == np.uint8 else ours[k]
        worst = max(worst, float(np.max(np.abs(theirs - want))))
    print(f"bitmap check {os.path.basename(path)}: {len(uv)} coordinates, largest difference {worst:.2e}",
          file=sys.stderr)
    if worst > 1e-6:
        sys.exit(f"{path}: warplight's texel rule differs from Mitsuba's nearest bitmap ({worst:.3g})")
    return worst


def lookup(tex, d):
    """warplight's environment lookup (path.cu's env()) of directions d (N x 3)
    in the map tex (H x W x 3), in float64."""
    h, w, _ = tex.shape
    u = np.arctan2(d[:, 0], -d[:, 2]) / (2 * math.pi)
    v = np.arccos(np.clip(d[:, 1], -1.0, 1.0)) / math.pi
    u = u - 0.5 / w
    u = u - np.floor(u)
    v = v - np.floor(v)
    x, y = u * w, v * (h - 1)
    px = np.minimum(np.floor(x), w - 1).astype(int)
    py = np.minimum(np.floor(y), h - 2).astype(int)
    fx, fy = (x - px)[:, None], (y - py)[:, None]
    qx = (px + 1) % w
    top = (1 - fx) * tex[py, px] + fx * tex[py, qx]
    bottom = (1 - fx) * tex[py + 1, px] + fx * tex[py + 1, qx]
    return (1 - fy) * top + fy * bottom


def check_envmap(mi, path):
    """The largest relative difference between lookup() and Mitsuba's envmap
    eval() over random directions and the axes; exits when above 1e-4."""
    tex = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False),
                   dtype=np.float64)
    em = mi.load_dict({"type": "envmap", "filename": path})
    rng = np.random.default_rng(1)
    d = rng.normal(size=(4096, 3))
    # the axes but the poles, where v = 1 wraps to 0 or not as acos(-1) / pi rounds
    d = np.concatenate([d, [[1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1]]])
    d /= np.linalg.norm(d, axis=1)[:, None]
    ours = lookup(tex, d)
    worst = 0.0
    for k in range(len(d)):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*(-d[k]))
        theirs = np.array(em.eval(si), dtype=np.float64)
        err = np.max(np.abs(theirs - ours[k]) / np.maximum(np.abs(theirs), 1e-3))
        worst = max(worst, float(err))
    print(f"envmap check: {len(d)} directions, largest relative difference {worst:.2e}", file=sys.stderr)
    if worst > 1e-4:
        sys.exit(f"{path}: warplight's lookup differs from Mitsuba's envmap (relative {worst:.3g})")
    return worst


def add_medium(path, desc, m, shapes, bounces):
    """Adds the scene's homogeneous medium (a null-BSDF cube over its box,
    Mitsuba's `homogeneous` with an `hg` phase inside) and makes the
    integrator `volpath`; refuses what is not comparable (see the docstring)."""
    if "height_scale" in m or any(x > 0 for x in m.get("emission", [0.0] * 3)):
        sys.exit(f"{path}: an emitting or exponential medium is not exported (Mitsuba's homogeneous medium has "
                 "neither)")
    if bounces != 1:
        sys.exit(f"{path}: warplight marches single scattering from direct light only; only --bounces 1 (Mitsuba's "
                 "max_depth 2) is the same light transport")
    if "box" in m:
        lo, hi = np.array(m["box"]["lo"], dtype=float), np.array(m["box"]["hi"], dtype=float)
    else:
        v = np.array([p for sh in shapes.values() for t in sh[3] for p in t], dtype=float)
        lo, hi = v.min(axis=0), v.max(axis=0)
    sa, ss = float(m["sigma_a"]), float(m["sigma_s"])
    st = sa + ss
    from mitsuba import ScalarTransform4f as T
    desc["integrator"] = {"type": "volpath", "max_depth": bounces + 1, "rr_depth": bounces + 2}
    desc["medium_box"] = {
        "type": "cube",
        "to_world": T().translate(((lo + hi) / 2).tolist()) @ T().scale(((hi - lo) / 2).tolist()),
        "bsdf": {"type": "null"},
        "interior": {
            "type": "homogeneous",
            "sigma_t": st,
            "albedo": {"type": "rgb", "value": [ss / st] * 3} if st > 0 else 0.0,
            "phase": {"type": "hg", "g": float(m.get("g", 0.0))},
        },
    }


def sss_medium(d):
    """A translucent material's interior (thesis 003 §5.3 as warplight builds
    it, path.cu's translucent()): free paths drawn with the reduced
    sigma_s' = (1 - g) sigma_s, absorption sigma_a (from `albedo` =
    sigma_s / (sigma_s + sigma_a) as warplight's loader converts it), and
    Henyey-Greenstein g for the direction: the radiative transfer of a
    homogeneous medium with scattering sigma_s', absorption sigma_a, HG(g)."""
    ss, g = float(d["sigma_s"]), float(d.get("g", 0.0))
    if "albedo" in d:
        al = d["albedo"] if isinstance(d["albedo"], list) else [d["albedo"]] * 3
        sa = [ss * (1.0 - float(x)) / float(x) for x in al]
    else:
        sa = d["sigma_a"] if isinstance(d["sigma_a"], list) else [d["sigma_a"]] * 3
        sa = [float(x) for x in sa]
    sr = (1.0 - g) * ss
    st = [sr + x for x in sa]
    top = max(st)   # an RGB texture must lie in [0, 1]: sigma_t = scale x (st / top)
    return {
        "type": "homogeneous",
        "scale": top,
        "sigma_t": {"type": "rgb", "value": [x / top for x in st]},
        "albedo": {"type": "rgb", "value": [sr / x if x > 0 else 0.0 for x in st]},
        "phase": {"type": "hg", "g": g},
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--size", type=int, default=32, help="image width and height in pixels")
    ap.add_argument("--batches", type=int, default=16)
    ap.add_argument("--spp", type=int, default=1024, help="samples per film pixel (subpixel) per batch")
    ap.add_argument("--bounces", type=int, default=16)
    ap.add_argument("--out")
    ap.add_argument(
        "--integrator",
        choices=["path", "ptracer"],
        default="path",
        help="Mitsuba's path tracer, or its particle tracer (light paths connected to the camera)",
    )
    ap.add_argument("--check-envmap", action="store_true", help="only check the environment lookup")
    ap.add_argument("--all-orders", action="store_true",
                    help="translucent materials: every order of scattering (not warplight's estimand; the "
                         "high-albedo comparison); no Russian roulette (its 0.95 cap makes the hundreds of "
                         "scatterings of a high albedo a heavy tail)")
    a = ap.parse_args()
    if not a.out and not a.check_envmap:
        ap.error("--out is required")
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    from mitsuba import ScalarTransform4f as T

    sc, shapes = load_scene(a.scene)
    env = os.path.join(os.path.dirname(a.scene), sc["environment"]) if "environment" in sc else None
    env_check = check_envmap(mi, env) if env else None
    if a.check_envmap:
        return
    cam = sc["camera"]
    pos = cam["position"]
    d = cam["direction"]
    up = cam.get("up", [0.0, 1.0, 0.0])
    tmp = tempfile.mkdtemp(prefix="warplight-mitsuba-")
    desc = {
        "type": "scene",
        "integrator": {"type": a.integrator, "max_depth": a.bounces + 1, "rr_depth": a.bounces + 2},
        "sensor": {
            "type": "perspective",
            "fov": cam["fov"],
            "fov_axis": "y",
            "to_world": T().look_at(origin=pos, target=[pos[i] + d[i] for i in range(3)], up=up),
            "film": {
                "type": "hdrfilm",
                "width": 2 * a.size,
                "height": 2 * a.size,
                "rfilter": {"type": "tent", "radius": 1.0},
                "sample_border": True,
                "pixel_format": "rgb",
            },
            "sampler": {"type": "independent", "sample_count": a.spp},
        },
    }
    triangles, light_area, sss = 0, 0.0, False
    aniso_tris = []
    bitmap_checks = {}
    for k, (name, (kind, color, em, tris, rough, glass)) in enumerate(sorted(shapes.items())):
        if not tris:
            continue
        f = os.path.join(tmp, f"{k}.obj")
        with open(f, "w") as o:
            for t in tris:
                for v in t:
                    o.write("v %r %r %r\n" % tuple(v))
            if kind == "textured":
                org, pu, pv = (np.array(x, dtype=float) for x in glass["planar"])
                for t in tris:
                    for v in t:
                        q = np.array(v, dtype=float) - org
                        o.write("vt %r %r\n" % (float(q @ pu), float(q @ pv)))
                for i in range(len(tris)):
                    o.write(f"f {3 * i + 1}/{3 * i + 1} {3 * i + 2}/{3 * i + 2} {3 * i + 3}/{3 * i + 3}\n")
            elif kind in ("mirror", "glass") and alpha_v(glass) is not None:
                for t in tris:
                    b1, b2 = duff_basis(winding_normal(t))
                    for v in t:
                        o.write("vt %r %r\n" % (float(np.dot(v, b1)), float(np.dot(v, b2))))
                for i in range(len(tris)):
                    o.write(f"f {3 * i + 1}/{3 * i + 1} {3 * i + 2}/{3 * i + 2} {3 * i + 3}/{3 * i + 3}\n")
                aniso_tris.extend(tris)
            else:
                for i in range(len(tris)):
                    o.write(f"f {3 * i + 1} {3 * i + 2} {3 * i + 3}\n")
        triangles += len(tris)
        shape = {"type": "obj", "filename": f, "face_normals": True}
        if kind == "emitter":
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": em}}
            for t in tris:
                light_area += 0.5 * np.linalg.norm(np.cross(np.subtract(t[1], t[0]), np.subtract(t[2], t[0])))
        elif kind == "glass":
            shape["bsdf"] = {
                "type": "roughdielectric" if rough > 0 else "dielectric",
                "int_ior": glass[0],
                "ext_ior": 1.0,
                "specular_reflectance": {"type": "rgb", "value": color},
                "specular_transmittance": {"type": "rgb", "value": color},
            }
            if rough > 0:
                lobe = {"alpha_u": rough, "alpha_v": alpha_v(glass)} if alpha_v(glass) is not None else {"alpha": rough}
                shape["bsdf"].update({"distribution": "beckmann", **lobe})
        elif kind == "translucent":
            shape["bsdf"] = {"type": "dielectric", "int_ior": glass[0], "ext_ior": 1.0}
            shape["interior"] = sss_medium(glass[2])
            sss = True
        elif kind == "textured":
            mp = glass["maps"]
            level = read_png(mp["roughness_map"])[..., :1]
            alpha = np.maximum(level.astype(np.float32) / np.float32(255), np.float32(1e-4))
            alpha_exr = os.path.join(tmp, f"{k}-alpha.exr")
            mi.Bitmap(alpha).write(alpha_exr)
            for key, path, data in [("albedo_map", mp["albedo_map"], read_png(mp["albedo_map"])),
                                    ("metalness_map", mp["metalness_map"], read_png(mp["metalness_map"])[..., :1]),
                                    ("alpha", alpha_exr, alpha)]:
                bitmap_checks[f"{name}.{key}"] = check_bitmap(mi, path, data)
            bm = lambda path: {"type": "bitmap", "filename": path, "filter_type": "nearest", "raw": True}
            shape["bsdf"] = {
                "type": "twosided",
                "bsdf": {
                    "type": "blendbsdf",
                    "weight": bm(mp["metalness_map"]),
                    "bsdf_0": {"type": "diffuse", "reflectance": bm(mp["albedo_map"])},
                    "bsdf_1": {
                        "type": "roughconductor",
                        "distribution": "beckmann",
                        "alpha": bm(alpha_exr),
                        "material": "none",
                        "specular_reflectance": 1.0,
                    },
                },
            }
        elif kind == "mirror" and rough > 0:
            lobe = {"alpha_u": rough, "alpha_v": alpha_v(glass)} if alpha_v(glass) is not None else {"alpha": rough}
            shape["bsdf"] = {
                "type": "twosided",
                "bsdf": {
                    "type": "roughconductor",
                    "distribution": "beckmann",
                    **lobe,
                    "material": "none",
                    "specular_reflectance": {"type": "rgb", "value": color},
                },
            }
        elif kind == "mirror":
            shape["bsdf"] = {
                "type": "twosided",
                "bsdf": {
                    "type": "conductor",
                    "material": "none",
                    "specular_reflectance": {"type": "rgb", "value": color},
                },
            }
        else:
            shape["bsdf"] = {
                "type": "twosided",
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": color}},
            }
        desc[f"shape_{k}_{name}"] = shape
    if env:
        desc["environment"] = {"type": "envmap", "filename": env}
    medium = sc.get("medium")
    if medium is not None:
        add_medium(a.scene, desc, medium, shapes, a.bounces)
    if sss:
        if a.bounces > 3 and not a.all_orders:
            sys.exit(f"{a.scene}: warplight's subsurface scattering scatters once per stay inside; only --bounces 3 "
                     "or fewer (Mitsuba's max_depth 4) is the same light transport (or --all-orders)")
        desc["integrator"] = {"type": "volpath", "max_depth": a.bounces + 1,
                              "rr_depth": a.bounces + 2}
    scene = mi.load_dict(desc)
    tangent_check = check_tangents(mi, scene, aniso_tris) if aniso_tris else None
    t0 = time.time()
    batches = []
    for b in range(a.batches):
        img = np.array(mi.render(scene, seed=b, spp=a.spp), dtype=np.float64)[:, :, :3]
        s = a.size
        batches.append(img.reshape(s, 2, s, 2, 3).mean(axis=(1, 3)))
        print(f"batch {b + 1}/{a.batches} ({time.time() - t0:.0f} s)", file=sys.stderr)
    x = np.stack(batches)
    mean = x.mean(axis=0)
    var = x.var(axis=0, ddof=1) / a.batches
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    mi.Bitmap(mean.astype(np.float32)).write(a.out + ".exr")
    mi.Bitmap(var.astype(np.float32)).write(a.out + "-var.exr")
    meta = {
        "scene": a.scene,
        "size": a.size,
        "batches": a.batches,
        "spp_per_subpixel_per_batch": a.spp,
        "max_bounces": a.bounces,
        "mitsuba": mi.__version__,
        "variant": "scalar_rgb",
        "triangles": triangles,
        "light_area": light_area,
        "environment": sc.get("environment"),
        "medium": sc.get("medium"),
        "integrator": desc["integrator"]["type"],
        "all_orders": a.all_orders,
        "envmap_check_max_rel_diff": env_check,
        "bitmap_check_max_diff": bitmap_checks or None,
        "tangent_check_max_diff": tangent_check,
        "seconds": round(time.time() - t0, 1),
        "command": "python3 tools/mitsuba/reference.py " + " ".join(sys.argv[1:]),
        "mean_rgb": [float(v) for v in mean.reshape(-1, 3).mean(axis=0)],
    }
    json.dump(meta, open(a.out + ".json", "w"), indent=2)
    print(json.dumps(meta, indent=2))


if __name__ == "__main__":
    main()
