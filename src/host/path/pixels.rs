//! Where a frame's camera rays fall in their subpixel (§4.2, 003:L221-230).
//!
//! The thesis jitters each of a pixel's 2 x 2 subpixels with smallpt's tent
//! filter, one uniform sample a frame, so that any number of frames is a
//! fair image (successive refinement). Its alternative, stratified sampling,
//! cuts the subpixel into D x D strata; it "reduces the error of estimation
//! from O(1/√n) to O(1/n)" (003:L223) but needs D² frames as a unit. The
//! stratified build of the kernel (`kernels/lin2017/path_stratified.cu`)
//! gives frame f stratum f mod D², row by row from the top left, the same in
//! every pixel, and a uniform place in it (a box filter over the subpixel).
//!
//! The progressive order answers the thesis' objection that strata cannot
//! refine successively (003:L223): frame f's stratum is read from f mod D²
//! two bits at a time, coarsest first, each pair scrambled per subpixel
//! (Owen's nested scrambling), so every 4^j aligned frames stratify the
//! subpixel on a 2^j x 2^j grid and every single frame's ray is uniform over
//! it: any frame count is a fair image.

/// The most strata across a subpixel [`PixelSampling::check`] allows (D² = 4,096 frames a round).
pub const MAX_STRATA: u32 = 64;

/// How a frame places its camera rays in their subpixels.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PixelSampling {
    /// smallpt's tent filter over a uniform sample (the thesis', 003:L225).
    #[default]
    Tent,
    /// D x D strata of the subpixel (D the value), frame f in stratum f mod D², uniform in it.
    Stratified(u32),
    /// D x D strata (D a power of two) in the progressive order
    /// ([`progressive_stratum`]): every 4^j aligned frames one ray in each
    /// cell of a 2^j x 2^j grid, each frame's ray uniform over the subpixel.
    Progressive(u32),
}

/// A pixel sampling the kernel's builds cannot take.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PixelSamplingError {
    /// Not `tent`, `stratified:D` or `progressive:D`.
    #[error(
        "unknown pixel sampling `{0}`; expected tent, stratified:D or progressive:D (D strata across a subpixel, 1 to {MAX_STRATA})"
    )]
    Name(String),
    /// A strata count outside 1..=[`MAX_STRATA`].
    #[error("stratified:{0}: the strata across a subpixel must be 1 to {MAX_STRATA}")]
    Strata(u32),
    /// A progressive strata count that is not a power of two in 1..=[`MAX_STRATA`].
    #[error("progressive:{0}: the strata across a subpixel must be a power of two from 1 to {MAX_STRATA}")]
    ProgressiveStrata(u32),
}

impl PixelSampling {
    /// The command-line name: `tent`, `stratified:D` or `progressive:D`.
    pub fn name(self) -> String {
        match self {
            PixelSampling::Tent => "tent".into(),
            PixelSampling::Stratified(d) => format!("stratified:{d}"),
            PixelSampling::Progressive(d) => format!("progressive:{d}"),
        }
    }

    /// A chart's label: `tent`, `stratified DxD` or `progressive DxD`.
    pub fn label(self) -> String {
        match self {
            PixelSampling::Tent => "tent".into(),
            PixelSampling::Stratified(d) => format!("stratified {d}x{d}"),
            PixelSampling::Progressive(d) => format!("progressive {d}x{d}"),
        }
    }

    /// Parses a command-line name (`stratified:D`, `progressive:D`; either
    /// alone is 4 x 4).
    pub fn parse(s: &str) -> Result<PixelSampling, PixelSamplingError> {
        let strata = |prefix: &str| {
            s.strip_prefix(prefix)
                .map(|d| if d.is_empty() { Some(4) } else { d.strip_prefix(':').and_then(|d| d.parse::<u32>().ok()) })
        };
        let p = if s == "tent" {
            PixelSampling::Tent
        } else if let Some(d) = strata("stratified") {
            PixelSampling::Stratified(d.ok_or_else(|| PixelSamplingError::Name(s.into()))?)
        } else if let Some(d) = strata("progressive") {
            PixelSampling::Progressive(d.ok_or_else(|| PixelSamplingError::Name(s.into()))?)
        } else {
            return Err(PixelSamplingError::Name(s.into()));
        };
        p.check()?;
        Ok(p)
    }

    /// Refuses strata counts outside 1..=[`MAX_STRATA`], and progressive
    /// ones that are not a power of two.
    pub fn check(self) -> Result<(), PixelSamplingError> {
        match self {
            PixelSampling::Stratified(d) if d == 0 || d > MAX_STRATA => Err(PixelSamplingError::Strata(d)),
            PixelSampling::Progressive(d) if !d.is_power_of_two() || d > MAX_STRATA => {
                Err(PixelSamplingError::ProgressiveStrata(d))
            }
            _ => Ok(()),
        }
    }

    /// The kernel's `Params::strata`: D row by row, −D progressive, or 0 under the tent filter.
    pub fn strata(self) -> i32 {
        match self {
            PixelSampling::Tent => 0,
            PixelSampling::Stratified(d) => d as i32,
            PixelSampling::Progressive(d) => -(d as i32),
        }
    }

    /// Frames a round takes (D², 1 under the tent filter): whole rounds
    /// cover every stratum, and each round is an independent estimate.
    pub fn round(self) -> u32 {
        match self {
            PixelSampling::Tent => 1,
            PixelSampling::Stratified(d) | PixelSampling::Progressive(d) => d * d,
        }
    }

    /// Whether `frames` frames from frame 0 make a fair image: any count
    /// under the tent filter and the progressive order, whole rounds only
    /// row by row.
    pub fn fair(self, frames: u32) -> bool {
        match self {
            PixelSampling::Stratified(_) => frames.is_multiple_of(self.round()),
            PixelSampling::Tent | PixelSampling::Progressive(_) => true,
        }
    }

    /// Where frame `frame` puts path `i`'s ray (subpixel `i & 3`) from the
    /// uniforms `r0` (across) and `r1` (down) under `seed`: offsets from the
    /// pixel's top left corner in subpixel widths (half pixels), the
    /// subpixel's own corner at (sub & 1, sub >> 1) plus [-0.5, 1.5) under
    /// the tent or [0, 1) stratified, as the kernel's `camera_ray` and
    /// `camera_stratified` compute them.
    pub fn offset(self, i: u32, frame: u32, seed: u32, r0: f32, r1: f32) -> (f32, f32) {
        let sub = i & 3;
        let (sx, sy) = ((sub & 1) as f32, (sub >> 1) as f32);
        let place = |d: i32, (cx, cy): (i32, i32)| (sx + (cx as f32 + r0) / d as f32, sy + (cy as f32 + r1) / d as f32);
        match self {
            PixelSampling::Tent => (sx + 0.5 + super::rng::tent(r0), sy + 0.5 + super::rng::tent(r1)),
            PixelSampling::Stratified(d) => {
                let d = d as i32;
                let s = (frame as i32) % (d * d);
                place(d, (s % d, s / d))
            }
            PixelSampling::Progressive(d) => {
                let k = frame % (d * d);
                place(d as i32, progressive_stratum(k, d, scramble_key(i, seed)))
            }
        }
    }
}

/// The stratum (across, down) of the D x D grid (`d` a power of two) that
/// the progressive order gives round position `k` (frame mod D²) under the
/// subpixel's `key`, the kernel's `progressive_stratum`: k's bit pairs from
/// the lowest choose the quadrant at each level from the coarsest, each
/// XORed with two bits hashed from the key and the quadrants chosen so far.
pub fn progressive_stratum(mut k: u32, d: u32, key: u32) -> (i32, i32) {
    let (mut x, mut y, mut node) = (0u32, 0u32, 1u32);
    let mut b = 1;
    while b < d {
        let q = (k & 3) ^ (super::rng::mix(key ^ node.wrapping_mul(0x85eb_ca6b)) & 3);
        x = x * 2 + (q & 1);
        y = y * 2 + (q >> 1);
        node = node.wrapping_mul(4).wrapping_add(q);
        b <<= 1;
        k >>= 2;
    }
    (x as i32, y as i32)
}

/// The key of path `i`'s scramble under `seed` (the same in every frame), the kernel's `scramble_key`.
pub fn scramble_key(i: u32, seed: u32) -> u32 {
    use super::rng::mix;
    mix(i.wrapping_mul(0x9e37_79b9) ^ mix(seed.wrapping_add(0x68e3_1da4)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_ones_are_refused() {
        for p in [
            PixelSampling::Tent,
            PixelSampling::Stratified(1),
            PixelSampling::Stratified(8),
            PixelSampling::Progressive(1),
            PixelSampling::Progressive(64),
        ] {
            assert_eq!(PixelSampling::parse(&p.name()), Ok(p));
        }
        assert_eq!(PixelSampling::parse("stratified"), Ok(PixelSampling::Stratified(4)));
        assert_eq!(PixelSampling::parse("progressive"), Ok(PixelSampling::Progressive(4)));
        assert_eq!(PixelSampling::parse("progressive:6"), Err(PixelSamplingError::ProgressiveStrata(6)));
        assert_eq!(PixelSampling::parse("progressive:0"), Err(PixelSamplingError::ProgressiveStrata(0)));
        assert_eq!(PixelSampling::parse("progressive:128"), Err(PixelSamplingError::ProgressiveStrata(128)));
        assert!(matches!(PixelSampling::parse("stratifiedx"), Err(PixelSamplingError::Name(_))));
        assert!(matches!(PixelSampling::parse("progressive:"), Err(PixelSamplingError::Name(_))));
        assert_eq!(PixelSampling::parse("stratified:0"), Err(PixelSamplingError::Strata(0)));
        assert_eq!(PixelSampling::parse("stratified:65"), Err(PixelSamplingError::Strata(65)));
        assert!(matches!(PixelSampling::parse("box"), Err(PixelSamplingError::Name(_))));
        assert!(matches!(PixelSampling::parse("stratified:x"), Err(PixelSamplingError::Name(_))));
    }

    /// Frame f's offsets lie in stratum f mod D², row by row: 2 x 2 strata,
    /// the centre of each (r = 0.5) at a quarter and three quarters.
    #[test]
    fn frames_walk_the_strata_row_by_row() {
        let p = PixelSampling::Stratified(2);
        let want = [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)];
        for f in 0..8 {
            assert_eq!(p.offset(0, f, 0, 0.5, 0.5), want[f as usize % 4], "frame {f}");
        }
        // subpixel 3 (right, down) is one subpixel further on both axes
        assert_eq!(p.offset(3, 1, 0, 0.5, 0.5), (1.75, 1.25));
        // a round's offsets cover the subpixel: 3 x 3 strata, r just below 1 stays in its stratum
        let q = PixelSampling::Stratified(3);
        for f in 0..9 {
            let (x, y) = q.offset(0, f, 0, 0.999, 0.0);
            assert!((x * 3.0).floor() as u32 == f % 3 && (y * 3.0).floor() as u32 == f / 3, "frame {f}: {x} {y}");
        }
        assert_eq!(p.round(), 4);
        assert_eq!(PixelSampling::Tent.round(), 1);
        // the tent's centre (r = 0.5 maps to 0) is the subpixel's centre
        assert_eq!(PixelSampling::Tent.offset(0, 7, 0, 0.5, 0.5), (0.5, 0.5));
    }

    /// The progressive order: k's lowest bit pair picks the quadrant, so
    /// every aligned block of 4^j frames puts one ray in each cell of the
    /// 2^j x 2^j grid (j = 0..3 of D = 8), under any key.
    #[test]
    fn every_aligned_block_of_4_to_the_j_frames_stratifies_a_2_to_the_j_grid() {
        let d = 8u32;
        for key in [0u32, 1, 0xdead_beef, scramble_key(12_345, 7)] {
            for j in 0..=3u32 {
                let (block, cells) = (4u32.pow(j), 1u32 << j);
                for start in (0..d * d).step_by(block as usize) {
                    let mut seen = vec![false; (cells * cells) as usize];
                    for k in start..start + block {
                        let (x, y) = progressive_stratum(k, d, key);
                        let cell = ((y as u32 >> (3 - j)) * cells + (x as u32 >> (3 - j))) as usize;
                        assert!(!seen[cell], "key {key:#x}, 4^{j} frames from {start}: cell {cell} twice");
                        seen[cell] = true;
                    }
                }
            }
        }
        // frames past a round wrap: frame 64 + f takes frame f's stratum, and a round's frames
        // take 64 different ones
        let p = PixelSampling::Progressive(8);
        let mut round: Vec<(u32, u32)> = (0..64)
            .map(|f| {
                assert_eq!(p.offset(9, f + 64, 2, 0.5, 0.5), p.offset(9, f, 2, 0.5, 0.5), "frame {f}");
                let (x, y) = p.offset(9, f, 2, 0.5, 0.5);
                ((x * 8.0) as u32, (y * 8.0) as u32)
            })
            .collect();
        round.sort();
        round.dedup();
        assert_eq!(round.len(), 64);
        // one stratum: nothing to choose
        assert_eq!(progressive_stratum(0, 1, 5), (0, 0));
    }

    /// Each frame's stratum is uniform over the subpixels' keys (the
    /// scramble), so any frame count is a fair image: frame 0 over 64,000
    /// subpixels lands in each of the 64 strata of D = 8 about 1,000 times.
    #[test]
    fn each_frame_is_uniform_over_the_strata_across_subpixels() {
        for frame in [0u32, 1, 17] {
            let mut n = [0u32; 64];
            for i in 0..64_000 {
                let (x, y) = progressive_stratum(frame % 64, 8, scramble_key(i, 3));
                n[(y * 8 + x) as usize] += 1;
            }
            // Poisson-like spread: sd ≈ 31; 6 sd either side
            for (s, c) in n.iter().enumerate() {
                assert!((810..=1190).contains(c), "frame {frame}: stratum {s} drew {c} of 64,000");
            }
        }
        // the offsets: a path of subpixel 0 whose frame 0 scrambles to the top right stratum of
        // progressive:2 puts r = 0.5 at (3/4, 1/4) of its subpixel
        let i = (0..).step_by(4).find(|&i| progressive_stratum(0, 2, scramble_key(i, 0)) == (1, 0)).unwrap();
        assert_eq!(PixelSampling::Progressive(2).offset(i, 0, 0, 0.5, 0.5), (0.75, 0.25));
    }
}
