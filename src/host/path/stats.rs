//! The statistical image test, in the manner of Mitsuba 3's render tests: a
//! renderer agrees with a reference when, block by block and channel by
//! channel, the difference of the mean estimates is within what their
//! estimated variances allow — a two-sided Welch t-test per cell, the family
//! of cells controlled by Holm's step-down correction at level α — rather
//! than under a fixed RMSE.
//!
//! A progressive render's variance comes from its frames (batch means: each
//! frame's block mean is an independent, identically distributed estimate);
//! the reference's from its own independent batches (`tools/mitsuba/`),
//! stored as a per-pixel variance of the mean.

use crate::host::image::FrameBuffer;

/// Mean estimates of cells (block × channel) with their variances.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Blocks across.
    pub blocks_x: u32,
    /// Blocks down.
    pub blocks_y: u32,
    /// Per cell (block-major, then channel): the estimated mean.
    pub mean: Vec<f64>,
    /// Per cell: the variance of that estimate.
    pub var: Vec<f64>,
    /// Degrees of freedom of the variance estimates.
    pub dof: f64,
}

fn block_means(img: &FrameBuffer, block: u32) -> (u32, u32, Vec<f64>) {
    let (bx, by) = (img.width.div_ceil(block), img.height.div_ceil(block));
    let mut sums = vec![0.0f64; (bx * by * 3) as usize];
    let mut counts = vec![0.0f64; (bx * by) as usize];
    for y in 0..img.height {
        for x in 0..img.width {
            let b = ((y / block) * bx + x / block) as usize;
            counts[b] += 1.0;
            for (c, v) in img.get(x, y).into_iter().enumerate() {
                sums[3 * b + c] += v as f64;
            }
        }
    }
    for (i, s) in sums.iter_mut().enumerate() {
        *s /= counts[i / 3];
    }
    (bx, by, sums)
}

/// The estimate of a progressive render from its frames' images: the mean of
/// the frames' block means, its variance the batch variance over the frame count.
pub fn from_frames(frames: &[FrameBuffer], block: u32) -> Option<Estimate> {
    if frames.len() < 2 || block == 0 {
        return None;
    }
    let per: Vec<(u32, u32, Vec<f64>)> = frames.iter().map(|f| block_means(f, block)).collect();
    let (bx, by) = (per[0].0, per[0].1);
    let k = frames.len() as f64;
    let cells = per[0].2.len();
    let mut mean = vec![0.0; cells];
    let mut var = vec![0.0; cells];
    for i in 0..cells {
        let m = per.iter().map(|p| p.2[i]).sum::<f64>() / k;
        let s2 = per.iter().map(|p| (p.2[i] - m).powi(2)).sum::<f64>() / (k - 1.0);
        mean[i] = m;
        var[i] = s2 / k;
    }
    Some(Estimate { blocks_x: bx, blocks_y: by, mean, var, dof: k - 1.0 })
}

/// The estimate of a reference given as a mean image and a per-pixel
/// variance-of-the-mean image from `batches` independent batches. Pixels are
/// taken as independent (the block's variance is the sum of its pixels'
/// over the pixel count squared).
pub fn from_reference(mean: &FrameBuffer, var: &FrameBuffer, block: u32, batches: u32) -> Estimate {
    let (bx, by, m) = block_means(mean, block);
    let (_, _, v) = block_means(var, block);
    // the mean of the variances over n pixels, divided by n once more
    let mut vv = v;
    for (i, x) in vv.iter_mut().enumerate() {
        let b = i / 3;
        let (cx, cy) = (b as u32 % bx, b as u32 / bx);
        let w = (mean.width - cx * block).min(block) as f64;
        let h = (mean.height - cy * block).min(block) as f64;
        *x /= w * h;
    }
    Estimate { blocks_x: bx, blocks_y: by, mean: m, var: vv, dof: batches.saturating_sub(1).max(1) as f64 }
}

/// Reads the RGB channels of an OpenEXR file (a reference image).
pub fn read_exr(path: &std::path::Path) -> Result<FrameBuffer, crate::host::image::ImageError> {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| FrameBuffer::new(res.width() as u32, res.height() as u32),
        |fb: &mut FrameBuffer, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            fb.set(pos.x() as u32, pos.y() as u32, [r, g, b]);
        },
    )
    .map_err(|e| crate::host::image::ImageError::Io { path: path.display().to_string(), msg: e.to_string() })?;
    Ok(img.layer_data.channel_data.pixels)
}

/// What the test found.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Outcome {
    /// Cells tested.
    pub cells: usize,
    /// Cells whose null hypothesis (equal means) Holm's procedure rejects.
    pub rejected: usize,
    /// The family-wise level.
    pub alpha: f64,
    /// The smallest p-value.
    pub min_p: f64,
    /// The cell of the smallest p-value: (block x, block y, channel), and its t.
    pub worst: (u32, u32, usize, f64),
    /// Relative difference of the overall means (a − b) / b.
    pub mean_rel_diff: f64,
    /// Cells whose variance of `a` was raised to the floor ([`welch_holm_floored`]).
    pub floored: usize,
}

impl Outcome {
    /// Whether the renders agree (no cell rejected).
    pub fn passed(&self) -> bool {
        self.rejected == 0
    }
}

/// Welch's t-test of every cell of `a` against `b`, Holm-corrected at `alpha`.
/// `None` when the estimates' block grids differ.
pub fn welch_holm(a: &Estimate, b: &Estimate, alpha: f64) -> Option<Outcome> {
    welch_holm_floored(a, b, alpha, 0.0)
}

/// [`welch_holm`] with each cell's variance of `a` taken as at least
/// `floor` × `b`'s (that cell's variance is then the reference's estimate,
/// scaled, and carries `b`'s degrees of freedom).
///
/// Why: `a`'s variance comes from few frames, and a cell whose value is
/// heavy-tailed (rare bright paths) looks certain of a low mean when no
/// frame happened to draw one: its batch variance can be orders of
/// magnitude below the true one. With `floor` = (the reference's samples
/// per pixel) / (`a`'s), the floor is the variance `b`'s estimator would
/// have at `a`'s sample count: a lower bound for `a` whenever `a`'s
/// estimator is no better per sample than the reference's
/// (docs/reproduction-lin2017.md, "Glass against Mitsuba"). A floor of 0 is
/// [`welch_holm`].
pub fn welch_holm_floored(a: &Estimate, b: &Estimate, alpha: f64, floor: f64) -> Option<Outcome> {
    if (a.blocks_x, a.blocks_y) != (b.blocks_x, b.blocks_y) || a.mean.len() != b.mean.len() {
        return None;
    }
    let n = a.mean.len();
    let mut floored = 0;
    let mut ps: Vec<(f64, usize, f64)> = (0..n)
        .map(|i| {
            let d = a.mean[i] - b.mean[i];
            let (va, dof_a) = if a.var[i] < floor * b.var[i] {
                floored += 1;
                (floor * b.var[i], b.dof)
            } else {
                (a.var[i], a.dof)
            };
            let v = va + b.var[i];
            if v <= 0.0 {
                return (if d == 0.0 { 1.0 } else { 0.0 }, i, if d == 0.0 { 0.0 } else { f64::INFINITY });
            }
            let t = d / v.sqrt();
            let dof = v * v / (va.powi(2) / dof_a + b.var[i].powi(2) / b.dof);
            (t_two_sided_p(t, dof), i, t)
        })
        .collect();
    ps.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut rejected = 0;
    for (k, (p, _, _)) in ps.iter().enumerate() {
        if *p <= alpha / (n - k) as f64 {
            rejected += 1;
        } else {
            break;
        }
    }
    let (min_p, wi, wt) = ps.first().copied().unwrap_or((1.0, 0, 0.0));
    let b_cell = wi / 3;
    let (sa, sb): (f64, f64) = (a.mean.iter().sum(), b.mean.iter().sum());
    Some(Outcome {
        cells: n,
        rejected,
        alpha,
        min_p,
        worst: (b_cell as u32 % a.blocks_x, b_cell as u32 / a.blocks_x, wi % 3, wt),
        mean_rel_diff: if sb != 0.0 { (sa - sb) / sb } else { 0.0 },
        floored,
    })
}

/// Two-sided p-value of Student's t with `dof` degrees of freedom:
/// I_{dof/(dof+t²)}(dof/2, 1/2).
pub fn t_two_sided_p(t: f64, dof: f64) -> f64 {
    if !t.is_finite() {
        return 0.0;
    }
    let x = dof / (dof + t * t);
    reg_inc_beta(0.5 * dof, 0.5, x).clamp(0.0, 1.0)
}

fn ln_gamma(x: f64) -> f64 {
    // Lanczos (g = 7, n = 9)
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized incomplete beta function I_x(a, b) (continued fraction).
fn reg_inc_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let front = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) { front * beta_cf(a, b, x) / a } else { 1.0 - front * beta_cf(b, a, 1.0 - x) / b }
}

fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < tiny {
        d = tiny;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if d.abs() < tiny {
            d = tiny;
        }
        c = 1.0 + aa / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if d.abs() < tiny {
            d = tiny;
        }
        c = 1.0 + aa / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn student_t_p_values_match_tables() {
        // two-sided critical values: t_{0.975}(10) = 2.228, t_{0.995}(5) = 4.032; normal limit 1.960
        assert!((t_two_sided_p(2.228, 10.0) - 0.05).abs() < 5e-4);
        assert!((t_two_sided_p(4.032, 5.0) - 0.01).abs() < 1e-4);
        assert!((t_two_sided_p(1.960, 1e6) - 0.05).abs() < 5e-4);
        assert_eq!(t_two_sided_p(0.0, 3.0), 1.0);
    }

    #[test]
    fn holm_rejects_a_shifted_cell_only() {
        let mk = |shift: f64| Estimate {
            blocks_x: 4,
            blocks_y: 1,
            mean: (0..12).map(|i| if i == 5 { 1.0 + shift } else { 1.0 }).collect(),
            var: vec![1e-4; 12],
            dof: 30.0,
        };
        let same = welch_holm(&mk(0.0), &mk(0.0), 0.01).unwrap();
        assert!(same.passed());
        let off = welch_holm(&mk(0.2), &mk(0.0), 0.01).unwrap();
        assert_eq!(off.rejected, 1);
        assert_eq!((off.worst.0, off.worst.1, off.worst.2), (1, 0, 2));
    }

    /// A cell whose frames all missed its rare bright paths: its batch
    /// variance is far below the reference's at the same sample count, and
    /// the floor (the reference's, scaled by the sample counts) keeps it
    /// from being rejected; a shift beyond that variance is still rejected.
    #[test]
    fn the_floor_raises_an_underestimated_variance_only() {
        let mk = |m5: f64, v5: f64| Estimate {
            blocks_x: 4,
            blocks_y: 1,
            mean: (0..12).map(|i| if i == 5 { m5 } else { 1.0 }).collect(),
            var: (0..12).map(|i| if i == 5 { v5 } else { 1e-4 }).collect(),
            dof: 15.0,
        };
        // reference: variance of the mean 1e-6 at 64 times our samples
        let reference = Estimate { var: vec![1e-6; 12], ..mk(1.0, 1e-6) };
        // ours: 1e-4 per cell (the floor, 64e-6, is below it), cell 5 low by 0.02 with variance 1e-7
        let ours = mk(0.98, 1e-7);
        let plain = welch_holm(&ours, &reference, 0.01).unwrap();
        assert_eq!((plain.rejected, plain.floored), (1, 0));
        let floored = welch_holm_floored(&ours, &reference, 0.01, 64.0).unwrap();
        // t = -0.02 / sqrt(64e-6 + 1e-6) = -2.48: not rejected among 12 cells
        assert_eq!((floored.rejected, floored.floored), (0, 1));
        assert!((floored.worst.3 + 0.02 / 65e-6f64.sqrt()).abs() < 1e-9, "{floored:?}");
        // low by 0.1: t = -12.4 even with the floor
        let off = welch_holm_floored(&mk(0.9, 1e-7), &reference, 0.01, 64.0).unwrap();
        assert_eq!((off.rejected, off.floored), (1, 1));
    }
}
