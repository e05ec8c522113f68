//! Compiled velocity constraints A(q)q̇ = 0.

use nalgebra::DMatrix;

use super::function::{check, check_parameters, rows_into, Inputs};
use super::Function;
use crate::model::VelocityConstraints;
use crate::{Error, ModelError};

/// A(q; parameters) (m × n, row-major) and its exact derivatives ∂A/∂qᵢ (n blocks of m × n,
/// block i row-major) as [`Function`]s of q: what the discrete Lagrange–d'Alembert step's
/// Newton Jacobian needs, with no differences.
#[derive(Clone, Debug)]
pub struct CompiledVelocityConstraints {
    m: usize,
    params: Vec<f64>,
    matrix: Function,
    derivative: Function,
}

with_parameters!(CompiledVelocityConstraints);

impl CompiledVelocityConstraints {
    /// Refuses functions of the wrong shape, naming them.
    pub fn new(m: usize, n: usize, params: Vec<f64>, matrix: Function, derivative: Function) -> Result<Self, Error> {
        check_parameters(&params, matrix.tape().params())?;
        check("velocity_constraints", &matrix, m * n, n, Inputs::Positions, &params)?;
        check(
            "velocity_constraint_derivative",
            &derivative,
            n * m * n,
            n,
            Inputs::Positions,
            &params,
        )?;
        Ok(CompiledVelocityConstraints {
            m,
            params,
            matrix,
            derivative,
        })
    }
}

impl VelocityConstraints for CompiledVelocityConstraints {
    fn count(&self) -> usize {
        self.m
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        self.matrix
            .eval_into(q, &[], 0.0, &self.params, |values| rows_into(values, a));
        Ok(())
    }

    /// Block i of the derivative tape (the whole tape runs: its n blocks share their terms).
    fn derivative(&self, q: &[f64], i: usize, out: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let block = self.m * q.len();
        self.derivative.eval_into(q, &[], 0.0, &self.params, |values| {
            rows_into(&values[i * block..(i + 1) * block], out)
        });
        Ok(())
    }
}
