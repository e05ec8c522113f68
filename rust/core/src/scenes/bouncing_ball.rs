use super::{Problem, State};
use crate::model::{Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// A point mass above a floor under gravity g, H = p²/2 + gq in its height q (unit mass). The
/// floor q ≥ 0 is not part of the model (scenes use the model layer only): Python attaches it
/// as a contact with the restitution (`varmech.scenes.bouncing_ball`).
#[derive(Clone, Debug)]
pub struct BouncingBall {
    g: f64,
    mass: Mass,
}

impl BouncingBall {
    pub fn new(g: f64) -> Result<Self, Error> {
        super::positive(&[("g", g)])?;
        Ok(BouncingBall {
            g,
            mass: Mass::Scalar(1.0),
        })
    }

    /// The bounces the scene follows, K: ten, or fewer where the flights shrink below 10⁻⁴ of
    /// the first sooner (the k-th lasts 2eᵏt₁, so K ≤ ln 10⁻⁴ / ln e), which a step resolving
    /// them would take millions of steps a flight to reach (e = 0.05: K = 3).
    pub fn bounces(restitution: f64) -> i32 {
        if restitution >= 1.0 {
            return 10;
        }
        // Between 1 and 10, so the cast is exact.
        (1e-4_f64.ln() / restitution.ln()).floor().clamp(1.0, 10.0) as i32
    }

    /// The time of the apex after the K-th impact ([`Self::bounces`]), from rest at h₀ with
    /// restitution e: the first impact is at t₁ = √(2h₀/g), the k-th rebound rises to h₀e²ᵏ and
    /// the flights after the first fall last 2eᵏt₁, so t₁(1 + 2(e + … + eᴷ⁻¹) + eᴷ)
    /// (reference/impulses_and_rolling.md).
    pub fn horizon(g: f64, h0: f64, restitution: f64) -> f64 {
        let last = Self::bounces(restitution);
        let flights: f64 = (1..last).map(|k| 2.0 * restitution.powi(k)).sum();
        (2.0 * h0 / g).sqrt() * (1.0 + flights + restitution.powi(last))
    }

    /// Dropped from rest at h₀ with restitution e ∈ (0, 1], to the apex after the K-th impact
    /// ([`Self::horizon`]), where q = h₀e²ᴷ and p = 0 (exact).
    pub fn problem(g: f64, h0: f64, restitution: f64) -> Result<Problem<Self>, Error> {
        let system = Self::new(g)?;
        super::positive(&[("h0", h0)])?;
        if !(restitution > 0.0 && restitution <= 1.0) {
            return Err(Error::invalid(
                "restitution",
                format!("must lie in (0, 1] (at 0 the ball comes to rest on the floor), got {restitution}"),
            ));
        }
        let t_end = Self::horizon(g, h0, restitution);
        Ok(Problem {
            system,
            initial: State::start(vec![h0], vec![0.0]),
            t_end,
            reference: Some((
                State {
                    t: t_end,
                    q: vec![h0 * restitution.powi(2 * Self::bounces(restitution))],
                    p: vec![0.0],
                },
                "exact: the apex after the last bounce followed (reference/impulses_and_rolling.md)",
            )),
        })
    }
}

impl MechanicalSystem for BouncingBall {
    fn dim(&self) -> usize {
        1
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(self.g * q[0])
    }
    #[inline]
    fn gradient(&self, _q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad[0] = self.g;
        Ok(())
    }
}
