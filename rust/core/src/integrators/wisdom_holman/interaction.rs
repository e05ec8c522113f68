//! The interaction Hamiltonian of the Wisdom–Holman splitting in Jacobi coordinates, and its
//! kick.

use super::Jacobi;

/// The accelerations of the Jacobi velocities under the interaction Hamiltonian
///
///   H_I(x′) = −G Σ_{i<j, (i,j)≠(0,1)} mᵢmⱼ/|xᵢ − xⱼ| + G Σ_{i≥2} mᵢηᵢ₋₁/|x′ᵢ|
///
/// (Wisdom & Holman 1991, eq. 14; the pair (0, 1) cancels the Kepler term of body 1 exactly):
/// a′ᵢ = −∂H_I/∂x′ᵢ / m′ᵢ = (Jacobi map of the pairwise accelerations)ᵢ + Gηᵢx′ᵢ/|x′ᵢ|³, as in
/// WHFast (Rein & Tamayo 2015, eq. 132). `x` holds the Jacobi positions; `inertial` is a work
/// buffer for the body-by-body positions. Writes a′ᵢ for i ≥ 1 into `acc` (acc₀ is left
/// meaningless); N(N − 1)/2 − 1 pairs, no allocation.
pub fn interaction_accelerations(jacobi: &Jacobi, x: &[[f64; 3]], inertial: &mut [[f64; 3]], acc: &mut [[f64; 3]]) {
    let g = jacobi.gravitational_constant();
    let masses = jacobi.masses();
    let n = masses.len();
    inertial.copy_from_slice(x);
    jacobi.backward(inertial);
    acc.fill([0.0; 3]);
    for i in 0..n {
        let xi = inertial[i];
        let mut ai = [0.0; 3];
        let first = if i == 0 { 2 } else { i + 1 };
        for j in first..n {
            let d = [inertial[j][0] - xi[0], inertial[j][1] - xi[1], inertial[j][2] - xi[2]];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let f = g / (r2 * r2.sqrt());
            let (fi, fj) = (f * masses[j], f * masses[i]);
            for k in 0..3 {
                ai[k] += fi * d[k];
                acc[j][k] -= fj * d[k];
            }
        }
        for k in 0..3 {
            acc[i][k] += ai[k];
        }
    }
    jacobi.forward(acc);
    for i in 2..n {
        let xi = x[i];
        let r2 = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2];
        let f = jacobi.mu()[i] / (r2 * r2.sqrt());
        for k in 0..3 {
            acc[i][k] += f * xi[k];
        }
    }
}
