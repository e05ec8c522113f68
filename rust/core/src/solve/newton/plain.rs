//! Newton's method in its plain form, for equations whose caller measures each residual
//! against its own round-off floor (the held contacts' position constraints), and on a scalar
//! equation whose Newton map the caller arranges to round well (Kepler's).

use nalgebra::DMatrix;

use crate::solve::lu::{lu_in_place, lu_solve};

/// How a [`solve`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ended {
    Converged,
    /// The measure not finite, or the iterations spent.
    Unconverged,
    /// J singular: the equations are dependent there.
    Singular,
}

/// Newton's method x ← x + δ, J(x)δ = −F(x), a fresh J each iteration (factorised in place,
/// [`lu_in_place`]), at most `iterations` evaluations: `evaluate` writes −F(x) into `r` and J(x)
/// into `jacobian`, and returns F's measure (‖F‖ against its round-off floor, say). Converged
/// where the measure is at most `floor`, or no smaller than the one before and at most `stall`
/// (F at its floor, however F rounds); unconverged where it is not finite.
///
/// `evaluate` may fail (e.g. a model error); its first error is returned.
pub(crate) fn solve<E>(
    iterations: usize,
    (floor, stall): (f64, f64),
    x: &mut [f64],
    (jacobian, pivots, r): (&mut DMatrix<f64>, &mut [usize], &mut [f64]),
    mut evaluate: impl FnMut(&[f64], &mut DMatrix<f64>, &mut [f64]) -> Result<f64, E>,
) -> Result<Ended, E> {
    let mut last = f64::INFINITY;
    for _ in 0..iterations {
        let measure = evaluate(x, jacobian, r)?;
        if measure <= floor || (measure >= last && measure <= stall) {
            return Ok(Ended::Converged);
        }
        last = measure;
        if !measure.is_finite() {
            break;
        }
        if lu_in_place(jacobian, pivots).is_none() {
            return Ok(Ended::Singular);
        }
        lu_solve(jacobian, pivots, r);
        for (x, d) in x.iter_mut().zip(r.iter()) {
            *x += d;
        }
    }
    Ok(Ended::Unconverged)
}

/// Newton's iteration x ← N(x) on a scalar equation f(x) = 0, N(x) = x − f(x)/f′(x) the
/// caller's `map` (arranged as its terms round best), at most `iterations` times. Quadratic: once
/// a correction is within `tolerance`·|x| one more reaches round-off, where x may wander by a few
/// ulps (a stop on exact repetition might not come); `polishing`: that one more is all that is
/// left. Returns the last x and whether it converged.
pub(crate) fn scalar(
    mut map: impl FnMut(f64) -> f64,
    mut x: f64,
    mut polishing: bool,
    (iterations, tolerance): (usize, f64),
) -> (f64, bool) {
    for _ in 0..iterations {
        let next = map(x);
        let correction = next - x;
        x = next;
        if polishing {
            return (x, true);
        }
        polishing = correction.abs() <= tolerance * x.abs();
    }
    (x, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_circle_and_a_line_and_reports_a_singular_jacobian() {
        // x² + y² = 2, x = y: (1, 1) from (2, 0.5).
        let mut x = [2.0, 0.5];
        let (mut jacobian, mut pivots, mut r) = (DMatrix::zeros(2, 2), [0; 2], [0.0; 2]);
        let circle = |x: &[f64], j: &mut DMatrix<f64>, r: &mut [f64]| {
            r[0] = 2.0 - x[0] * x[0] - x[1] * x[1];
            r[1] = x[1] - x[0];
            j.copy_from_slice(&[2.0 * x[0], 1.0, 2.0 * x[1], -1.0]);
            Ok::<_, ()>(r[0].abs().max(r[1].abs()) / f64::EPSILON)
        };
        let ended = solve(30, (4.0, 1e3), &mut x, (&mut jacobian, &mut pivots, &mut r), circle);
        assert_eq!(ended, Ok(Ended::Converged));
        assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14, "{x:?}");
        let flat = |_: &[f64], j: &mut DMatrix<f64>, r: &mut [f64]| {
            r.fill(1.0);
            j.fill(0.0);
            Ok::<_, ()>(1e9)
        };
        let ended = solve(30, (4.0, 1e3), &mut x, (&mut jacobian, &mut pivots, &mut r), flat);
        assert_eq!(ended, Ok(Ended::Singular));
    }

    #[test]
    fn a_scalar_newton_polishes_once_and_gives_up_on_a_cycle() {
        let (root, converged) = scalar(|x| 0.5 * (x + 2.0 / x), 1.0, false, (32, 1e-9));
        assert!(
            converged && (root - 2.0_f64.sqrt()).abs() <= f64::EPSILON * root,
            "{root}"
        );
        // x³ − 2x + 2 from 0: Newton cycles 0 → 1 → 0.
        let (_, converged) = scalar(
            |x| x - (x * x * x - 2.0 * x + 2.0) / (3.0 * x * x - 2.0),
            0.0,
            false,
            (32, 1e-9),
        );
        assert!(!converged);
    }
}
