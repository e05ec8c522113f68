use std::cell::RefCell;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::{EnergyTerms, MechanicalSystem};
use crate::error::StepError;
use crate::solve::difference::{self, central_gradient, central_jacobian, Evaluations};
use crate::solve::newton::{
    degenerate, model_error, norm, Correction, Newton, NewtonOptions, NewtonProblem, Reasons, Rules,
};
use crate::solve::scratch::with_scratch;
use crate::ModelError;

/// The length m = n(1 + d) of each block of the delayed forces' `slots` ([`Lagrangian::delayed_force`]):
/// [q, q(t − τ₁) …], [q̇, q̇(t − τ₁) …], [q̈, q̈(t − τ₁) …], then t, 3m + 1 in all. q̈ now is
/// what the step solves for, not known where it evaluates its force: its n slots are never read.
pub fn delayed_block(slots: usize) -> usize {
    slots / 3
}

/// The number of the delayed forces' slots for n coordinates and d delays: 3n(1 + d) + 1.
pub fn delayed_slots(n: usize, d: usize) -> usize {
    3 * n * (1 + d) + 1
}

/// The second derivatives of L at one point, n × n each.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Hessians {
    /// ∂²L/∂q².
    pub qq: DMatrix<f64>,
    /// ∂²L/∂q∂q̇: entry (i, j) is ∂²L/∂qᵢ∂q̇ⱼ.
    pub qv: DMatrix<f64>,
    /// ∂²L/∂q̇².
    pub vv: DMatrix<f64>,
}

impl Hessians {
    pub fn zeros(n: usize) -> Self {
        Hessians {
            qq: DMatrix::zeros(n, n),
            qv: DMatrix::zeros(n, n),
            vv: DMatrix::zeros(n, n),
        }
    }

    /// Sets ∂²L/∂q², ∂²L/∂q∂q̇ and ∂²L/∂q̇² from 3n² values, each matrix row-major in turn:
    /// the layout of compiled models and function pointers.
    pub fn set_rows(&mut self, values: &[f64]) {
        let n2 = self.qq.len();
        for (m, block) in [&mut self.qq, &mut self.qv, &mut self.vv]
            .into_iter()
            .zip(values.chunks_exact(n2))
        {
            m.copy_from_slice(block);
            // Row-major values into column-major storage.
            m.transpose_mut();
        }
    }
}

/// A Lagrangian system L(q, q̇, t) with n generalized coordinates.
///
/// The discrete layer builds discrete Lagrangians L_d ≈ ∫ L dt from it and their Legendre
/// transforms from ∂L/∂q and ∂L/∂q̇. Separable mechanical systems ([`MechanicalSystem`])
/// implement it exactly; general Lagrangians (configuration-dependent mass, velocity-linear
/// terms, explicit time dependence) implement [`Lagrangian::lagrangian`] and, where they can,
/// the derivatives exactly: the defaults are central differences.
pub trait Lagrangian {
    /// Number of generalized coordinates n.
    fn dim(&self) -> usize;

    /// L(q, q̇, t).
    fn lagrangian(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError>;

    /// Writes ∂L/∂q at (q, q̇, t) into `out`. Default: central differences of L (they allocate
    /// a scratch vector; models used in long runs should supply it).
    fn dl_dq(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let mut work = vec![0.0; q.len()];
        central_gradient(|x| self.lagrangian(x, v, t), q, &mut work, out)
    }

    /// Writes the momentum p = ∂L/∂q̇ at (q, q̇, t) into `out`. Default: central differences.
    fn dl_dv(&self, q: &[f64], v: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let mut work = vec![0.0; v.len()];
        central_gradient(|x| self.lagrangian(q, x, t), v, &mut work, out)
    }

    /// Writes ∂L/∂q into `dq` and ∂L/∂q̇ into `dv`, both at (q, q̇, t): the discrete
    /// Lagrangians need them together. Default: [`Lagrangian::dl_dq`] and
    /// [`Lagrangian::dl_dv`] in turn; a model that computes them in one pass overrides it.
    fn gradients(&self, q: &[f64], v: &[f64], t: f64, dq: &mut [f64], dv: &mut [f64]) -> Result<(), ModelError> {
        self.dl_dq(q, v, t, dq)?;
        self.dl_dv(q, v, t, dv)
    }

    /// [`Lagrangian::gradients`], with ∂L/∂t where the model takes it from the same evaluation
    /// (a compiled L of t: one tape, its common subexpressions shared), so that the discrete
    /// rules keep it from Newton's last evaluation for the energy balance
    /// (`crate::discrete::Quadrature::time_derivative`) instead of evaluating
    /// [`Lagrangian::dl_dt`] again; None (the default) where it does not.
    fn gradients_and_dl_dt(
        &self,
        q: &[f64],
        v: &[f64],
        t: f64,
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<Option<f64>, ModelError> {
        self.gradients(q, v, t, dq, dv).map(|()| None)
    }

    /// Writes the exact second derivatives of L at (q, q̇, t) into `out` and returns true, or
    /// returns false (the default) when the model does not supply them; the implicit
    /// integrators then difference their equations for Newton's Jacobian.
    fn hessians(&self, _q: &[f64], _v: &[f64], _t: f64, _out: &mut Hessians) -> Result<bool, ModelError> {
        Ok(false)
    }

    /// Whether L depends on t explicitly; if it does, the energy function E = p·q̇ − L is not
    /// conserved and no report may claim it is: it changes by −∫∂L/∂t dt (with the forces'
    /// work), which the run tracks ([`Lagrangian::dl_dt`]).
    fn is_time_dependent(&self) -> bool {
        false
    }

    /// ∂L/∂t at (q, q̇, t). Default: 0 where L does not depend on t, else
    /// [`differenced_dl_dt`].
    fn dl_dt(&self, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
        differenced_dl_dt(self, q, v, t)
    }

    /// Whether non-conservative generalized forces act (then the energy is not conserved, and
    /// the integrators follow the discrete Lagrange–d'Alembert principle).
    fn is_forced(&self) -> bool {
        false
    }

    /// Writes the generalized force f(q, q̇, t) (friction, Rayleigh dissipation f = −∂R/∂q̇,
    /// driving) into `out`. Default: none.
    fn force(&self, _q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out.fill(0.0);
        Ok(())
    }

    /// The delays τ₁ … τ_d of the model's delayed forces (each τⱼ > 0); none by default. A
    /// model with delays is forced ([`Lagrangian::is_forced`]).
    fn delays(&self) -> &[f64] {
        &[]
    }

    /// Writes the state before the run, q(s), q̇(s) and q̈(s) at s, into `q`, `v` and `a` where
    /// the model gives its history (the initial function of its delayed forces) and returns
    /// true; false where it gives none (then a delayed term acts only once its past exists).
    /// Default: none.
    fn history(&self, _s: f64, _q: &mut [f64], _v: &mut [f64], _a: &mut [f64]) -> Result<bool, ModelError> {
        Ok(false)
    }

    /// Whether the delayed term of τⱼ reads the acceleration q̈(t − τⱼ): then the run's history
    /// gives it (from the velocities on either side of t − τⱼ). Default: none does.
    fn delayed_reads_acceleration(&self, _j: usize) -> bool {
        false
    }

    /// Whether the delayed terms of [`Lagrangian::delayed_force`] read the past alone (and t),
    /// not the state now: then a step, whose force node keeps its t, evaluates them once and
    /// Q alone ([`Lagrangian::force`], the same values as the first block) at each Newton
    /// iteration. Default: false, every evaluation takes them all.
    fn delayed_of_past_alone(&self) -> bool {
        false
    }

    /// Writes the forces of a model with delays into `out`, n(1 + d): first the force now,
    /// Q(q, q̇, t), then for each delay j the term of the state now and of the state τⱼ ago, each
    /// its own block so that a term whose past does not exist yet is left out (one evaluation
    /// for all, the step's hot path). `state` holds a compiled function's own slots, passed as
    /// they are ([`delayed_block`]). Default: Q from [`Lagrangian::force`], no delayed term.
    fn delayed_force(&self, state: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let m = delayed_block(state.len());
        let n = out.len() / (1 + self.delays().len());
        out[n..].fill(0.0);
        self.force(&state[..n], &state[m..m + n], state[3 * m], &mut out[..n])
    }

    /// Writes the velocity q̇ with ∂L/∂q̇(q, q̇, t) = p into `v`: the inverse Legendre
    /// transform, unique for a regular Lagrangian. Default: Newton's method from `v` as given,
    /// with the exact ∂²L/∂q̇² where [`Lagrangian::hessians`] supplies it and a difference
    /// Jacobian otherwise (either exact in one step when L is quadratic in q̇), to round-off or
    /// to the noise floor of difference derivatives.
    fn velocity(&self, q: &[f64], p: &[f64], t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        inverse_legendre(self, q, p, t, v)
    }

    /// The energy function E(q, p, t) = p·q̇ − L(q, q̇, t), with q̇ from [`Lagrangian::velocity`];
    /// conserved when L does not depend on t.
    fn energy(&self, q: &[f64], p: &[f64], t: f64) -> Result<f64, ModelError> {
        with_zeros(q.len(), |v| {
            self.velocity(q, p, t, v)?;
            Ok(p.iter().zip(v.iter()).map(|(a, b)| a * b).sum::<f64>() - self.lagrangian(q, v, t)?)
        })
    }

    /// E(q, p, t) with its kinetic and potential terms (see [`EnergyTerms`]); the potential is
    /// −L(q, 0, t).
    fn energy_terms(&self, q: &[f64], p: &[f64], t: f64) -> Result<EnergyTerms, ModelError> {
        let energy = self.energy(q, p, t)?;
        let potential = -with_zeros(q.len(), |rest| self.lagrangian(q, rest, t))?;
        Ok(EnergyTerms {
            energy,
            kinetic: energy - potential,
            potential,
        })
    }
}

/// The inverse Legendre transform by Newton's method: [`Lagrangian::velocity`]'s default,
/// for models that check something before it.
pub fn inverse_legendre<L: Lagrangian + ?Sized>(
    sys: &L,
    q: &[f64],
    p: &[f64],
    t: f64,
    v: &mut [f64],
) -> Result<(), ModelError> {
    with_legendre_scratch(v.len(), |scratch| {
        let LegendreScratch {
            newton,
            plus,
            minus,
            hessians,
        } = scratch;
        let mut problem = InverseLegendre {
            sys,
            q,
            p,
            t,
            v,
            plus,
            minus,
            hessians: Some(hessians),
        };
        let rules = Rules { simplified: false };
        newton
            .solve(&mut problem, &NewtonOptions::default(), rules)
            .map_err(model_error)?;
        Ok(())
    })
}

/// ∂L/∂t by a central difference in t (two evaluations of L, about 1e-10 relative); 0 where L
/// does not depend on t.
pub fn differenced_dl_dt<L: Lagrangian + ?Sized>(l: &L, q: &[f64], v: &[f64], t: f64) -> Result<f64, ModelError> {
    if !l.is_time_dependent() {
        return Ok(0.0);
    }
    let h = difference::step(t.abs().max(1.0));
    Ok((l.lagrangian(q, v, t + h)? - l.lagrangian(q, v, t - h)?) / (2.0 * h))
}

/// L = ½ q̇ᵀ M q̇ − V(q): ∂L/∂q = −∇V(q), ∂L/∂q̇ = M q̇.
impl<S: MechanicalSystem + ?Sized> Lagrangian for S {
    fn dim(&self) -> usize {
        MechanicalSystem::dim(self)
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        Ok(self.mass().kinetic_energy_of_velocity(v) - self.potential(q)?)
    }

    fn dl_dq(&self, q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.gradient(q, out)?;
        out.iter_mut().for_each(|x| *x = -*x);
        Ok(())
    }

    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.mass().momentum(v, out);
        Ok(())
    }

    fn velocity(&self, _q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        self.mass().velocity(p, v);
        Ok(())
    }

    /// H = T + V with T = ½pᵀM⁻¹p and V(q), as [`super::hamiltonian`] sums them.
    fn energy_terms(&self, q: &[f64], p: &[f64], _t: f64) -> Result<EnergyTerms, ModelError> {
        let (kinetic, potential) = (self.mass().kinetic_energy(p), self.potential(q)?);
        Ok(EnergyTerms {
            energy: kinetic + potential,
            kinetic,
            potential,
        })
    }
}

/// ∂L/∂q̇(q, v, t) − p = 0 for v: the default inverse Legendre transform.
struct InverseLegendre<'a, S: ?Sized> {
    sys: &'a S,
    q: &'a [f64],
    p: &'a [f64],
    t: f64,
    v: &'a mut [f64],
    plus: &'a mut [f64],
    minus: &'a mut [f64],
    /// Scratch for the exact Hessians; None once the model has said it has none.
    hessians: Option<&'a mut Hessians>,
}

/// The inverse Legendre transform's workspace for n coordinates, kept per thread so that a
/// step that needs q̇(q, p) (the nonholonomic end condition, the energy check) allocates
/// nothing once it has its size.
struct LegendreScratch {
    newton: Newton,
    plus: Vec<f64>,
    minus: Vec<f64>,
    hessians: Hessians,
}

impl LegendreScratch {
    fn new(n: usize) -> Self {
        LegendreScratch {
            newton: Newton::new(n),
            plus: vec![0.0; n],
            minus: vec![0.0; n],
            hessians: Hessians::zeros(n),
        }
    }
}

thread_local! {
    static LEGENDRE: RefCell<Option<LegendreScratch>> = const { RefCell::new(None) };
    static ZEROS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// Runs `body` with n zeros (a velocity to fill, or q̇ = 0) from this thread's workspace
/// ([`with_scratch`]), so that the energy check at saved states allocates nothing.
fn with_zeros<R>(n: usize, body: impl FnOnce(&mut [f64]) -> R) -> R {
    with_scratch(&ZEROS, Vec::new, |buffer| {
        buffer.clear();
        buffer.resize(n, 0.0);
        body(buffer)
    })
}

/// Runs `body` with the workspace for n coordinates from this thread's ([`with_scratch`]).
fn with_legendre_scratch<R>(n: usize, body: impl FnOnce(&mut LegendreScratch) -> R) -> R {
    with_scratch(
        &LEGENDRE,
        || None,
        |slot| {
            if slot.as_ref().is_some_and(|s| s.plus.len() != n) {
                *slot = None;
            }
            body(slot.get_or_insert_with(|| LegendreScratch::new(n)))
        },
    )
}

impl<S: Lagrangian + ?Sized> NewtonProblem for InverseLegendre<'_, S> {
    const REASONS: Reasons = Reasons {
        singular: "the Hessian ∂²L/∂q̇² is singular: the Lagrangian is not regular here",
        non_finite_start: "the inverse Legendre transform ∂L/∂q̇ = p is non-finite at the start",
        non_finite: "the inverse Legendre transform ∂L/∂q̇ = p became non-finite",
        not_converged: "the inverse Legendre transform ∂L/∂q̇ = p did not converge",
        outside: "∂L/∂q̇ = p has no solution near the last velocity: L is not convex in q̇ on the way \
                  (∂²L/∂q̇² vanishes there), or p lies beyond what ∂L/∂q̇ reaches",
    };

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        self.sys.dl_dv(self.q, self.v, self.t, r)?;
        r.iter_mut().zip(self.p).for_each(|(r, p)| *r -= p);
        Ok(())
    }

    /// ∂²L/∂q̇², exact where the model supplies its Hessians, else by central differences of
    /// ∂L/∂q̇ (exact in one step when L is quadratic in q̇).
    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        let (sys, q, t) = (self.sys, self.q, self.t);
        if let Some(hessians) = &mut self.hessians {
            if sys.hessians(q, self.v, t, hessians)? {
                jac.copy_from(&hessians.vv);
                return Ok(());
            }
            self.hessians = None;
        }
        let at = Evaluations {
            plus: self.plus,
            minus: self.minus,
        };
        central_jacobian(|v, out| sys.dl_dv(q, v, t, out), self.v, difference::unit, at, jac)?;
        Ok(())
    }

    fn correct(&mut self, delta: &[f64]) -> Correction {
        Correction::relative(self.v, delta)
    }

    /// Its Jacobian is ∂²L/∂q̇².
    fn degenerate(&mut self) -> Result<bool, StepError> {
        let n = self.v.len();
        let mut mass = DMatrix::zeros(n, n);
        self.jacobian(&mut mass)?;
        Ok(degenerate(&mass))
    }

    /// The rounding of p.
    fn noise(&self) -> f64 {
        4.0 * f64::EPSILON * norm(self.p)
    }

    /// ∂L/∂q̇'s terms are of the size of ∂²L/∂q̇² q̇; the corrections are measured relative.
    fn offset(&self) -> f64 {
        norm(self.v)
    }
}
