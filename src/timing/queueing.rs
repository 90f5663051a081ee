//! Exact mean value analysis of a closed queueing network: `n` customers
//! (warps) circulate through queueing stations (the issue port, the texture
//! units, DRAM) and one pure delay (memory latency). The textbook recursion
//! (Reiser & Lavenberg 1980; Lazowska et al., *Quantitative System
//! Performance*, 1984, ch. 6): for k = 1..n, the residence time at station i
//! is R_i = D_i (1 + Q_i(k−1)), the throughput X = k / (Z + Σ R_i), and the
//! queue length Q_i(k) = X R_i.

/// Throughput (customers completing a round per unit of time) of `n`
/// customers over stations with service demands `demands` and a delay `z`
/// (same time unit). Zero when `n` is zero or nothing takes time.
pub fn throughput(demands: &[f64], z: f64, n: u32) -> f64 {
    let mut q = vec![0.0; demands.len()];
    let mut x = 0.0;
    for k in 1..=n {
        let r: Vec<f64> = demands.iter().zip(&q).map(|(d, q)| d * (1.0 + q)).collect();
        let total = z + r.iter().sum::<f64>();
        if total <= 0.0 {
            return 0.0;
        }
        x = k as f64 / total;
        for (qi, ri) in q.iter_mut().zip(&r) {
            *qi = x * ri;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::throughput;

    #[test]
    fn one_customer_takes_the_sum_of_its_demands() {
        assert!((throughput(&[2.0, 3.0], 5.0, 1) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn many_customers_saturate_the_bottleneck() {
        let x = throughput(&[4.0, 1.0], 20.0, 200);
        assert!((x - 0.25).abs() < 1e-3, "{x}");
    }

    #[test]
    fn throughput_never_exceeds_either_bound() {
        for n in 1..40 {
            let x = throughput(&[4.0, 2.0], 100.0, n);
            assert!(x <= 0.25 + 1e-12 && x <= n as f64 / 106.0 + 1e-12, "{n}: {x}");
        }
    }
}
