#!/usr/bin/env python3
"""Downscales an equirectangular (latitude-longitude) HDR environment map by
averaging square blocks of texels, for thesis 003's environment-lit scene
(scenes/env-spheres.toml). The committed map was made by:

  python3 tools/mitsuba/envmap.py /work/shared/scenes/forest-slope-envmap/forest_slope_1k.hdr \\
      --factor 8 --out scenes/forest-slope-envmap/forest_slope_128x64.exr

(1024 x 512 Radiance RGBE -> 128 x 64 float32 RGB OpenEXR: each output texel
the plain mean of an 8 x 8 block, linear radiance, no weighting by solid
angle). Reads and writes through Mitsuba 3's Bitmap (`pip install mitsuba`).
"""

import argparse

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input")
    ap.add_argument("--factor", type=int, default=8)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    bmp = mi.Bitmap(a.input).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    img = np.array(bmp, dtype=np.float64)
    h, w, _ = img.shape
    f = a.factor
    if h % f or w % f:
        raise SystemExit(f"{a.input}: {w} x {h} is not a multiple of {f}")
    small = img.reshape(h // f, f, w // f, f, 3).mean(axis=(1, 3))
    mi.Bitmap(small.astype(np.float32)).write(a.out)
    lum = small @ np.array([0.2126, 0.7152, 0.0722])
    print(f"{w} x {h} -> {w // f} x {h // f}; mean rgb {small.reshape(-1, 3).mean(axis=0)}, max luminance {lum.max():.3f}")


if __name__ == "__main__":
    main()
