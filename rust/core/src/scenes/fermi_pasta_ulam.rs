use super::{Problem, State};
use crate::model::{Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// The Fermi–Pasta–Ulam problem of HLW I.5: 2m unit masses in a chain with fixed ends, stiff
/// linear springs (frequency ω) alternating with soft quartic ones,
///
/// H = Σpᵢ²/2 + (ω²/4)Σᵢ₌₁ᵐ(q₂ᵢ − q₂ᵢ₋₁)² + Σᵢ₌₀ᵐ(q₂ᵢ₊₁ − q₂ᵢ)⁴,   q₀ = q₂ₘ₊₁ = 0.
///
/// The total oscillatory energy of the stiff springs is an adiabatic invariant.
#[derive(Clone, Debug)]
pub struct FermiPastaUlam {
    m: usize,
    omega: f64,
    mass: Mass,
}

impl FermiPastaUlam {
    pub fn new(m: usize, omega: f64) -> Result<Self, Error> {
        if m == 0 {
            return Err(Error::invalid("m", "needs at least one stiff spring"));
        }
        super::positive(&[("omega", omega)])?;
        Ok(FermiPastaUlam {
            m,
            omega,
            mass: Mass::Scalar(1.0),
        })
    }

    /// HLW I.5: m = 3, ω = 50, the first stiff spring excited, H₀ = 2.00120008.
    pub fn problem() -> Problem<Self> {
        let mut q = vec![0.0; 6];
        let mut p = vec![0.0; 6];
        q[0] = 0.6929646455628166;
        q[1] = 0.7212489168102785;
        p[1] = std::f64::consts::SQRT_2;
        Problem {
            system: Self::new(3, 50.0).expect("valid parameters"),
            initial: State::start(q, p),
            t_end: 200.0,
            reference: None,
        }
    }

    /// The oscillatory energy of stiff spring j (1-based), Iⱼ = (ẋⱼ² + ω²xⱼ²)/2 with
    /// xⱼ = (q₂ⱼ − q₂ⱼ₋₁)/√2 (the adiabatic invariant is their sum).
    pub fn oscillatory_energy(&self, q: &[f64], p: &[f64], j: usize) -> f64 {
        let x = (q[2 * j - 1] - q[2 * j - 2]) / std::f64::consts::SQRT_2;
        let y = (p[2 * j - 1] - p[2 * j - 2]) / std::f64::consts::SQRT_2;
        0.5 * (y * y + self.omega * self.omega * x * x)
    }

    /// q₀ … q₂ₘ₊₁ with the fixed ends, q₀ = q₂ₘ₊₁ = 0 (`x` holds q₁ … q₂ₘ).
    fn position(&self, x: &[f64], k: usize) -> f64 {
        if k == 0 || k == 2 * self.m + 1 {
            0.0
        } else {
            x[k - 1]
        }
    }
}

impl MechanicalSystem for FermiPastaUlam {
    fn dim(&self) -> usize {
        2 * self.m
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        let stiff: f64 = (1..=self.m).map(|i| (q[2 * i - 1] - q[2 * i - 2]).powi(2)).sum();
        let soft: f64 = (0..=self.m)
            .map(|i| (self.position(q, 2 * i + 1) - self.position(q, 2 * i)).powi(4))
            .sum();
        Ok(0.25 * self.omega * self.omega * stiff + soft)
    }
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.fill(0.0);
        let w2 = 0.5 * self.omega * self.omega;
        for i in 1..=self.m {
            let d = w2 * (q[2 * i - 1] - q[2 * i - 2]);
            grad[2 * i - 1] += d;
            grad[2 * i - 2] -= d;
        }
        for i in 0..=self.m {
            let d = self.position(q, 2 * i + 1) - self.position(q, 2 * i);
            let f = 4.0 * d * d * d;
            if i < self.m {
                grad[2 * i] += f;
            }
            if i > 0 {
                grad[2 * i - 1] -= f;
            }
        }
        Ok(())
    }
}
