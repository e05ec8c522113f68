//! Frobenius' test: whether velocity constraints are holonomic in disguise.

use nalgebra::{DMatrix, SymmetricEigen};

use super::VelocityConstraints;
use crate::ModelError;

/// The curvature of the constraint distribution ker A(q) at q, relative to the size of ∂A/∂q.
///
/// The constraints A(q)q̇ = 0 integrate near q to m holonomic ones g(q) = 0 exactly when ker A
/// is involutive (Frobenius), that is, when the exterior derivative of each constraint form
/// ω_k = Σⱼ A_kj dqⱼ vanishes on ker A:
///
/// Nᵀ Ω_k N = 0,   (Ω_k)ᵢⱼ = ∂A_kj/∂qᵢ − ∂A_ki/∂qⱼ,
///
/// with N (n × (n − m)) any basis of ker A(q): no smooth frame of vector fields and no Lie
/// brackets are needed. Returns max_k ‖Nᵀ Ω_k N‖ / ‖∂A/∂q‖ (max norms, N
/// orthonormal): round-off (or the accuracy of a differenced ∂A) for integrable constraints,
/// such as x ẋ + y ẏ = 0, and of order 1 for rolling, where the distribution twists. A
/// constant A gives 0: A q̇ = 0 integrates to A q = const.
///
/// The test is local: it holds at q, and a caller that wants "integrable near q₀" tests a few
/// points about q₀. It assumes A(q) has full rank m (the n − m eigenvectors of AᵀA with the
/// smallest eigenvalues span ker A).
pub fn curvature<C: VelocityConstraints + ?Sized>(constraints: &C, q: &[f64]) -> Result<f64, ModelError> {
    let (m, n) = (constraints.count(), q.len());
    let mut a = DMatrix::zeros(m, n);
    constraints.matrix(q, &mut a)?;
    if m == 0 || m >= n {
        return Ok(0.0);
    }
    let eigen = SymmetricEigen::new(a.transpose() * &a);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| eigen.eigenvalues[i].total_cmp(&eigen.eigenvalues[j]));
    let kernel = DMatrix::from_fn(n, n - m, |r, c| eigen.eigenvectors[(r, order[c])]);
    // ∂A/∂qᵢ for each i, then Ω_k from them.
    let mut derivatives = vec![DMatrix::zeros(m, n); n];
    for (i, d) in derivatives.iter_mut().enumerate() {
        constraints.derivative(q, i, d)?;
    }
    let size = derivatives.iter().map(|d| d.amax()).fold(0.0, f64::max);
    if size == 0.0 {
        return Ok(0.0);
    }
    let mut worst = 0.0_f64;
    for k in 0..m {
        let omega = DMatrix::from_fn(n, n, |i, j| derivatives[i][(k, j)] - derivatives[j][(k, i)]);
        worst = worst.max((kernel.transpose() * omega * &kernel).amax());
    }
    Ok(worst / size)
}
