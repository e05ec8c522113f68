//! The secular equation of a trust region's boundary (Moré & Sorensen 1983, "Computing a
//! trust region step", SIAM J. Sci. Stat. Comput. 4, 553–572): the multiplier ρ ≥ 0 of
//! |(ρI + cW)⁻¹b| = 1, by safeguarded Newton on Cholesky factors.

use super::cholesky::{backward, factorise, forward};

/// The direction x/|x| of x(ρ) = (ρI + cW)⁻¹b with |x(ρ)| = 1, into `direction` (k = |b|
/// entries), for W symmetric positive semidefinite (`metric`, k × k row-major), c > 0 finite
/// and b ≠ 0; ρ = 0 where |x(0)| ≤ 1 already. Newton on the secular equation
/// g(ρ) = 1/|x(ρ)| − 1 (concave, increasing, nearly linear), g' = xᵀ(ρI + cW)⁻¹x/|x|³, from
/// ρ = 0, safeguarded by bisection on [0, |b|] (|x(|b|)| ≤ 1): ρ ← ρ − g/g', bisected where it
/// leaves the bracket, until it moves by a few ulps of |b| + c·tr W, at most 100 times. ρI + cW
/// not positive definite: the root is to the right of ρ. `direction` starts as b/|b|;
/// `factor` (k × k) and `work` (2k) are scratch.
pub(crate) fn direction(
    (metric, c): (&[f64], f64),
    b: &[f64],
    factor: &mut [f64],
    (direction, work): (&mut [f64], &mut [f64]),
) {
    let k = b.len();
    let size = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    unit(direction, b);
    let (x, w) = work.split_at_mut(k);
    let trace: f64 = (0..k).map(|i| metric[i * k + i]).sum();
    let (mut low, mut high, mut rho) = (0.0, size, 0.0);
    let tolerance = 4.0 * f64::EPSILON * (size + c * trace);
    for _ in 0..100 {
        for i in 0..k {
            for j in 0..=i {
                factor[i * k + j] = c * metric[i * k + j] + if i == j { rho } else { 0.0 };
            }
        }
        if !factorise(factor, k) {
            low = rho;
            rho = 0.5 * (low + high);
            continue;
        }
        // x = (ρI + cW)⁻¹b = L⁻ᵀL⁻¹b, then w = L⁻¹x: |w|² = xᵀ(ρI + cW)⁻¹x.
        forward(factor, b, w, k);
        backward(factor, w, x, k);
        forward(factor, x, w, k);
        let length = x.iter().map(|y| y * y).sum::<f64>().sqrt();
        let curvature = w.iter().map(|y| y * y).sum::<f64>();
        unit(direction, x);
        let g = 1.0 / length - 1.0;
        if g >= 0.0 {
            if rho == 0.0 {
                return;
            }
            high = rho;
        } else {
            low = rho;
        }
        let mut next = rho - g * length.powi(3) / curvature;
        if !(next > low && next < high) {
            next = 0.5 * (low + high);
        }
        if (next - rho).abs() <= tolerance {
            return;
        }
        rho = next;
    }
}

/// x/|x| into `direction`, 0 for x = 0.
pub(crate) fn unit(direction: &mut [f64], x: &[f64]) {
    let size = x.iter().map(|y| y * y).sum::<f64>().sqrt();
    for (d, y) in direction.iter_mut().zip(x) {
        *d = if size > 0.0 { y / size } else { 0.0 };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_boundary_of_a_diagonal_metric() {
        // W = diag(1, 3), c = 1, b = (2, 4): x = (2/(ρ + 1), 4/(ρ + 3)), |x| = 1 at ρ ≈ 2.18.
        let (metric, b) = ([1.0, 0.0, 0.0, 3.0], [2.0, 4.0]);
        let (mut factor, mut d, mut work) = ([0.0; 4], [0.0; 2], [0.0; 4]);
        direction((&metric, 1.0), &b, &mut factor, (&mut d, &mut work));
        let rho = 2.0 / d[0] - 1.0;
        assert!((4.0 / (rho + 3.0) - d[1]).abs() < 1e-12, "{d:?}");
        assert!((d[0].hypot(d[1]) - 1.0).abs() < 1e-15);
    }
}
