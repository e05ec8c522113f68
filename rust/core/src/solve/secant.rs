//! A root of a scalar function by the secant method, for roots without a bracket.

/// A root of f by the secant method from x₀ (its value f₀ = f(x₀) given) and x₁:
/// x_{k+1} = x_k − f_k (x_k − x_{k−1})/(f_k − f_{k−1}), at most `iterations` evaluations.
/// Converged at the first x_k with |f_k| ≤ `noise` (f's rounding: no secant tells a better
/// root) or within 4 ulps of x_{k−1}; None where the secant has no slope (f_k = f_{k−1}), f_k
/// is not finite, or the evaluations run out.
///
/// `f` may fail (e.g. a model error); its first error is returned.
pub(crate) fn secant<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    (mut x0, mut f0): (f64, f64),
    mut x1: f64,
    noise: f64,
    iterations: usize,
) -> Result<Option<f64>, E> {
    for _ in 0..iterations {
        let f1 = f(x1)?;
        if f1.abs() <= noise || (x1 - x0).abs() <= 4.0 * f64::EPSILON * x1.abs() {
            return Ok(Some(x1));
        }
        if f1 == f0 || !f1.is_finite() {
            break;
        }
        (x0, x1, f0) = (x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1);
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::secant;

    #[test]
    fn finds_a_square_root_and_gives_up_without_a_slope() {
        let f = |x: f64| Ok::<_, ()>(x * x - 2.0);
        let root = secant(f, (1.0, -1.0), 2.0, 1e-15, 40).unwrap().unwrap();
        assert!((root - 2.0_f64.sqrt()).abs() < 1e-15, "{root}");
        assert_eq!(secant(|_| Ok::<_, ()>(1.0), (0.0, 1.0), 1.0, 0.0, 40), Ok(None));
    }
}
