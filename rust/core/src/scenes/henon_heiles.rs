use super::{Problem, State};
use crate::model::{Mass, MechanicalSystem};
use crate::ModelError;

/// The Hénon–Heiles system, H = (p₁² + p₂²)/2 + (q₁² + q₂²)/2 + q₁²q₂ − q₂³/3; orbits are
/// bounded below the escape energy 1/6, and chaotic in part of the energy shell near it.
#[derive(Clone, Debug)]
pub struct HenonHeiles {
    mass: Mass,
}

unit_mass!(HenonHeiles);

impl HenonHeiles {
    /// The long-run protocol of the SciML benchmarks: q = (0.1, 0), p = (0, 0.5), H = 0.13, to
    /// t = 5·10⁴ (no reference state; the energy is the invariant to check).
    pub fn problem() -> Problem<Self> {
        Problem {
            system: Self::new(),
            initial: State::start(vec![0.1, 0.0], vec![0.0, 0.5]),
            t_end: 5e4,
            reference: None,
        }
    }
}

impl MechanicalSystem for HenonHeiles {
    fn dim(&self) -> usize {
        2
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        let (x, y) = (q[0], q[1]);
        Ok(0.5 * (x * x + y * y) + x * x * y - y * y * y / 3.0)
    }
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        let (x, y) = (q[0], q[1]);
        grad[0] = x + 2.0 * x * y;
        grad[1] = y + x * x - y * y;
        Ok(())
    }
    fn hessian(&self, q: &[f64], out: &mut [f64]) -> Option<Result<(), ModelError>> {
        let (x, y) = (q[0], q[1]);
        out.copy_from_slice(&[1.0 + 2.0 * y, 2.0 * x, 2.0 * x, 1.0 - 2.0 * y]);
        Some(Ok(()))
    }
}
