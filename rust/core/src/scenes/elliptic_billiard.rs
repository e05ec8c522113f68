use super::{Problem, State};
use crate::model::{Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// A free particle of unit mass in the plane, H = |p|²/2, for the elliptic billiard
/// x²/A² + y²/B² ≤ 1 with A ≥ B. The table's wall is not part of the model (scenes use the
/// model layer only): Python attaches it as a contact (`varmech.scenes.elliptic_billiard`).
#[derive(Clone, Debug)]
pub struct EllipticBilliard {
    a: f64,
    b: f64,
    mass: Mass,
}

impl EllipticBilliard {
    /// The horizon of the scene's runs.
    pub const HORIZON: f64 = 100.0;

    /// The table with semi-axes A ≥ B > 0 (the foci on the x axis).
    pub fn new(a: f64, b: f64) -> Result<Self, Error> {
        if !(b.is_finite() && b > 0.0) {
            return Err(Error::invalid("B", format!("must be finite and positive, got {b}")));
        }
        if !(a.is_finite() && a >= b) {
            return Err(Error::invalid(
                "A",
                format!("must be finite and at least B = {b} (the foci on the x axis), got {a}"),
            ));
        }
        Ok(EllipticBilliard {
            a,
            b,
            mass: Mass::Scalar(1.0),
        })
    }

    /// The semi-axes (A, B).
    pub fn semi_axes(&self) -> (f64, f64) {
        (self.a, self.b)
    }

    /// φ(q) = 1 − x²/A² − y²/B², positive inside the table.
    pub fn inside(&self, q: &[f64]) -> f64 {
        let (u, v) = (q[0] / self.a, q[1] / self.b);
        1.0 - (u * u + v * v)
    }

    /// The product L₁L₂ of the angular momenta about the foci (±c, 0), c² = A² − B²,
    /// Lᵢ = (x ∓ c)p_y − y p_x: conserved between and across elastic impacts (it fixes the
    /// orbit's confocal caustic; reference/impulses_and_rolling.md).
    pub fn focal_product(&self, q: &[f64], p: &[f64]) -> f64 {
        let c = (self.a * self.a - self.b * self.b).sqrt();
        let about = |focus: f64| (q[0] - focus) * p[1] - q[1] * p[0];
        about(c) * about(-c)
    }

    /// From (x₀, y₀) strictly inside with momenta (p_x, p_y), to t = 100 (about 50 impacts at
    /// unit speed on the default table A = 2, B = 1). No reference: the invariants are the test.
    pub fn problem(a: f64, b: f64, q0: [f64; 2], p0: [f64; 2]) -> Result<Problem<Self>, Error> {
        let system = Self::new(a, b)?;
        super::finite(&[("x0", q0[0]), ("y0", q0[1]), ("px0", p0[0]), ("py0", p0[1])])?;
        if system.inside(&q0) <= 0.0 {
            return Err(Error::invalid(
                "x0",
                format!("(x0, y0) = ({}, {}) must lie strictly inside the table", q0[0], q0[1]),
            ));
        }
        Ok(Problem {
            system,
            initial: State::start(q0.to_vec(), p0.to_vec()),
            t_end: Self::HORIZON,
            reference: None,
        })
    }
}

impl MechanicalSystem for EllipticBilliard {
    fn dim(&self) -> usize {
        2
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, _q: &[f64]) -> Result<f64, ModelError> {
        Ok(0.0)
    }
    #[inline]
    fn gradient(&self, _q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.fill(0.0);
        Ok(())
    }
}
