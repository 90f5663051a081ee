//! The environment map of thesis 003's path tracer (§5.4, 003:L405-417): a
//! ray that misses every triangle sees an infinitely distant sphere, stored
//! as an equirectangular ("spherical projection", 003:L411) map. The lookup
//! follows Mitsuba 3's `envmap` conventions, so that its references compare
//! (`tools/mitsuba/reference.py` checks the same formula against Mitsuba's
//! emitter): y up, u = atan2(x, −z) / 2π, v = acos(y) / π; texel column c
//! is centred at u = (c + ½) / W, row r lies on v = r / (H − 1); bilinear,
//! periodic in u. [`radiance`] is the kernel's `env()` operation for
//! operation (no fused multiply-add, no SFU instruction: atan2 is
//! [`atan2_series`]), so the native and the emulated render agree bit for bit.

use std::path::Path;

use super::layout::LayoutError;

/// An environment map in the kernel's layout.
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    /// Texels across (azimuth).
    pub width: u32,
    /// Texels down (row 0 the zenith, the last row the nadir).
    pub height: u32,
    /// Row-major texels `[r, g, b, 0]` (one 16-byte load each).
    pub texels: Vec<[f32; 4]>,
}

impl Environment {
    /// Reads the RGB channels of an OpenEXR map. A map needs at least 2 x 3
    /// texels (as Mitsuba's), and finite, non-negative radiance.
    pub fn load(path: &Path) -> Result<Environment, LayoutError> {
        let err = |msg: String| LayoutError::Environment { path: path.display().to_string(), msg };
        let img = super::stats::read_exr(path).map_err(|e| err(e.to_string()))?;
        if img.width < 2 || img.height < 3 {
            return Err(err(format!("{} x {} texels; an environment map needs at least 2 x 3", img.width, img.height)));
        }
        let mut texels = Vec::with_capacity(img.pixels.len());
        for (i, px) in img.pixels.iter().enumerate() {
            if px.iter().any(|c| !c.is_finite() || *c < 0.0) {
                let (x, y) = (i as u32 % img.width, i as u32 / img.width);
                return Err(err(format!("texel ({x}, {y}) is {px:?}; expected finite radiance >= 0")));
            }
            texels.push([px[0], px[1], px[2], 0.0]);
        }
        Ok(Environment { width: img.width, height: img.height, texels })
    }

    /// The radiance seen in the unit direction `d`: the kernel's `env()`.
    pub fn radiance(&self, d: [f32; 3]) -> [f32; 3] {
        radiance(&self.texels, self.width, self.height, d)
    }
}

/// atan s for |s| ≤ tan(π/8) by its series to s^15 (error < 2e-8): the kernel's `atan_series`.
pub fn atan_series(s: f32) -> f32 {
    let s2 = s * s;
    s * (1.0
        - s2 * (1.0 / 3.0
            - s2 * (0.2 - s2 * (1.0 / 7.0 - s2 * (1.0 / 9.0 - s2 * (1.0 / 11.0 - s2 * (1.0 / 13.0 - s2 / 15.0)))))))
}

/// atan2(y, x) in [−π, π] with no SFU instruction: the kernel's
/// `atan2_series` (t = min / max of |x|, |y|; above tan(π/8),
/// atan t = π/4 + atan((t − 1) / (t + 1)); then the octant).
pub fn atan2_series(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (mx, mn) = (ax.max(ay), ax.min(ay));
    let t = if mx > 0.0 { mn / mx } else { 0.0 };
    let mut a = if t > 0.414_213_57 {
        std::f32::consts::FRAC_PI_4 + atan_series((t - 1.0) / (t + 1.0))
    } else {
        atan_series(t)
    };
    if ay > ax {
        a = std::f32::consts::FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = std::f32::consts::PI - a;
    }
    if y < 0.0 { -a } else { a }
}

/// The bilinear lookup of `texels` (`w` x `h`) in the unit direction `d`.
pub fn radiance(texels: &[[f32; 4]], w: u32, h: u32, d: [f32; 3]) -> [f32; 3] {
    const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
    let [dx, dy, dz] = d;
    let (w, h) = (w as i32, h as i32);
    let mut u = atan2_series(dx, -dz) * (0.5 * INV_PI) - 0.5 / w as f32;
    let mut v = atan2_series((dx * dx + dz * dz).sqrt(), dy) * INV_PI;
    u -= u.floor();
    v -= v.floor();
    let (x, y) = (u * w as f32, v * (h - 1) as f32);
    // cvt.rzi.s32: NaN to 0, as `as`
    let (px, py) = ((x as i32).min(w - 1), (y as i32).min(h - 2));
    let (fx, fy) = (x - px as f32, y - py as f32);
    let (gx, gy) = (1.0 - fx, 1.0 - fy);
    let qx = if px + 1 == w { 0 } else { px + 1 };
    let at = |x: i32, y: i32| texels[(y * w + x) as usize];
    let (a, b, c, e) = (at(px, py), at(qx, py), at(px, py + 1), at(qx, py + 1));
    let mix = |k: usize| gy * (gx * a[k] + fx * b[k]) + fy * (gx * c[k] + fx * e[k]);
    [mix(0), mix(1), mix(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan2_series_agrees_with_f64() {
        let mut worst = 0.0f64;
        for i in 0..=200 {
            for j in 0..=200 {
                let (y, x) = (i as f32 / 50.0 - 2.0, j as f32 / 50.0 - 2.0);
                let want = (y as f64).atan2(x as f64);
                let got = atan2_series(y, x) as f64;
                worst = worst.max((got - want).abs());
            }
        }
        assert!(worst < 1e-6, "largest error {worst}");
        assert_eq!(atan2_series(0.0, 1.0), 0.0);
        assert_eq!(atan2_series(1.0, 0.0), std::f32::consts::FRAC_PI_2);
    }

    /// A 4 x 3 map of distinct texels, looked up by hand.
    #[test]
    fn the_lookup_follows_mitsubas_conventions() {
        let env = Environment {
            width: 4,
            height: 3,
            texels: (0..12).map(|i| [i as f32, 100.0 + i as f32, 0.0, 0.0]).collect(),
        };
        let close = |got: [f32; 3], want: [f32; 2]| {
            assert!((got[0] - want[0]).abs() < 1e-4 && (got[1] - want[1]).abs() < 1e-4, "{got:?} vs {want:?}");
        };
        // -z on the horizon: u = 0 - 1/8 wraps to 7/8, x = 3.5 (columns 3 and
        // 0 half each), v = 1/2, y = 1 (row 1)
        close(env.radiance([0.0, 0.0, -1.0]), [0.5 * (7.0 + 4.0), 100.0 + 0.5 * (7.0 + 4.0)]);
        // +x: u = 1/4 - 1/8, x = 0.5 (columns 0 and 1); row 1
        close(env.radiance([1.0, 0.0, 0.0]), [0.5 * (4.0 + 5.0), 100.0 + 0.5 * (4.0 + 5.0)]);
        // the zenith: row 0, u = -1/8 -> 7/8 again
        close(env.radiance([0.0, 1.0, 0.0]), [0.5 * (3.0 + 0.0), 100.0 + 0.5 * (3.0 + 0.0)]);
        // +z, 45 degrees down: u = 1/2 - 1/8, x = 1.5 (columns 1 and 2); v = 3/4, y = 1.5 (rows 1 and 2)
        let s = std::f32::consts::FRAC_1_SQRT_2;
        close(env.radiance([0.0, -s, s]), [0.25 * (5.0 + 6.0 + 9.0 + 10.0), 100.0 + 0.25 * (5.0 + 6.0 + 9.0 + 10.0)]);
    }
}
