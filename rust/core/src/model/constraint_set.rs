//! A model's constraints as one record: holonomic rows g(q) = 0 and velocity rows
//! A(q)q̇ + b(q) = 0, either, both or none; what a model kind has, as data.

use nalgebra::{DMatrix, DVector};

use super::{HolonomicConstraints, VelocityConstraints};
use crate::ModelError;

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
}
