//! The tangent map DΨ_h of a step: the step's linearization, applied to tangent vectors
//! (δq, δp), for the variational equations of chaos indicators (Lyapunov spectra).
//!
//! A kick–drift step is a composition of shears, so its tangent map is one too, exactly:
//! a drift q ← q + bhM⁻¹p maps δq ← δq + bhM⁻¹δp, a kick p ← p − ah∇V(q) maps
//! δp ← δp − ahH(q)δq with H = ∂²V/∂q² at the kick's point. With H symmetric each factor has
//! determinant 1 and is symplectic, so the tangent map is, to round-off, whatever H's accuracy:
//! a differenced H is symmetrized.

use nalgebra::DMatrix;

use super::{Method, Splitting};
use crate::model::MechanicalSystem;
use crate::solve::difference::{central_jacobian, unit, Evaluations};
use crate::{Error, ModelError};

/// The tangent map of one method's step on n coordinates, with its buffers: [`Tangent::apply`]
/// allocates nothing.
#[derive(Clone, Debug)]
pub struct Tangent {
    splitting: Splitting,
    n: usize,
    /// The stage's (q, p), its velocity, the force at it and H there.
    q: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    force: Vec<f64>,
    hessian: DMatrix<f64>,
    /// A tangent vector's δp through M⁻¹, and the gradients a differenced H takes.
    velocity: Vec<f64>,
    plus: Vec<f64>,
    minus: Vec<f64>,
    /// Evaluations of ∇V and of H (exact or differenced) made.
    evaluations: u64,
}

impl Tangent {
    /// The tangent map of `method`'s step on n coordinates: the kick–drift methods have one
    /// here; the others are refused, naming the method.
    pub fn new(method: Method, n: usize) -> Result<Tangent, Error> {
        let Some(splitting) = Splitting::of(method) else {
            return Err(Error::invalid(
                "method",
                format!(
                    "{} has no tangent map here: the explicit kick–drift methods (verlet, yoshida4, \
                     blanes_moan4, aba864, …) have one",
                    method.info().name
                ),
            ));
        };
        let buffer = || vec![0.0; n];
        Ok(Tangent {
            splitting,
            n,
            q: buffer(),
            p: buffer(),
            v: buffer(),
            force: buffer(),
            hessian: DMatrix::zeros(n, n),
            velocity: buffer(),
            plus: buffer(),
            minus: buffer(),
            evaluations: 0,
        })
    }

    /// Force and Hessian evaluations made so far (a differenced H counts its 2n gradients).
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Applies DΨ_h of the step of size h from (q, p) to the tangent vectors in `x`, in place:
    /// column j of the 2n × k column-major `x` is (δq, δp). The stages are replayed from
    /// (q, p), so that each kick's H is taken where that kick acts.
    pub fn apply<S: MechanicalSystem + ?Sized>(
        &mut self,
        sys: &S,
        h: f64,
        (q, p): (&[f64], &[f64]),
        x: &mut [f64],
    ) -> Result<(), ModelError> {
        let (n, mass) = (self.n, sys.mass());
        self.q.copy_from_slice(q);
        self.p.copy_from_slice(p);
        let last = self.splitting.kicks().len() - 1;
        for i in 0..=last {
            let a = self.splitting.kicks()[i];
            if i > 0 {
                let b = self.splitting.drifts()[i - 1] * h;
                mass.velocity(&self.p, &mut self.v);
                self.q.iter_mut().zip(&self.v).for_each(|(q, v)| *q += b * v);
                for column in x.chunks_exact_mut(2 * n) {
                    let (dq, dp) = column.split_at_mut(n);
                    mass.velocity(dp, &mut self.velocity);
                    dq.iter_mut().zip(&self.velocity).for_each(|(d, v)| *d += b * v);
                }
            }
            if a == 0.0 {
                continue;
            }
            let a = a * h;
            self.hessian(sys)?;
            for column in x.chunks_exact_mut(2 * n) {
                let (dq, dp) = column.split_at_mut(n);
                // H is symmetric: its column r is its row r.
                for (r, d) in dp.iter_mut().enumerate() {
                    let row = self.hessian.column(r);
                    *d -= a * row.iter().zip(dq.iter()).map(|(h, x)| h * x).sum::<f64>();
                }
            }
            // The stage momenta, for the drifts after this kick; the last kick's are not needed.
            if i < last {
                self.evaluations += 1;
                sys.gradient(&self.q, &mut self.force)?;
                self.p.iter_mut().zip(&self.force).for_each(|(p, f)| *p -= a * f);
            }
        }
        Ok(())
    }

    /// H = ∂²V/∂q² at the stage's q: the model's own, or central differences of ∇V
    /// ([`central_jacobian`]), symmetrized.
    fn hessian<S: MechanicalSystem + ?Sized>(&mut self, sys: &S) -> Result<(), ModelError> {
        self.evaluations += 1;
        if let Some(exact) = sys.hessian(&self.q, self.hessian.as_mut_slice()) {
            return exact;
        }
        let at = Evaluations {
            plus: &mut self.plus,
            minus: &mut self.minus,
        };
        central_jacobian(|q, out| sys.gradient(q, out), &mut self.q, unit, at, &mut self.hessian)?;
        self.evaluations += 2 * self.n as u64 - 1;
        for i in 0..self.n {
            for j in 0..i {
                let mean = 0.5 * (self.hessian[(i, j)] + self.hessian[(j, i)]);
                self.hessian[(i, j)] = mean;
                self.hessian[(j, i)] = mean;
            }
        }
        Ok(())
    }
}
