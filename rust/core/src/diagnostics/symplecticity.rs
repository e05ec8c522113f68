use nalgebra::DMatrix;

use crate::error::check_vector;
use crate::integrators::{Dynamics, Increment, Integrator, Method, StepStart};
use crate::Error;

/// The symplecticity defect ‖ΨᵀJΨ − J‖_F of one step of `method` from (q, p), where Ψ is the
/// Jacobian of the one-step map and J = [[0, I], [−I, 0]]. Zero (to round-off) for a symplectic
/// method.
///
/// Ψ comes from fourth-order central differences, Ψeⱼ ≈ [8(Φ(x+δ) − Φ(x−δ)) − (Φ(x+2δ) −
/// Φ(x−2δ))]/12δ with δ = 1e-3·max(|xⱼ|, 1), whose O(δ⁴) truncation and O(ε/δ) round-off both
/// stay near 1e-12 for a smooth map of unit scale.
pub fn symplecticity_defect<S: Dynamics + ?Sized>(
    sys: &S,
    method: Method,
    q: &[f64],
    p: &[f64],
    h: f64,
) -> Result<f64, Error> {
    let n = sys.dim();
    check_vector("q", q, n)?;
    check_vector("p", p, n)?;
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::invalid("dt", format!("must be finite and positive, got {h}")));
    }
    method.check(sys.kind())?;
    let mut integrator = Integrator::new(method, n);
    let mut flow = |x: &[f64]| -> Result<Vec<f64>, Error> {
        let (mut dq, mut dp) = (vec![0.0; n], vec![0.0; n]);
        integrator.reset();
        let start = StepStart {
            t: 0.0,
            h,
            q: &x[..n],
            p: &x[n..],
        };
        let mut increment = Increment {
            dq: &mut dq,
            dp: &mut dp,
        };
        sys.increment(&mut integrator, &start, &mut increment)
            .map_err(|e| e.at(1, 0.0))?;
        Ok(x.iter().zip(dq.iter().chain(&dp)).map(|(a, d)| a + d).collect())
    };
    let x0: Vec<f64> = q.iter().chain(p).copied().collect();
    let mut psi = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for j in 0..2 * n {
        let delta = 1e-3 * x0[j].abs().max(1.0);
        let mut at = |k: f64| {
            let mut x = x0.clone();
            x[j] += k * delta;
            flow(&x)
        };
        let (p1, m1, p2, m2) = (at(1.0)?, at(-1.0)?, at(2.0)?, at(-2.0)?);
        for i in 0..2 * n {
            psi[(i, j)] = (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * delta);
        }
    }
    let mut j = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        j[(i, n + i)] = 1.0;
        j[(n + i, i)] = -1.0;
    }
    let defect = (psi.transpose() * &j * &psi - j).norm();
    // Finite arguments whose step (or its differences) overflows leave no defect to report.
    if !defect.is_finite() {
        let reason = format!(
            "one step of {} from this state overflows, so its symplecticity defect is undefined (got {defect}); \
             take smaller values",
            method.info().name
        );
        return Err(Error::invalid("q, p, dt", reason));
    }
    Ok(defect)
}
