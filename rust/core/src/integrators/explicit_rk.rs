use super::{Increment, StepStart};
use crate::model::MechanicalSystem;
use crate::ModelError;
use serde::{Deserialize, Serialize};

/// An explicit Runge–Kutta method whose Butcher matrix has only a subdiagonal, aᵢ,ᵢ₋₁ = cᵢ,
/// applied to q̇ = M⁻¹p, ṗ = −∇V(q):
///
/// kᵢ = f(yₙ + cᵢh kᵢ₋₁),   yₙ₊₁ = yₙ + h Σ wᵢkᵢ.
///
/// This covers explicit Euler (c = 0, w = 1) and classical RK4 (c = 0, ½, ½, 1;
/// w = ⅙, ⅓, ⅓, ⅙), the non-structure-preserving baselines.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExplicitRk {
    tableau: Tableau,
    q: Vec<f64>,
    p: Vec<f64>,
    kq: Vec<f64>,
    kp: Vec<f64>,
    evaluations: u64,
}

impl ExplicitRk {
    fn new(tableau: Tableau, n: usize) -> Self {
        ExplicitRk {
            tableau,
            q: vec![0.0; n],
            p: vec![0.0; n],
            kq: vec![0.0; n],
            kp: vec![0.0; n],
            evaluations: 0,
        }
    }

    /// Explicit Euler: qₙ₊₁ = qₙ + hM⁻¹pₙ, pₙ₊₁ = pₙ − h∇V(qₙ).
    pub fn euler(n: usize) -> Self {
        Self::new(Tableau::Euler, n)
    }

    /// The classical fourth-order Runge–Kutta method.
    pub fn rk4(n: usize) -> Self {
        Self::new(Tableau::Rk4, n)
    }

    pub(super) fn force_evaluations(&self) -> u64 {
        self.evaluations
    }

    pub(super) fn increment<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        start: &StepStart,
        increment: &mut Increment,
    ) -> Result<(), ModelError> {
        let StepStart { h, q, p, .. } = *start;
        let Increment { dq, dp } = increment;
        dq.fill(0.0);
        dp.fill(0.0);
        let (c, w) = self.tableau.coefficients();
        for (&c, &w) in c.iter().zip(w) {
            if c == 0.0 {
                // The first stage: the previous k may hold anything, even non-finite values.
                self.q.copy_from_slice(q);
                self.p.copy_from_slice(p);
            } else {
                for i in 0..q.len() {
                    self.q[i] = q[i] + c * h * self.kq[i];
                    self.p[i] = p[i] + c * h * self.kp[i];
                }
            }
            sys.mass().velocity(&self.p, &mut self.kq);
            self.evaluations += 1;
            sys.gradient(&self.q, &mut self.kp)?;
            for i in 0..q.len() {
                self.kp[i] = -self.kp[i];
                dq[i] += w * h * self.kq[i];
                dp[i] += w * h * self.kp[i];
            }
        }
        Ok(())
    }
}

/// The two tableaux, by name (so that a serialised integrator names its coefficients).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
enum Tableau {
    Euler,
    Rk4,
}

impl Tableau {
    /// (c, w).
    fn coefficients(self) -> (&'static [f64], &'static [f64]) {
        match self {
            Tableau::Euler => (&[0.0], &[1.0]),
            Tableau::Rk4 => (&[0.0, 0.5, 0.5, 1.0], &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0]),
        }
    }
}
