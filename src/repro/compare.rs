//! Comparing our numbers with a thesis' printed ones: printed values read
//! exactly as printed, means as the theses compute them, tolerances and the
//! verdict of one cell.
//!
//! A table declares a tolerance per column ([`Tolerance`]): absolute counts
//! within ±5 % relative, relative changes within ±10 % as the factor deviation
//! `(1 + ours) / (1 + thesis) − 1`, differences in percentage points within a
//! stated number of points. Frame rates fitted to the thesis are never
//! compared (a fitted number agrees by construction).

use serde::{Deserialize, Serialize};

/// A number as the thesis prints it (`"+122.9%"`, `"−0.8%"`, `"±0.0%"`,
/// `"2249.9"`, `"207425"`), kept as text so that it is quoted exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Printed(pub &'static str);

impl Printed {
    /// The value (percent signs and units dropped, `−` read as minus, `±0` as 0).
    pub fn value(&self) -> f64 {
        parse_printed(self.0).unwrap_or(f64::NAN)
    }

    /// The text as printed.
    pub fn text(&self) -> &'static str {
        self.0
    }
}

/// Reads a printed number: `+12.5%`, `−3.8%`, `±0.0%`, `97.2%`, `2,155,935`, `0.003`.
pub fn parse_printed(s: &str) -> Option<f64> {
    let t: String =
        s.trim().replace('−', "-").replace('±', "").chars().filter(|c| !matches!(c, '%' | ',' | ' ' | '+')).collect();
    let t = t.trim_end_matches("pp");
    t.parse::<f64>().ok()
}

/// How close one of our cells must be to the thesis' to agree.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Tolerance {
    /// An absolute quantity: |ours / thesis − 1| ≤ the fraction.
    Relative(f64),
    /// A relative change in percent: the factor deviation
    /// |(1 + ours/100) / (1 + thesis/100) − 1| ≤ the fraction.
    Factor(f64),
    /// A difference in percentage points: |ours − thesis| ≤ the points.
    Points(f64),
}

impl Tolerance {
    /// Counts: ±5 % relative.
    pub const COUNT: Tolerance = Tolerance::Relative(0.05);
    /// Ratios (relative changes): ±10 % factor deviation.
    pub const RATIO: Tolerance = Tolerance::Factor(0.10);

    /// The deviation of `ours` from `thesis` in this tolerance's measure.
    pub fn deviation(&self, ours: f64, thesis: f64) -> f64 {
        match self {
            Tolerance::Relative(_) => ours / thesis - 1.0,
            Tolerance::Factor(_) => (1.0 + ours / 100.0) / (1.0 + thesis / 100.0) - 1.0,
            Tolerance::Points(_) => ours - thesis,
        }
    }

    /// The bound.
    pub fn bound(&self) -> f64 {
        match *self {
            Tolerance::Relative(f) | Tolerance::Factor(f) | Tolerance::Points(f) => f,
        }
    }

    /// Whether `ours` agrees with `thesis`.
    pub fn verdict(&self, ours: f64, thesis: f64) -> Verdict {
        let d = self.deviation(ours, thesis);
        if !d.is_finite() {
            Verdict::Outside
        } else if d.abs() <= self.bound() + 1e-12 {
            Verdict::Within
        } else {
            Verdict::Outside
        }
    }

    /// A short description: `±5 %`, `±10 % (factor)`, `±1 pp`.
    pub fn describe(&self) -> String {
        match *self {
            Tolerance::Relative(f) => format!("±{} % relative", f * 100.0),
            Tolerance::Factor(f) => format!("±{} % as the factor (1+ours)/(1+thesis)", f * 100.0),
            Tolerance::Points(p) => format!("±{p} percentage points"),
        }
    }
}

/// The verdict of one compared cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Verdict {
    /// Within the table's tolerance.
    Within,
    /// Outside it.
    Outside,
}

impl Verdict {
    /// The mark printed beside the cell.
    pub fn mark(&self) -> &'static str {
        match self {
            Verdict::Within => "✓",
            Verdict::Outside => "✗",
        }
    }
}

/// Mean and sample standard deviation (n − 1), as the theses compute their
/// "Average" and "Std. Dev." rows.
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = if v.len() > 1 { v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (v.len() - 1) as f64 } else { 0.0 };
    (m, var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printed_values_read_as_printed() {
        assert_eq!(parse_printed("+122.9%"), Some(122.9));
        assert_eq!(parse_printed("−0.8%"), Some(-0.8));
        assert_eq!(parse_printed("±0.0%"), Some(0.0));
        assert_eq!(parse_printed("2,155,935"), Some(2155935.0));
        assert_eq!(parse_printed("-1.6pp"), Some(-1.6));
        assert_eq!(parse_printed("–"), None);
        assert_eq!(Printed("97.2%").value(), 97.2);
    }

    #[test]
    fn tolerances_by_hand() {
        // counts: 7.31 vs 7.6 is +4.0 %: within ±5 %; 7.31 vs 7.7 is +5.3 %: outside
        assert_eq!(Tolerance::COUNT.verdict(7.6, 7.31), Verdict::Within);
        assert_eq!(Tolerance::COUNT.verdict(7.7, 7.31), Verdict::Outside);
        // ratios: +130.6 % vs +122.9 %: 2.306 / 2.229 = 1.0345: within ±10 %
        assert_eq!(Tolerance::RATIO.verdict(130.6, 122.9), Verdict::Within);
        // +62.9 % vs +35.7 %: 1.629 / 1.357 = 1.20: outside
        assert_eq!(Tolerance::RATIO.verdict(62.9, 35.7), Verdict::Outside);
        // a small change near zero: +5.7 % vs +0.3 %: 1.057 / 1.003 = 1.054: within
        assert_eq!(Tolerance::RATIO.verdict(5.7, 0.3), Verdict::Within);
        assert_eq!(Tolerance::Points(1.0).verdict(-0.9, -2.2), Verdict::Outside);
        assert_eq!(Tolerance::Points(1.0).verdict(-1.3, -2.2), Verdict::Within);
        assert_eq!(Tolerance::COUNT.verdict(f64::NAN, 1.0), Verdict::Outside);
    }

    #[test]
    fn mean_and_sample_sd_as_the_thesis() {
        // Table 4.5's stackless column: printed +122.9 % and 55.7 %
        let (m, sd) = mean_sd(&[35.7, 136.7, 151.5, 182.7, 108.1]);
        assert!((m - 122.94).abs() < 0.005 && (sd - 55.69).abs() < 0.01, "{m} {sd}");
    }
}
