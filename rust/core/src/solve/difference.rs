//! Derivatives by central differences, for models and equations that do not supply them.
//!
//! Every difference here steps by hᵢ = ε^{1/3}·max(|xᵢ|, floor) (ε the machine epsilon), which
//! balances the O(h²) truncation against the O(ε/h) round-off, for an error of order
//! ε^{2/3} ≈ 4e-11 relative.

use nalgebra::DMatrix;

use crate::ModelError;

/// √ε: relative changes below this in a Newton iteration whose equations are built from central
/// differences (accurate to about ε^{2/3}) are noise, and a correction there that a fresh
/// Newton step cannot halve means the iteration has converged as far as it can.
pub const NOISE_FLOOR: f64 = 1.5e-8;

/// ε^{1/3}, written out: `f64::cbrt` is not a `const fn`, and a libm call per difference costs
/// as much as a cheap model's gradient.
pub const CBRT_EPSILON: f64 = 6.055_454_452_393_339_5e-6;

/// The central-difference step for a variable of magnitude `size`: ε^{1/3}·size.
#[inline]
pub fn step(size: f64) -> f64 {
    CBRT_EPSILON * size
}

/// The forward-difference step for a variable of magnitude `size`: √ε·size, which balances a
/// one-sided difference's O(h) truncation against its O(ε/h) round-off (error about √ε).
#[inline]
pub fn forward_step(size: f64) -> f64 {
    f64::EPSILON.sqrt() * size
}

/// The magnitude a variable's difference step is relative to: max(|x|, 1).
pub fn unit(_: usize, x: f64) -> f64 {
    x.abs().max(1.0)
}

/// ∇f(q) by central differences, ∂f/∂qᵢ ≈ [f(q + hᵢeᵢ) − f(q − hᵢeᵢ)] / 2hᵢ, with the step
/// hᵢ = ε^{1/3}·max(|qᵢ|, 1).
///
/// `work` (length n) is scratch space, so the call allocates nothing.
pub fn central_gradient<F>(mut f: F, q: &[f64], work: &mut [f64], grad: &mut [f64]) -> Result<(), ModelError>
where
    F: FnMut(&[f64]) -> Result<f64, ModelError>,
{
    work.copy_from_slice(q);
    for i in 0..q.len() {
        let h = step(unit(i, q[i]));
        work[i] = q[i] + h;
        let forward = f(work)?;
        work[i] = q[i] - h;
        let backward = f(work)?;
        work[i] = q[i];
        grad[i] = (forward - backward) / (2.0 * h);
    }
    Ok(())
}

/// The two evaluations of a central difference, f(x + hⱼeⱼ) and f(x − hⱼeⱼ) (length m each):
/// scratch space, so that a Jacobian allocates nothing.
#[derive(Debug)]
pub struct Evaluations<'a> {
    pub plus: &'a mut [f64],
    pub minus: &'a mut [f64],
}

/// ∂f/∂x (m × n) of f: ℝⁿ → ℝᵐ by central differences, column by column,
///
/// ∂f/∂xⱼ ≈ [f(x + hⱼeⱼ) − f(x − hⱼeⱼ)] / 2hⱼ,   hⱼ = ε^{1/3}·size(j, xⱼ),
///
/// `size` the magnitude the step is relative to ([`fn@unit`] for max(|xⱼ|, 1)). x is moved and
/// restored in place; nothing is allocated.
pub fn central_jacobian<E, F>(
    mut f: F,
    x: &mut [f64],
    size: impl Fn(usize, f64) -> f64,
    at: Evaluations<'_>,
    jac: &mut DMatrix<f64>,
) -> Result<(), E>
where
    F: FnMut(&[f64], &mut [f64]) -> Result<(), E>,
{
    for j in 0..x.len() {
        let xj = x[j];
        let h = step(size(j, xj));
        x[j] = xj + h;
        f(x, at.plus)?;
        x[j] = xj - h;
        f(x, at.minus)?;
        x[j] = xj;
        for (i, (a, b)) in at.plus.iter().zip(at.minus.iter()).enumerate() {
            jac[(i, j)] = (a - b) / (2.0 * h);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn cbrt_epsilon_is_the_cube_root_of_epsilon() {
        assert_eq!(super::CBRT_EPSILON.to_bits(), f64::EPSILON.cbrt().to_bits());
    }
}
