//! The gravitational N-body problem: point masses in space under Newtonian gravity.

use super::{Generator, Mass, MechanicalSystem};
use crate::memory::check_allocation;
use crate::{Error, ModelError};

/// Gravitational N-body problem in 3 dimensions, H = Σ|pᵢ|²/2mᵢ − G Σᵢ<ⱼ mᵢmⱼ/|xᵢ − xⱼ|, with
/// q = (x₁, …, x_N) body by body; translation and rotation invariant.
#[derive(Clone, Debug)]
pub struct NBody {
    g: f64,
    masses: Vec<f64>,
    /// Products G·mᵢ·mⱼ for i < j, row by row: the force loop reads them in order.
    gmm: Vec<f64>,
    mass: Mass,
}

impl NBody {
    pub fn new(g: f64, masses: Vec<f64>) -> Result<Self, Error> {
        if !(g.is_finite() && g > 0.0) {
            return Err(Error::invalid("G", format!("must be finite and positive, got {g}")));
        }
        if masses.len() < 2 {
            return Err(Error::invalid("masses", "need at least two bodies"));
        }
        // The table of pairs, N(N − 1)/2 products.
        let n = masses.len();
        check_allocation("masses", n.saturating_mul(n - 1) / 2, std::mem::size_of::<f64>())?;
        let mass = Mass::diagonal(masses.iter().flat_map(|m| [*m; 3]).collect())?;
        let gmm = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .map(|(i, j)| g * masses[i] * masses[j])
            .collect();
        Ok(NBody { g, masses, gmm, mass })
    }

    pub fn masses(&self) -> &[f64] {
        &self.masses
    }

    pub fn gravitational_constant(&self) -> f64 {
        self.g
    }
}

impl MechanicalSystem for NBody {
    fn dim(&self) -> usize {
        3 * self.masses.len()
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        let mut v = 0.0;
        let mut k = 0;
        let n = self.masses.len();
        for i in 0..n {
            for j in i + 1..n {
                let d = [
                    q[3 * i] - q[3 * j],
                    q[3 * i + 1] - q[3 * j + 1],
                    q[3 * i + 2] - q[3 * j + 2],
                ];
                v -= self.gmm[k] / (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                k += 1;
            }
        }
        Ok(v)
    }
    /// ∂V/∂xᵢ = Σⱼ G mᵢmⱼ (xᵢ − xⱼ)/|xᵢ − xⱼ|³, each pair visited once.
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.fill(0.0);
        let mut gmm = self.gmm.iter();
        for i in 0..self.masses.len() {
            let (head, tail) = grad.split_at_mut(3 * i + 3);
            let xi = &q[3 * i..3 * i + 3];
            let mut gi = [0.0; 3];
            for ((xj, gj), k) in q[3 * i + 3..]
                .chunks_exact(3)
                .zip(tail.chunks_exact_mut(3))
                .zip(&mut gmm)
            {
                let d = [xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]];
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let f = k / (r2 * r2.sqrt());
                for a in 0..3 {
                    gi[a] += f * d[a];
                    gj[a] -= f * d[a];
                }
            }
            for (g, v) in head[3 * i..].iter_mut().zip(gi) {
                *g += v;
            }
        }
        Ok(())
    }
    fn as_nbody(&self) -> Option<&NBody> {
        Some(self)
    }
    fn symmetries(&self) -> Vec<Generator> {
        (0..3)
            .map(|axis| Generator::Translation { axis, spatial_dim: 3 })
            .chain((0..3).map(|axis| Generator::Rotation { axis, spatial_dim: 3 }))
            .collect()
    }
}
