//! A model's constraints as one record: holonomic rows g(q) = 0 and velocity rows
//! A(q)q̇ + b(q) = 0, either, both or none; what a model kind has, as data.

use nalgebra::{DMatrix, DVector};

use super::constraints::{momentum_projection, row_norm};
use super::{project, Action, HolonomicConstraints, PhaseState, Residuals, VelocityConstraints};
use crate::{Error, ModelError};

/// The constraints of a model ([`crate::integrators::Dynamics::constraints`]): its holonomic
/// g(q) = 0 and its velocity constraints A(q)q̇ + b(q) = 0, if any. The rows of their forces
/// are [G(q); A(q)], with [0; b(q)] (G's rows first).
#[derive(Clone, Copy, Default)]
pub struct ConstraintSet<'a> {
    pub holonomic: Option<&'a dyn HolonomicConstraints>,
    pub velocity: Option<&'a dyn VelocityConstraints>,
}

impl ConstraintSet<'_> {
    /// The number of constraints m and how many of them are holonomic.
    pub fn counts(&self) -> (usize, usize) {
        let k = self.holonomic.map_or(0, |h| h.count());
        (k + self.velocity.map_or(0, |v| v.count()), k)
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.holonomic.is_none() && self.velocity.is_none()
    }

    /// Whether the velocity constraints have an affine term b(q) ≠ 0, whose forces do work.
    pub fn is_affine(&self) -> bool {
        self.velocity.is_some_and(|v| v.is_affine())
    }

    /// [G(q); A(q)] and [0; b(q)], allocated (diagnostics and set-up).
    pub fn stacked(&self, q: &[f64]) -> Result<(DMatrix<f64>, DVector<f64>), ModelError> {
        let ((m, k), n) = (self.counts(), q.len());
        let mut stacked = DMatrix::zeros(m, n);
        let mut b = DVector::zeros(m);
        if let Some(h) = self.holonomic {
            let mut g = DMatrix::zeros(k, n);
            h.jacobian(q, &mut g)?;
            stacked.rows_mut(0, k).copy_from(&g);
        }
        if let Some(v) = self.velocity {
            let mut a = DMatrix::zeros(m - k, n);
            v.matrix(q, &mut a)?;
            v.offset(q, &mut b.as_mut_slice()[k..])?;
            stacked.rows_mut(k, m - k).copy_from(&a);
        }
        Ok((stacked, b))
    }

    /// [G(q); A(q)] into `c` and [0; b(q)] into `b`: the rows of the forces of constraint
    /// ([`super::Reaction::solve`]); one set's rows written in place, both sets' stacked.
    pub fn rows(&self, q: &[f64], c: &mut DMatrix<f64>, b: &mut [f64]) -> Result<(), ModelError> {
        match (self.holonomic, self.velocity) {
            (Some(h), None) => {
                b.fill(0.0);
                h.jacobian(q, c)
            }
            (None, Some(v)) => {
                v.matrix(q, c)?;
                v.offset(q, b)
            }
            _ => {
                let (stacked, offset) = self.stacked(q)?;
                c.copy_from(&stacked);
                b.copy_from_slice(offset.as_slice());
                Ok(())
            }
        }
    }

    /// |g(q)|∞ against ‖G(q)‖∞‖q‖∞, and |[G; A]q̇ + [0; b]|∞ with q̇ = `velocity`(q, p) against
    /// ‖[G; A]‖∞‖q̇‖∞ + |b(q)|∞: the position and the velocity residuals of both sets at once
    /// (of the holonomic ones alone, |Gq̇|∞ is the hidden constraint's).
    pub fn residuals(&self, velocity: Action<'_>, q: &[f64], p: &[f64]) -> Result<Residuals, ModelError> {
        let k = self.counts().1;
        let mut g = vec![0.0; k];
        if let Some(h) = self.holonomic {
            h.residual(q, &mut g)?;
        }
        let (stacked, b) = self.stacked(q)?;
        let mut v = vec![0.0; q.len()];
        velocity(q, p, &mut v)?;
        let v = DVector::from_column_slice(&v);
        let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
        Ok(Residuals {
            position: amax(&g),
            velocity: (&stacked * &v + &b).amax(),
            position_size: row_norm(&stacked.rows(0, k).into_owned()) * amax(q),
            velocity_size: row_norm(&stacked) * v.amax() + b.amax(),
        })
    }

    /// The nearest consistent state: q onto g = 0 as [`project`] puts it (which projects the
    /// momenta onto Gq̇ = 0 too), then, with velocity constraints, p ← p − [G; A]ᵀν with
    /// ([G; A]M⁻¹[G; A]ᵀ)ν = [G; A]q̇(q, p) + [0; b(q)], the M-orthogonal projection onto both.
    /// `minv` applies M(q)⁻¹, `velocity` is the inverse Legendre transform (M⁻¹x = q̇(q, x) −
    /// q̇(q, 0), exact for L quadratic in q̇).
    pub fn project(&self, minv: Action<'_>, velocity: Action<'_>, q0: &[f64], p0: &[f64]) -> Result<PhaseState, Error> {
        let q = match (self.holonomic, self.velocity) {
            (None, None) => return Ok((q0.to_vec(), p0.to_vec())),
            (Some(h), None) => return project(h, minv, velocity, q0, p0),
            (Some(h), Some(_)) => project(h, minv, velocity, q0, p0)?.0,
            (None, Some(_)) => q0.to_vec(),
        };
        let which = if self.holonomic.is_some() {
            "constraints"
        } else {
            "velocity constraints"
        };
        let model = |e: ModelError| Error::invalid("q0", format!("the {which} failed to evaluate: {e}"));
        let (stacked, b) = self.stacked(&q).map_err(model)?;
        let p = momentum_projection(&stacked, &b, minv, velocity, &q, p0)?;
        Ok((q, p))
    }
}
