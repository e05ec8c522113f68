use super::{segment, StepEquations};
use crate::discrete::{Galerkin, Quadrature};
use crate::integrators::StepStart;
use crate::model::Lagrangian;
use crate::solve::difference;
use crate::ModelError;

/// The Galerkin variational integrator (Marsden & West 2001, §2.6; order 2s): its L_d made
/// stationary in the interior control points, with the Legendre transforms at the ends,
///
/// F = (∂L_d/∂Q₁, …, ∂L_d/∂Q_{s−1}, p₀ + ∂L_d/∂Q₀),   p₁ = ∂L_d/∂Q_s,
///
/// so that p₁ − p₀ = Σⱼ ∂L_d/∂Qⱼ − ΣF = hΣᵢ bᵢ ∂L/∂q(cᵢ) − ΣF, free of cancellation.
impl StepEquations for Galerkin {
    fn unknowns(&self, n: usize) -> usize {
        self.quadrature.degree() * n
    }

    fn equations<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let (n, s, h) = (start.q.len(), self.quadrature.degree(), start.h);
        self.derivatives(sys, segment(&start, x), false)?;
        // F sums the nodes' derivatives with weights whose sizes add up to 2.3 (s = 2) and 3
        // (s = 3): so too their rounding, where they are differences (none recorded else, and
        // the gain, about a hundred instructions, is not worth computing).
        let noise = difference::take_noise();
        if noise > 0.0 {
            difference::record(noise * self.noise_gain(h));
        }
        for j in 1..s {
            self.slot(j, h, &mut out[(j - 1) * n..j * n]);
        }
        let last = &mut out[(s - 1) * n..];
        self.slot(0, h, last);
        last.iter_mut().zip(start.p).for_each(|(o, p)| *o += p);
        Ok(())
    }

    fn momentum_change<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError> {
        let at = segment(&start, x);
        let work = self.derivatives(sys, at, true)?;
        self.slot_sum(start.h, dp);
        for block in residual.chunks_exact(start.q.len()) {
            dp.iter_mut().zip(block).for_each(|(d, r)| *d -= r);
        }
        // ∂L_d/∂t at the solution alone, not at each of Newton's iterates.
        self.energy_put_in(sys, at, work)
    }

    /// The control points along the predicted increment: Qⱼ − q₀ = (j/s)·δq.
    fn predict(&self, dq: &[f64], x: &mut [f64]) {
        let n = dq.len();
        let s = self.quadrature.degree();
        for j in 1..=s {
            let w = j as f64 / s as f64;
            x[(j - 1) * n..j * n].iter_mut().zip(dq).for_each(|(x, d)| *x = w * d);
        }
    }

    fn quadrature(&mut self) -> &mut Quadrature {
        &mut self.quadrature
    }
}

impl super::Del<Galerkin> {
    /// The discrete energy of the last step, from `start` ([`Galerkin::energy`] at its solved
    /// control points).
    pub(in crate::integrators) fn energy<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
    ) -> Result<f64, ModelError> {
        let controls = &self.x[self.m..];
        self.scheme.energy(sys, segment(&start, controls))
    }
}
