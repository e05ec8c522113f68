//! A compiled general Lagrangian L(q, q̇, t).

use super::function::{check, check_parameters, Inputs};
use super::Function;
use crate::model::{delayed_block, differenced_dl_dt, inverse_legendre, Hessians, Lagrangian};
use crate::solve::{copy, fill};
use crate::{Error, ModelError};

/// L(q, q̇, t; parameters) with its exact derivatives, each a [`Function`] of the slots
/// [q, q̇, t]: L; (∂L/∂q, ∂L/∂q̇) together; the Hessians (∂²L/∂q², ∂²L/∂q∂q̇, ∂²L/∂q̇²) row by
/// row; for a forced system, the generalized force Q(q, q̇, t); and, for an L that depends on t,
/// ∂L/∂t (differenced from L where a model stored before it was compiled lacks it); for a
/// model of variable mass, its masses m(q, t), which must stay positive and finite; for delayed
/// forces, their delays and one function of their slots ([`crate::model::delayed_block`])
/// whose outputs are Q, then a block of n a delay (with whether each reads the acceleration
/// τ ago, and whether they read the past alone, not the state now), with the history before
/// the run where given: (q(s), q̇(s), q̈(s)), a function of the one slot \[s\].
#[derive(Clone, Debug)]
pub struct CompiledLagrangian {
    n: usize,
    params: Vec<f64>,
    lagrangian: Function,
    gradients: Function,
    /// (∂L/∂q, ∂L/∂q̇) without ∂L/∂t, `gradients` itself where it has none: a step's Newton
    /// iterations need ∂L/∂t only at their last evaluation.
    gradients_alone: Function,
    hessians: Function,
    /// Q, none where it is zero (a model forced by its delayed terms alone): not evaluated.
    force: Option<Function>,
    forced: bool,
    dl_dt: Option<Function>,
    time_dependent: bool,
    masses: Option<Function>,
    delayed: Option<(Function, Vec<f64>)>,
    delayed_accelerations: Vec<bool>,
    delayed_of_past_alone: bool,
    history: Option<Function>,
}

with_parameters!(CompiledLagrangian);

impl CompiledLagrangian {
    /// Refuses functions with the wrong number of outputs or parameters, naming the function,
    /// masses without a force (the reactive force of a changing mass is one), and delays that
    /// are not positive and finite.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        n: usize,
        params: Vec<f64>,
        lagrangian: Function,
        gradients: Function,
        hessians: Function,
        force: Option<Function>,
        (dl_dt, time_dependent): (Option<Function>, bool),
        masses: Option<Function>,
        (delayed, history): (Option<(Function, Vec<f64>)>, Option<Function>),
    ) -> Result<Self, Error> {
        check_parameters(&params, lagrangian.tape().params())?;
        check("lagrangian", &lagrangian, 1, n, Inputs::All, &params)?;
        // With ∂L/∂t as a last output for an L of t (a model stored before has 2n).
        let with_time = time_dependent && gradients.outputs() == 2 * n + 1;
        check(
            "gradients",
            &gradients,
            2 * n + usize::from(with_time),
            n,
            Inputs::All,
            &params,
        )?;
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
        if let Some(m) = &masses {
            if force.is_none() {
                return Err(Error::invalid("masses", "given without a force (the reactive force)"));
            }
            check("masses", m, m.outputs().max(1), n, Inputs::All, &params)?;
        }
        if let Some((f, delays)) = &delayed {
            if delays.is_empty() || !delays.iter().all(|tau| tau.is_finite() && *tau > 0.0) {
                return Err(Error::invalid(
                    "delays",
                    format!("must be positive and finite, got {delays:?}"),
                ));
            }
            let d = delays.len();
            check("delayed_force", f, n * (1 + d), n * (1 + d), Inputs::Delayed, &params)?;
        }
        if let Some(f) = &history {
            if delayed.is_none() {
                return Err(Error::invalid(
                    "history",
                    "given without delayed forces, which alone read it",
                ));
            }
            check("history", f, 3 * n, 0, Inputs::All, &params)?;
        }
        // What the delayed terms (outputs n..m) read, in blocks of m = n(1 + d) slots.
        let (delayed_of_past_alone, delayed_accelerations) = match &delayed {
            Some((f, delays)) => {
                let m = n * (1 + delays.len());
                let terms_read = |slot: &dyn Fn(usize) -> bool| f.tape().reads(n..m, slot);
                (
                    // The slots of q and q̇ now: the first n of the first two blocks.
                    !terms_read(&|s| s < n || (m..m + n).contains(&s)),
                    // q̈(t − τⱼ): the j + 1st n slots of the third block.
                    (0..delays.len())
                        .map(|j| terms_read(&|s| (2 * m + (j + 1) * n..2 * m + (j + 2) * n).contains(&s)))
                        .collect(),
                )
            }
            None => (false, Vec::new()),
        };
        let forced = force.is_some() || delayed.is_some();
        Ok(CompiledLagrangian {
            n,
            params,
            lagrangian,
            gradients_alone: if with_time {
                gradients.restricted(0..2 * n)
            } else {
                gradients.clone()
            },
            gradients,
            hessians,
            force: force.filter(|f| !f.tape().is_zero()),
            forced,
            dl_dt,
            time_dependent,
            masses,
            delayed,
            delayed_accelerations,
            delayed_of_past_alone,
            history,
        })
    }

    pub fn parameters(&self) -> &[f64] {
        &self.params
    }

    /// Refuses a state where a variable mass is not positive and finite (masses depend on q
    /// and t alone).
    fn check_masses(&self, q: &[f64], v: &[f64], t: f64) -> Result<(), ModelError> {
        let Some(m) = &self.masses else { return Ok(()) };
        let lost = m.eval_into(q, v, t, &self.params, |m| {
            m.iter().position(|m| *m <= 0.0 || !m.is_finite()).map(|i| (i, m[i]))
        });
        match lost {
            Some((i, m)) => Err(format!(
                "mass_flow[{i}]: the mass is {m} at t = {t}: it must stay positive and finite (the body \
                 has run out of mass; end the run before)"
            )
            .into()),
            None => Ok(()),
        }
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
        self.gradients_alone
            .eval_into(q, v, t, &self.params, |g| copy(out, &g[..self.n]));
        Ok(())
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.gradients_alone
            .eval_into(q, v, t, &self.params, |g| copy(out, &g[self.n..2 * self.n]));
        Ok(())
    }

    fn gradients(&self, q: &[f64], v: &[f64], t: f64, dq: &mut [f64], dv: &mut [f64]) -> Result<(), ModelError> {
        let n = self.n;
        self.gradients_alone.eval_into(q, v, t, &self.params, |g| {
            copy(dq, &g[..n]);
            copy(dv, &g[n..2 * n]);
        });
        Ok(())
    }

    fn gradients_and_dl_dt(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<Option<f64>, ModelError> {
        let n = self.n;
        Ok(self.gradients.eval_into(q, v, t, &self.params, |g| {
            copy(dq, &g[..n]);
            copy(dv, &g[n..2 * n]);
            g.get(2 * n).copied()
        }))
    }

    fn hessians(&self, q: &[f64], v: &[f64], t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        self.hessians.eval_into(q, v, t, &self.params, |h| out.set_rows(h));
        Ok(true)
    }

    fn is_time_dependent(&self) -> bool {
        self.time_dependent
    }

    // A state whose mass has run out has no velocity: said so, before Newton finds ∂²L/∂q̇² singular.
    fn velocity(&self, q: &[f64], p: &[f64], t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        self.check_masses(q, v, t)?;
        inverse_legendre(self, q, p, t, v)
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
        self.forced
    }

    fn delays(&self) -> &[f64] {
        self.delayed.as_ref().map_or(&[], |(_, d)| d)
    }

    fn delayed_of_past_alone(&self) -> bool {
        self.delayed_of_past_alone
    }

    fn history(&self, s: f64, q: &mut [f64], v: &mut [f64], a: &mut [f64]) -> Result<bool, ModelError> {
        let Some(f) = &self.history else {
            return Ok(false);
        };
        f.eval_into(&[], &[], s, &self.params, |state| {
            let n = self.n;
            copy(q, &state[..n]);
            copy(v, &state[n..2 * n]);
            copy(a, &state[2 * n..]);
        });
        Ok(true)
    }

    fn delayed_reads_acceleration(&self, j: usize) -> bool {
        self.delayed_accelerations[j]
    }

    fn delayed_force(&self, state: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let m = delayed_block(state.len());
        let (q, v, t) = (&state[..self.n], &state[m..m + self.n], state[3 * m]);
        let Some((f, _)) = &self.delayed else {
            return self.force(q, v, t, out);
        };
        self.check_masses(q, v, t)?;
        f.eval_slots(state, &self.params, out);
        Ok(())
    }

    fn force(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.check_masses(q, v, t)?;
        match &self.force {
            Some(f) => f.eval(q, v, t, &self.params, out),
            None => fill(out, 0.0),
        }
        Ok(())
    }
}
