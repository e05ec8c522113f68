use crate::model::{Mass, MechanicalSystem};
use crate::ModelError;

/// A free rigid body in coordinates whose kinetic energy is ½q̇ᵀMq̇ with constant diagonal M and
/// no potential (a coin's contact point, heading and rolling angle; a sleigh's centre and
/// heading): what velocity constraints then hold ([`super::NonholonomicScene`]).
#[derive(Clone, Debug)]
pub struct FreeBody {
    mass: Mass,
    dim: usize,
}

impl FreeBody {
    /// The body with the masses and moments of inertia `diagonal`, all positive.
    pub fn new(diagonal: Vec<f64>) -> Result<Self, crate::Error> {
        let dim = diagonal.len();
        Ok(FreeBody {
            mass: Mass::diagonal(diagonal)?,
            dim,
        })
    }
}

impl MechanicalSystem for FreeBody {
    fn dim(&self) -> usize {
        self.dim
    }

    fn mass(&self) -> &Mass {
        &self.mass
    }

    fn potential(&self, _q: &[f64]) -> Result<f64, ModelError> {
        Ok(0.0)
    }

    fn gradient(&self, _q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.fill(0.0);
        Ok(())
    }
}
