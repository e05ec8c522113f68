//! Compiled holonomic constraints g(q) = 0.

use nalgebra::DMatrix;

use super::function::{check, check_parameters, rows_into, Inputs};
use super::Function;
use crate::model::HolonomicConstraints;
use crate::{Error, ModelError};

/// g(q; parameters) (m entries) and its exact Jacobian G = ∂g/∂q (m × n, row-major) as
/// [`Function`]s of q.
#[derive(Clone, Debug)]
pub struct CompiledConstraints {
    m: usize,
    params: Vec<f64>,
    residual: Function,
    jacobian: Function,
}

with_parameters!(CompiledConstraints);

impl CompiledConstraints {
    /// Refuses functions of the wrong shape, naming them.
    pub fn new(m: usize, n: usize, params: Vec<f64>, residual: Function, jacobian: Function) -> Result<Self, Error> {
        check_parameters(&params, residual.tape().params())?;
        check("constraints", &residual, m, n, Inputs::Positions, &params)?;
        check("constraint_jacobian", &jacobian, m * n, n, Inputs::Positions, &params)?;
        Ok(CompiledConstraints {
            m,
            params,
            residual,
            jacobian,
        })
    }
}

impl HolonomicConstraints for CompiledConstraints {
    fn count(&self) -> usize {
        self.m
    }

    fn residual(&self, q: &[f64], g: &mut [f64]) -> Result<(), ModelError> {
        self.residual.eval(q, &[], 0.0, &self.params, g);
        Ok(())
    }

    fn jacobian(&self, q: &[f64], jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        self.jacobian
            .eval_into(q, &[], 0.0, &self.params, |values| rows_into(values, jac));
        Ok(())
    }
}
