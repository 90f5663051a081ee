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
}

/// A pixel sampling the kernel's builds cannot take.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PixelSamplingError {
    /// Not `tent` or `stratified:D`.
    #[error(
        "unknown pixel sampling `{0}`; expected tent or stratified:D (D strata across a subpixel, 1 to {MAX_STRATA})"
    )]
    Name(String),
    /// A strata count outside 1..=[`MAX_STRATA`].
    #[error("stratified:{0}: the strata across a subpixel must be 1 to {MAX_STRATA}")]
    Strata(u32),
}

impl PixelSampling {
    /// The command-line name: `tent` or `stratified:D`.
    pub fn name(self) -> String {
        match self {
            PixelSampling::Tent => "tent".into(),
            PixelSampling::Stratified(d) => format!("stratified:{d}"),
        }
    }

    /// A chart's label: `tent` or `stratified DxD`.
    pub fn label(self) -> String {
        match self {
            PixelSampling::Tent => "tent".into(),
            PixelSampling::Stratified(d) => format!("stratified {d}x{d}"),
        }
    }

    /// Parses a command-line name (`stratified:D`; `stratified` alone is 4 x 4).
    pub fn parse(s: &str) -> Result<PixelSampling, PixelSamplingError> {
        let p = match s {
            "tent" => PixelSampling::Tent,
            "stratified" => PixelSampling::Stratified(4),
            _ => {
                let d = s.strip_prefix("stratified:").and_then(|d| d.parse::<u32>().ok());
                PixelSampling::Stratified(d.ok_or_else(|| PixelSamplingError::Name(s.into()))?)
            }
        };
        p.check()?;
        Ok(p)
    }

    /// Refuses strata counts outside 1..=[`MAX_STRATA`].
    pub fn check(self) -> Result<(), PixelSamplingError> {
        match self {
            PixelSampling::Stratified(d) if d == 0 || d > MAX_STRATA => Err(PixelSamplingError::Strata(d)),
            _ => Ok(()),
        }
    }

    /// The kernel's `Params::strata`: D, or 0 under the tent filter.
    pub fn strata(self) -> i32 {
        match self {
            PixelSampling::Tent => 0,
            PixelSampling::Stratified(d) => d as i32,
        }
    }

    /// Frames a round takes (D², 1 under the tent filter): only whole rounds
    /// cover every subpixel, and each round is an independent estimate.
    pub fn round(self) -> u32 {
        match self {
            PixelSampling::Tent => 1,
            PixelSampling::Stratified(d) => d * d,
        }
    }

    /// Where frame `frame` puts subpixel `sub`'s ray from the uniforms `r0`
    /// (across) and `r1` (down): offsets from the pixel's top left corner in
    /// subpixel widths (half pixels), the subpixel's own corner at (sub & 1,
    /// sub >> 1) plus [-0.5, 1.5) under the tent or [0, 1) stratified, as the
    /// kernel's `camera_ray` and `camera_stratified` compute them.
    pub fn offset(self, sub: u32, frame: u32, r0: f32, r1: f32) -> (f32, f32) {
        let (sx, sy) = ((sub & 1) as f32, (sub >> 1) as f32);
        match self {
            PixelSampling::Tent => (sx + 0.5 + super::rng::tent(r0), sy + 0.5 + super::rng::tent(r1)),
            PixelSampling::Stratified(d) => {
                let d = d as i32;
                let s = (frame as i32) % (d * d);
                (sx + ((s % d) as f32 + r0) / d as f32, sy + ((s / d) as f32 + r1) / d as f32)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_ones_are_refused() {
        for p in [PixelSampling::Tent, PixelSampling::Stratified(1), PixelSampling::Stratified(8)] {
            assert_eq!(PixelSampling::parse(&p.name()), Ok(p));
        }
        assert_eq!(PixelSampling::parse("stratified"), Ok(PixelSampling::Stratified(4)));
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
            assert_eq!(p.offset(0, f, 0.5, 0.5), want[f as usize % 4], "frame {f}");
        }
        // subpixel 3 (right, down) is one subpixel further on both axes
        assert_eq!(p.offset(3, 1, 0.5, 0.5), (1.75, 1.25));
        // a round's offsets cover the subpixel: 3 x 3 strata, r just below 1 stays in its stratum
        let q = PixelSampling::Stratified(3);
        for f in 0..9 {
            let (x, y) = q.offset(0, f, 0.999, 0.0);
            assert!((x * 3.0).floor() as u32 == f % 3 && (y * 3.0).floor() as u32 == f / 3, "frame {f}: {x} {y}");
        }
        assert_eq!(p.round(), 4);
        assert_eq!(PixelSampling::Tent.round(), 1);
        // the tent's centre (r = 0.5 maps to 0) is the subpixel's centre
        assert_eq!(PixelSampling::Tent.offset(0, 7, 0.5, 0.5), (0.5, 0.5));
    }
}
