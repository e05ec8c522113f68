use std::cell::RefCell;

use nalgebra::{DMatrix, DVector};

use super::Lagrangian;
use crate::solve::difference::central_gradient;
use crate::ModelError;

/// A natural mechanical system, L = ½q̇ᵀM(q)q̇ − V(q): kinetic energy a positive-definite
/// quadratic form in q̇ whose matrix depends on the configuration (a double pendulum, a body in
/// angles). [`Natural`] turns it into a [`Lagrangian`] with exact ∂L/∂q̇ = M(q)q̇ and an exact
/// inverse Legendre transform q̇ = M(q)⁻¹p.
pub trait NaturalSystem {
    /// Number of generalized coordinates n.
    fn dim(&self) -> usize;

    /// Writes the mass matrix M(q), symmetric positive definite, into `m` (n × n).
    fn mass_matrix(&self, q: &[f64], m: &mut DMatrix<f64>) -> Result<(), ModelError>;

    /// The potential V(q).
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError>;

    /// Writes ∇V(q) into `grad`.
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError>;

    /// Writes ∂T/∂q, with (∂T/∂q)ᵢ = ½q̇ᵀ(∂M/∂qᵢ)q̇, into `out`. Default:
    /// [`differenced_kinetic_gradient`].
    fn kinetic_gradient(&self, q: &[f64], v: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        differenced_kinetic_gradient(self, q, v, out)
    }
}

/// ∂T/∂q by central differences of T(q) = ½q̇ᵀM(q)q̇: 2n evaluations of M (they allocate
/// scratch), about 1e-10 relative accuracy.
pub fn differenced_kinetic_gradient<S: NaturalSystem + ?Sized>(
    sys: &S,
    q: &[f64],
    v: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let n = q.len();
    let mut m = DMatrix::zeros(n, n);
    let v = DVector::from_column_slice(v);
    let mut work = vec![0.0; n];
    central_gradient(
        |x| {
            sys.mass_matrix(x, &mut m)?;
            Ok(0.5 * v.dot(&(&m * &v)))
        },
        q,
        &mut work,
        out,
    )
}

/// ∂T/∂q from the derivatives of the mass matrix: (∂T/∂q)ᵢ = ½q̇ᵀ(∂M/∂qᵢ)q̇, with
/// `mass_derivative` holding ∂M/∂qᵢ for i = 0..n, each n × n, stacked in C order (i first).
pub fn kinetic_gradient_from_mass_derivative(mass_derivative: &[f64], v: &[f64], out: &mut [f64]) {
    let n = v.len();
    for (o, d) in out.iter_mut().zip(mass_derivative.chunks_exact(n * n)) {
        *o = 0.5
            * d.chunks_exact(n)
                .zip(v)
                .map(|(row, vj)| vj * row.iter().zip(v).map(|(a, vk)| a * vk).sum::<f64>())
                .sum::<f64>();
    }
}

/// The [`Lagrangian`] of a [`NaturalSystem`], with scratch for M(q). The scratch sits in
/// `RefCell`s, so a `Natural` serves one thread (the Python closures' adapter is one).
#[derive(Debug)]
pub struct Natural<S> {
    system: S,
    mass: RefCell<DMatrix<f64>>,
    work: RefCell<Vec<f64>>,
}

impl<S: NaturalSystem> Natural<S> {
    pub fn new(system: S) -> Self {
        let n = system.dim();
        Natural {
            system,
            mass: RefCell::new(DMatrix::zeros(n, n)),
            work: RefCell::new(vec![0.0; n]),
        }
    }

    pub fn system(&self) -> &S {
        &self.system
    }
}

impl<S: NaturalSystem> Lagrangian for Natural<S> {
    fn dim(&self) -> usize {
        self.system.dim()
    }

    /// L = ½q̇ᵀM(q)q̇ − V(q).
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        let p = &mut *self.work.borrow_mut();
        self.dl_dv(q, v, t, p)?;
        Ok(0.5 * p.iter().zip(v).map(|(p, v)| p * v).sum::<f64>() - self.system.potential(q)?)
    }

    /// ∂L/∂q = ∂T/∂q − ∇V.
    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.system.kinetic_gradient(q, v, out)?;
        let grad = &mut *self.work.borrow_mut();
        self.system.gradient(q, grad)?;
        out.iter_mut().zip(grad.iter()).for_each(|(o, g)| *o -= g);
        Ok(())
    }

    /// p = ∂L/∂q̇ = M(q)q̇.
    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let m = &mut *self.mass.borrow_mut();
        self.system.mass_matrix(q, m)?;
        for (i, o) in out.iter_mut().enumerate() {
            *o = m.row(i).iter().zip(v).map(|(a, b)| a * b).sum();
        }
        Ok(())
    }

    /// q̇ = M(q)⁻¹p by Cholesky factorisation (it allocates; the integrators call it only for
    /// diagnostics and once a run).
    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let m = &mut *self.mass.borrow_mut();
        self.system.mass_matrix(q, m)?;
        let cholesky = m.clone().cholesky().ok_or_else(|| {
            ModelError::from(format!(
                "the mass matrix M(q) is not symmetric positive definite at q = {q:?}"
            ))
        })?;
        v.copy_from_slice(cholesky.solve(&DVector::from_column_slice(p)).as_slice());
        Ok(())
    }
}
