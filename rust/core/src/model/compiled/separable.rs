//! A compiled separable mechanical system, L = ½q̇ᵀMq̇ − V(q) with constant M.

use super::function::{check, check_parameters, Inputs};
use super::Function;
use crate::model::{Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// V(q; parameters) and ∇V as [`Function`]s of q, and the constant mass matrix M evaluated
/// from the parameters: a [`MechanicalSystem`], for every unconstrained method.
#[derive(Clone, Debug)]
pub struct CompiledSeparable {
    n: usize,
    params: Vec<f64>,
    potential: Function,
    gradient: Function,
    /// M(parameters): 1 output for M = m·I, n for a diagonal M, n² (row-major) for a full one.
    mass_function: Function,
    mass: Mass,
}

impl CompiledSeparable {
    /// Refuses functions of the wrong shape (naming them), and a mass matrix that is not
    /// symmetric positive definite at these parameters.
    pub fn new(
        n: usize,
        params: Vec<f64>,
        potential: Function,
        gradient: Function,
        mass: Function,
    ) -> Result<Self, Error> {
        check_parameters(&params, potential.tape().params())?;
        check("potential", &potential, 1, n, Inputs::Positions, &params)?;
        check("gradient", &gradient, n, n, Inputs::Positions, &params)?;
        let entries = mass.outputs();
        if ![1, n, n * n].contains(&entries) {
            return Err(Error::invalid(
                "mass",
                format!("has {entries} outputs where 1 (m·I), n = {n} (diagonal) or n² (full) are needed"),
            ));
        }
        check("mass", &mass, entries, n, Inputs::Positions, &params)?;
        if mass.tape().slots_read() > 0 {
            return Err(Error::invalid(
                "mass",
                "must be constant (a separable system's M cannot depend on q)",
            ));
        }
        let m = Self::evaluate_mass(&mass, n, &params)?;
        Ok(CompiledSeparable {
            n,
            params,
            potential,
            gradient,
            mass_function: mass,
            mass: m,
        })
    }

    fn evaluate_mass(f: &Function, n: usize, params: &[f64]) -> Result<Mass, Error> {
        let mut values = vec![0.0; f.outputs()];
        f.eval(&vec![0.0; n], &[], 0.0, params, &mut values);
        match values.len() {
            1 => Mass::scalar(values[0]),
            k if k == n => Mass::diagonal(values),
            _ => Mass::full(nalgebra::DMatrix::from_row_slice(n, n, &values)),
        }
    }

    /// The same functions with another parameter vector (of the same length, finite).
    pub fn with_parameters(&self, params: &[f64]) -> Result<Self, Error> {
        check_parameters(params, self.params.len())?;
        Ok(CompiledSeparable {
            params: params.to_vec(),
            mass: Self::evaluate_mass(&self.mass_function, self.n, params)?,
            ..self.clone()
        })
    }

    pub fn parameters(&self) -> &[f64] {
        &self.params
    }
}

impl MechanicalSystem for CompiledSeparable {
    fn dim(&self) -> usize {
        self.n
    }

    fn mass(&self) -> &Mass {
        &self.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        let mut v = [0.0];
        self.potential.eval(q, &[], 0.0, &self.params, &mut v);
        Ok(v[0])
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        self.gradient.eval(q, &[], 0.0, &self.params, grad);
        Ok(())
    }
}
