#!/usr/bin/env python3
"""Generates the scratched-metal texture set of thesis 003's Fig. 13 (lower:
"the diffuse back wall of the original Cornell box" made "a realistic scratched
metal" by albedo, roughness and metalness maps, 003:L413-417; the thesis'
maps are not distributed, their resolution and filtering not stated).

256 x 256 8-bit greyscale / RGB PNGs, deterministic for a seed (numpy's
PCG64):
  albedo.png     RGB: brushed steel (0.55-0.66 grey, slightly blue) where bare,
                 blue-grey paint (0.18, 0.27, 0.40) where paint is left
  metalness.png  grey: 255 on bare metal, 0 on paint, fractional on the
                 antialiased edges of the scratches through the paint
  roughness.png  grey: Beckmann alpha x 255 of the metal: 0.22 brushed
                 (horizontal streaks +-0.05), 0.06 in the polished scratches,
                 0.45 in the deep ones
  albedo-white-metal.png  the albedo with every texel of metalness > 0 white:
                 the metal's specular colour lerp(white, albedo, m) is then 1
                 and Schlick's F equals Mitsuba's conductor with material
                 "none" (the compared scene, scenes/cornell-scratched-white.toml)
The paint is left mostly on the lower left (a large-scale gradient), so that a
mirrored or shifted map changes the image (tests/lin2017_textures.rs).

Usage (the committed maps): python3 make_scratched_metal.py --seed 2017 --size 256
Needs numpy only (the PNG writer is below).
"""
import argparse
import os
import struct
import zlib

import numpy as np


def write_png(path, img):
    """8-bit PNG of a H x W (grey) or H x W x 3 (RGB) uint8 array."""
    h, w = img.shape[:2]
    colour = 2 if img.ndim == 3 else 0
    rows = b"".join(b"\x00" + img[y].tobytes() for y in range(h))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(rows, 9)))
        f.write(chunk(b"IEND", b""))


def smooth_noise(rng, n, cells):
    """Value noise on an n x n periodic grid of `cells` cells, bilinear, in [0, 1)."""
    g = rng.random((cells, cells))
    x = np.arange(n) * cells / n
    i = np.floor(x).astype(int)
    f = x - i
    f = f * f * (3 - 2 * f)
    a = g[np.ix_(i % cells, i % cells)]
    b = g[np.ix_(i % cells, (i + 1) % cells)]
    c = g[np.ix_((i + 1) % cells, i % cells)]
    d = g[np.ix_((i + 1) % cells, (i + 1) % cells)]
    fy, fx = f[:, None], f[None, :]
    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy


def scratches(rng, n, count, width):
    """Coverage in [0, 1] of `count` antialiased straight scratches."""
    yy, xx = np.mgrid[0:n, 0:n] + 0.5
    cov = np.zeros((n, n))
    for _ in range(count):
        x0, y0 = rng.random(2) * n
        ang = rng.normal(0.35, 0.5)
        length = rng.uniform(0.08, 0.5) * n
        dx, dy = np.cos(ang), np.sin(ang)
        # distance to the segment, with periodic wrap
        px = (xx - x0 + n / 2) % n - n / 2
        py = (yy - y0 + n / 2) % n - n / 2
        t = np.clip(px * dx + py * dy, 0, length)
        dist = np.hypot(px - t * dx, py - t * dy)
        cov = np.maximum(cov, np.clip(width / 2 + 0.5 - dist, 0, 1))
    return cov


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=2017)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--out", default=os.path.dirname(os.path.abspath(__file__)))
    a = ap.parse_args()
    rng = np.random.Generator(np.random.PCG64(a.seed))
    n = a.size
    yy, xx = np.mgrid[0:n, 0:n] / n
    # paint left on the lower left: a gradient plus blotches
    blotch = smooth_noise(rng, n, 8) * 0.6 + smooth_noise(rng, n, 24) * 0.4
    paint = ((1.0 - xx) * 0.55 + yy * 0.55 + (blotch - 0.5) * 0.9) > 0.72
    fine = scratches(rng, n, 90, 1.2)     # polished scratches
    deep = scratches(rng, n, 14, 2.5)     # deep, rough ones
    through = np.maximum(fine, deep)
    metal = np.where(paint, through, 1.0)
    # brushed metal: horizontal streaks
    streak = np.repeat(rng.random((n, 1)), n, axis=1)
    streak = (streak + np.roll(streak, 1, 0) + np.roll(streak, -1, 0)) / 3
    alpha = 0.22 + (streak - 0.5) * 0.1 + (smooth_noise(rng, n, 6) - 0.5) * 0.06
    alpha = alpha * (1 - fine) + 0.06 * fine
    alpha = alpha * (1 - deep) + 0.45 * deep
    steel = 0.6 + (streak - 0.5) * 0.08 + (smooth_noise(rng, n, 12) - 0.5) * 0.1
    steel = steel * (1 - deep) + 0.45 * deep + 0.06 * fine * (1 - deep)
    steel_rgb = np.stack([steel * 0.97, steel * 0.99, steel * 1.03], axis=-1)
    paint_rgb = np.array([0.18, 0.27, 0.40]) * (0.9 + 0.2 * blotch)[..., None]
    m = metal[..., None]
    albedo = steel_rgb * m + paint_rgb * (1 - m)
    to8 = lambda v: np.clip(np.round(v * 255), 0, 255).astype(np.uint8)
    m8 = to8(metal)
    os.makedirs(a.out, exist_ok=True)
    write_png(os.path.join(a.out, "albedo.png"), to8(albedo))
    write_png(os.path.join(a.out, "metalness.png"), m8)
    write_png(os.path.join(a.out, "roughness.png"), to8(alpha))
    white = to8(albedo)
    white[m8 > 0] = 255
    write_png(os.path.join(a.out, "albedo-white-metal.png"), white)
    print(f"paint {np.mean(m8 == 0):.2f}, metal {np.mean(m8 == 255):.2f}, partial {np.mean((m8 > 0) & (m8 < 255)):.3f}, "
          f"alpha {alpha.min():.3f}-{alpha.max():.3f}")


if __name__ == "__main__":
    main()
