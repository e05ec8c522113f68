use std::cell::RefCell;

use nalgebra::DMatrix;

use crate::solve::difference;
use crate::solve::scratch::with_scratch;
use crate::ModelError;

/// Velocity constraints A(q)q̇ + b(q) = 0 affine in the velocities, m rows on n coordinates,
/// that need not integrate to constraints on the positions (nonholonomic: rolling without
/// slipping, a skate's blade). The constraint forces are Aᵀλ, by the Lagrange–d'Alembert
/// principle. Mostly b = 0 (linear constraints, the default); an affine term b(q), the
/// inhomogeneous part of *affine nonholonomic constraints* (Bloch, *Nonholonomic Mechanics and
/// Control*, §5.2), is the velocity of a moving surface at the contact, e.g. a turntable's
/// Ω ẑ × r. With b ≠ 0 the constraint forces do work, λ·b, and the energy is not conserved.
pub trait VelocityConstraints {
    /// Number of constraints m.
    fn count(&self) -> usize;

    /// Writes A(q) (m × n) into `a`.
    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError>;

    /// Writes ∂A/∂qᵢ (m × n) into `out`: with it Newton's method assembles the exact Jacobian of
    /// the discrete Lagrange–d'Alembert equations. Default: [`differenced_derivative`].
    fn derivative(&self, q: &[f64], i: usize, out: &mut DMatrix<f64>) -> Result<(), ModelError> {
        differenced_derivative(self, q, i, out)
    }

    /// Whether the constraints have an affine term b(q) ≠ 0 ([`Self::offset`]).
    fn is_affine(&self) -> bool {
        false
    }

    /// Writes the affine term b(q) (m entries) into `b`. Default: 0, linear constraints.
    fn offset(&self, _q: &[f64], b: &mut [f64]) -> Result<(), ModelError> {
        b.fill(0.0);
        Ok(())
    }

    /// Writes ∂b/∂qᵢ (m entries) into `out`, for Newton's exact Jacobian. Default: 0 for
    /// linear constraints, a central difference of b (as [`differenced_derivative`]) for affine
    /// ones.
    fn offset_derivative(&self, q: &[f64], i: usize, out: &mut [f64]) -> Result<(), ModelError> {
        if !self.is_affine() {
            out.fill(0.0);
            return Ok(());
        }
        let h = difference::step(q[i].abs().max(1.0));
        shifted(q, |x, _, minus| {
            minus.resize(out.len(), 0.0);
            x[i] = q[i] + h;
            self.offset(x, out)?;
            x[i] = q[i] - h;
            self.offset(x, minus)?;
            out.iter_mut()
                .zip(minus.iter())
                .for_each(|(o, m)| *o = (*o - m) / (2.0 * h));
            Ok(())
        })
    }
}

/// ∂A/∂qᵢ by a central difference of A, with the step ε^{1/3}·max(|qᵢ|, 1) (two evaluations of
/// A), about 1e-10 relative accuracy.
pub fn differenced_derivative<C: VelocityConstraints + ?Sized>(
    constraints: &C,
    q: &[f64],
    i: usize,
    out: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let h = difference::step(q[i].abs().max(1.0));
    shifted(q, |x, minus, _| {
        if minus.shape() != out.shape() {
            *minus = DMatrix::zeros(out.nrows(), out.ncols());
        }
        x[i] = q[i] + h;
        constraints.matrix(x, out)?;
        x[i] = q[i] - h;
        constraints.matrix(x, minus)?;
        *out -= &*minus;
        *out /= 2.0 * h;
        Ok(())
    })
}

/// The differences' workspace: the shifted point and the values of A and b at q − hεᵢ.
#[derive(Default)]
struct Scratch {
    point: Vec<f64>,
    matrix: DMatrix<f64>,
    offset: Vec<f64>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

/// Runs `body` with a copy of q to shift and the buffers for A and b there, from this
/// thread's workspace ([`with_scratch`]).
fn shifted<R>(q: &[f64], body: impl FnOnce(&mut [f64], &mut DMatrix<f64>, &mut Vec<f64>) -> R) -> R {
    with_scratch(&SCRATCH, Scratch::default, |scratch| {
        let Scratch { point, matrix, offset } = scratch;
        point.clear();
        point.extend_from_slice(q);
        body(point, matrix, offset)
    })
}

/// A Lagrangian system S with velocity constraints C: what the discrete Lagrange–d'Alembert
/// integrator ([`crate::integrators::Del`] with the midpoint rule) integrates. S is any
/// [`super::Lagrangian`]: a separable or natural mechanical system, or a general L(q, q̇, t).
#[derive(Clone, Debug)]
pub struct Nonholonomic<S, C> {
    pub system: S,
    pub constraints: C,
}
