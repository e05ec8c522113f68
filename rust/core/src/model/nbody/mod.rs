//! The gravitational N-body problem: point masses in space under Newtonian gravity.
//!
//! - this file: the model, [`NBody`] (G, the masses, the diagonal mass matrix);
//! - `kernel.rs`: [`PairKernel`], the instruction set of the pair loops of V and ∇V (scalar,
//!   AVX2, AVX-512) chosen at run time, and the scalar loops;
//! - `tiles.rs`: the vector loops, over tiles of bodies in structure-of-arrays layout (x86-64);
//! - `lanes.rs`: the SIMD lanes the vector loops are written over.

mod kernel;
#[cfg(target_arch = "x86_64")]
mod lanes;
#[cfg(target_arch = "x86_64")]
mod tiles;

pub use kernel::PairKernel;

use super::{Generator, Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// Gravitational N-body problem in 3 dimensions, H = Σ|pᵢ|²/2mᵢ − G Σᵢ<ⱼ mᵢmⱼ/|xᵢ − xⱼ|, with
/// q = (x₁, y₁, z₁, x₂, …) body by body; translation and rotation invariant.
///
/// It keeps O(N) data: the masses mᵢ and the products G·mᵢ (a pair's G·mᵢ·mⱼ is formed as
/// (G·mᵢ)·mⱼ when the pair is visited, the same rounding as a table of products). V and ∇V
/// visit each unique pair once, the SIMD [`PairKernel`] of the CPU ([`PairKernel::detect`]).
#[derive(Clone, Debug)]
pub struct NBody {
    g: f64,
    masses: Vec<f64>,
    /// G·mᵢ, body by body.
    gm: Vec<f64>,
    mass: Mass,
    kernel: PairKernel,
}

impl NBody {
    /// The N-body problem of `masses` (N ≥ 2, each finite and positive) under the gravitational
    /// constant `g` (finite, positive), with the widest pair kernel of this CPU.
    pub fn new(g: f64, masses: Vec<f64>) -> Result<Self, Error> {
        if !(g.is_finite() && g > 0.0) {
            return Err(Error::invalid("G", format!("must be finite and positive, got {g}")));
        }
        if masses.len() < 2 {
            return Err(Error::invalid("masses", "need at least two bodies"));
        }
        let mass = Mass::diagonal(masses.iter().flat_map(|m| [*m; 3]).collect())?;
        let gm = masses.iter().map(|m| g * m).collect();
        Ok(NBody {
            g,
            masses,
            gm,
            mass,
            kernel: PairKernel::detect(),
        })
    }

    /// The same model evaluated by `kernel`; refused where this CPU lacks its instructions.
    pub fn with_kernel(self, kernel: PairKernel) -> Result<Self, Error> {
        if !kernel.is_available() {
            return Err(Error::invalid(
                "kernel",
                format!("{kernel:?} needs instructions this CPU lacks"),
            ));
        }
        Ok(NBody { kernel, ..self })
    }

    /// The pair kernel V and ∇V run.
    pub fn kernel(&self) -> PairKernel {
        self.kernel
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
    /// V = −Σᵢ<ⱼ G mᵢmⱼ / |xᵢ − xⱼ|, each pair visited once.
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(self.kernel.potential(&self.gm, &self.masses, q))
    }
    /// ∂V/∂xᵢ = Σⱼ G mᵢmⱼ (xᵢ − xⱼ)/|xᵢ − xⱼ|³, each pair visited once.
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        self.kernel.gradient(&self.gm, &self.masses, q, grad);
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
