//! A compiled general Lagrangian L(q, q̇, t).

use super::function::{check, check_parameters, Inputs};
use super::Function;
use crate::model::{differenced_dl_dt, Hessians, Lagrangian};
use crate::{Error, ModelError};

/// L(q, q̇, t; parameters) with its exact derivatives, each a [`Function`] of the slots
/// [q, q̇, t]: L; (∂L/∂q, ∂L/∂q̇) together; the Hessians (∂²L/∂q², ∂²L/∂q∂q̇, ∂²L/∂q̇²) row by
/// row; for a forced system, the generalized force Q(q, q̇, t); and, for an L that depends on t,
/// ∂L/∂t (differenced from L where a model stored before it was compiled lacks it).
#[derive(Clone, Debug)]
pub struct CompiledLagrangian {
    n: usize,
    params: Vec<f64>,
    lagrangian: Function,
    gradients: Function,
    hessians: Function,
    force: Option<Function>,
    dl_dt: Option<Function>,
    time_dependent: bool,
}

impl CompiledLagrangian {
    /// Refuses functions with the wrong number of outputs or parameters, naming the function.
    pub fn new(
        n: usize,
        params: Vec<f64>,
        lagrangian: Function,
        gradients: Function,
        hessians: Function,
        force: Option<Function>,
        (dl_dt, time_dependent): (Option<Function>, bool),
    ) -> Result<Self, Error> {
        check_parameters(&params, lagrangian.tape().params())?;
        check("lagrangian", &lagrangian, 1, n, Inputs::All, &params)?;
        check("gradients", &gradients, 2 * n, n, Inputs::All, &params)?;
        check("hessians", &hessians, 3 * n * n, n, Inputs::All, &params)?;
        if let Some(f) = &force {
            check("force", f, n, n, Inputs::All, &params)?;
        }
        if let Some(f) = &dl_dt {
            if !time_dependent {
                return Err(Error::invalid("dl_dt", "given for an L that does not depend on t"));
            }
            check("dl_dt", f, 1, n, Inputs::All, &params)?;
        }
        Ok(CompiledLagrangian {
            n,
            params,
            lagrangian,
            gradients,
            hessians,
            force,
            dl_dt,
            time_dependent,
        })
    }

    /// The same functions with another parameter vector (of the same length, finite).
    pub fn with_parameters(&self, params: &[f64]) -> Result<Self, Error> {
        check_parameters(params, self.params.len())?;
        Ok(CompiledLagrangian {
            params: params.to_vec(),
            ..self.clone()
        })
    }

    pub fn parameters(&self) -> &[f64] {
        &self.params
    }
}

impl Lagrangian for CompiledLagrangian {
    fn dim(&self) -> usize {
        self.n
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        let mut l = [0.0];
        self.lagrangian.eval(q, v, t, &self.params, &mut l);
        Ok(l[0])
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.gradients
            .eval_into(q, v, t, &self.params, |g| out.copy_from_slice(&g[..self.n]));
        Ok(())
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.gradients
            .eval_into(q, v, t, &self.params, |g| out.copy_from_slice(&g[self.n..]));
        Ok(())
    }

    fn gradients(&self, q: &[f64], v: &[f64], t: f64, dq: &mut [f64], dv: &mut [f64]) -> Result<(), ModelError> {
        self.gradients.eval_into(q, v, t, &self.params, |g| {
            dq.copy_from_slice(&g[..self.n]);
            dv.copy_from_slice(&g[self.n..]);
        });
        Ok(())
    }

    fn hessians(&self, q: &[f64], v: &[f64], t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        self.hessians.eval_into(q, v, t, &self.params, |h| out.set_rows(h));
        Ok(true)
    }

    fn is_time_dependent(&self) -> bool {
        self.time_dependent
    }

    fn dl_dt(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        let Some(f) = &self.dl_dt else {
            return differenced_dl_dt(self, q, v, t);
        };
        let mut out = [0.0];
        f.eval(q, v, t, &self.params, &mut out);
        Ok(out[0])
    }

    fn is_forced(&self) -> bool {
        self.force.is_some()
    }

    fn force(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        match &self.force {
            Some(f) => f.eval(q, v, t, &self.params, out),
            None => out.fill(0.0),
        }
        Ok(())
    }
}
