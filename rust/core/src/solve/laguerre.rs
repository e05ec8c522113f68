//! Laguerre's iteration for a root of a scalar function, in the form Conway (1986) gave it for
//! Kepler's equation ("An improved algorithm due to Laguerre for the solution of Kepler's
//! equation", Celest. Mech. 39, 199–211): it converges from almost any start.

/// A root of f by Laguerre's iteration of degree n = 5 from x,
/// x ← x − nf/(f′ ± √|(n − 1)²f′² − n(n − 1)ff″|), the root's sign f′'s, at most `iterations`
/// times, until a step within `tolerance`·|x| or a NaN step (then x is NaN: the caller's
/// fallback takes over). `derivatives(x)` gives (f, f′, f″).
pub(crate) fn laguerre(
    mut derivatives: impl FnMut(f64) -> (f64, f64, f64),
    mut x: f64,
    iterations: usize,
    tolerance: f64,
) -> f64 {
    for _ in 0..iterations {
        let (f, fp, fpp) = derivatives(x);
        let step = 5.0 * f / (fp + (16.0 * fp * fp - 20.0 * f * fpp).abs().sqrt().copysign(fp));
        x -= step;
        if step.abs() <= tolerance * x.abs() || step.is_nan() {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::laguerre;

    #[test]
    fn solves_keplers_equation_from_a_poor_start() {
        // E − e sin E = M, e = 0.99, M = 0.1, from E = 10.
        let (e, m) = (0.99, 0.1);
        let root = laguerre(
            |x| (x - e * x.sin() - m, 1.0 - e * x.cos(), e * x.sin()),
            10.0,
            64,
            1e-14,
        );
        assert!((root - e * root.sin() - m).abs() < 1e-14, "{root}");
    }
}
