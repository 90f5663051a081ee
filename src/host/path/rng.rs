//! The path tracer's counter-based random numbers and sample warps, as
//! `kernels/lin2017/path.cu` computes them (same integer and float
//! operations in the same order): dimension `d` of path `i` in frame `f` is a
//! hash of `(i, f, seed, d)`, so the kernel and the native path tracer draw
//! the same numbers without any state.

/// One round of the 32-bit integer hash.
pub fn mix(mut h: u32) -> u32 {
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    h
}

/// The key of path `i` in frame `frame` under `seed`.
pub fn path_key(i: u32, frame: u32, seed: u32) -> u32 {
    mix(i.wrapping_mul(0x9e37_79b9) ^ mix(frame.wrapping_mul(0x632b_e5ab).wrapping_add(seed)))
}

/// Dimension `d` of the path with `key`: a uniform float in [0, 1) with 24 random bits.
pub fn rng(key: u32, d: u32) -> f32 {
    let h = mix(mix(key ^ d.wrapping_add(1).wrapping_mul(0x85eb_ca6b)));
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Where an integrator draws its random numbers: dimension `d`'s uniform.
/// A path's key ([`path_key`]) draws them by [`rng`]; an MLT iteration's
/// [`super::mlt::Sampler`] from its chain's primary samples.
pub trait Sample: Copy {
    /// Dimension `d`.
    fn at(self, d: u32) -> f32;
}

impl Sample for u32 {
    fn at(self, d: u32) -> f32 {
        rng(self, d)
    }
}

/// smallpt's tent warp of a uniform `y` in [0, 1) to [-1, 1).
pub fn tent(y: f32) -> f32 {
    let r = 2.0 * y;
    if r < 1.0 { r.sqrt() - 1.0 } else { 1.0 - (2.0 - r).sqrt() }
}

/// (cos, sin) of the azimuth 2πy for `y` in [0, 1), by the kernel's Taylor
/// polynomials on a quarter turn (no sin/cos instruction).
pub fn azimuth(y: f32) -> (f32, f32) {
    let f4 = y * 4.0;
    let q = f4 as i32;
    let x = (f4 - q as f32) * std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4;
    let x2 = x * x;
    let sx = x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))));
    let cx = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0 * (1.0 - x2 / 56.0 * (1.0 - x2 / 90.0))));
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let (cr, sr) = ((cx - sx) * h, (sx + cx) * h);
    match q {
        0 => (cr, sr),
        1 => (-sr, cr),
        2 => (-cr, -sr),
        _ => (sr, -cr),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_mean_and_range() {
        let key = path_key(7, 3, 0);
        let n = 20_000;
        let xs: Vec<f32> = (0..n).map(|d| rng(key, d)).collect();
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
        let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        assert_ne!(path_key(0, 0, 0), path_key(1, 0, 0));
        assert_ne!(path_key(0, 0, 0), path_key(0, 1, 0));
    }

    #[test]
    fn azimuth_matches_sin_cos_and_tent_covers_minus_one_to_one() {
        for k in 0..1000 {
            let y = k as f32 / 1000.0;
            let (c, s) = azimuth(y);
            let a = y as f64 * std::f64::consts::TAU;
            assert!((c as f64 - a.cos()).abs() < 1e-6 && (s as f64 - a.sin()).abs() < 1e-6, "{y}");
        }
        assert_eq!(tent(0.0), -1.0);
        assert_eq!(tent(0.5), 0.0);
        assert!(tent(0.999_999) > 0.99);
    }
}
