//! Derivatives by differences, for models that do not supply them.

use crate::ModelError;

/// √ε: relative changes below this in a Newton iteration whose equations are built from central
/// differences (accurate to about ε^{2/3}) are noise, and a correction there that a fresh
/// Newton step cannot halve means the iteration has converged as far as it can.
pub const NOISE_FLOOR: f64 = 1.5e-8;

/// ∇f(q) by central differences, ∂f/∂qᵢ ≈ [f(q + hᵢeᵢ) − f(q − hᵢeᵢ)] / 2hᵢ, with the step
/// hᵢ = ε^{1/3}·max(|qᵢ|, 1) that balances the O(h²) truncation against the O(ε/h) round-off
/// (ε the machine epsilon), for an error of order ε^{2/3} ≈ 4e-11 relative.
///
/// `work` (length n) is scratch space, so the call allocates nothing.
pub fn central_gradient<F>(mut f: F, q: &[f64], work: &mut [f64], grad: &mut [f64]) -> Result<(), ModelError>
where
    F: FnMut(&[f64]) -> Result<f64, ModelError>,
{
    let cbrt_eps = f64::EPSILON.cbrt();
    work.copy_from_slice(q);
    for i in 0..q.len() {
        let h = cbrt_eps * q[i].abs().max(1.0);
        work[i] = q[i] + h;
        let forward = f(work)?;
        work[i] = q[i] - h;
        let backward = f(work)?;
        work[i] = q[i];
        grad[i] = (forward - backward) / (2.0 * h);
    }
    Ok(())
}
