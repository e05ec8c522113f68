//! The discrete energy E_d = −∂L_d/∂τ of a method's step of size τ, at fixed ends: what the
//! variational collision integrator conserves across an impact (Fetecau, Marsden, Ortiz &
//! West 2003), for an autonomous L.

use super::{Dynamics, Feature, Increment, Integrator, Method, Splitting, StepStart};
use crate::model::{Lagrangian, MechanicalSystem};
use crate::solve::fixed_point::{self, Pass};
use crate::{ModelError, StepError};

/// The methods with a discrete energy here, and their data.
#[derive(Clone, Debug)]
enum Rule {
    /// A kick–drift method, L_d(q₀, q₁, τ) = Σᵢ bᵢτ T((qᵢ − qᵢ₋₁)/(bᵢτ)) − Σⱼ aⱼτ V(q⁽ʲ⁾),
    /// stationary in the drifts' ends q⁽ʲ⁾ where the kicks act, so that
    /// E_d = Σᵢ bᵢ T(pᵢ) + Σⱼ aⱼ V(q⁽ʲ⁾), pᵢ the momenta of the i-th drift.
    KickDrift(Splitting),
    /// L_d = τL(q̄, v), q̄ = (q₀ + q₁)/2: E_d = E(q̄, v) = H(q̄, p̄), since the momenta
    /// p₀,₁ = ∂L/∂q̇ ∓ (τ/2)∂L/∂q (at q̄, v) have the half-sum p̄ = ∂L/∂q̇(q̄, v).
    Midpoint,
    /// L_d = (τ/2)[L(q₀, v) + L(q₁, v)]: E_d = ½[E(q₀, v) + E(q₁, v)], with v solved from the
    /// half-sum of the momenta (see [`DiscreteEnergy::trapezoid`]).
    Trapezoid,
    /// A Galerkin rule: its step solved again from (q₀, p₀), E_d from the control points that
    /// make L_d stationary ([`crate::discrete::Galerkin::energy`]).
    Galerkin(Box<Integrator>),
}

/// The discrete energy E_d = −∂L_d/∂τ of one method's step, with the buffers it needs, made
/// once: [`DiscreteEnergy::energy`] allocates nothing.
///
/// Velocities come from the momenta, never from (q₁ − q₀)/τ: a difference of the step's
/// positions keeps only a fraction τ‖v‖/‖q‖ of the digits of v, none as τ → 0.
#[derive(Clone, Debug)]
pub struct DiscreteEnergy {
    rule: Rule,
    q: Vec<f64>,
    p: Vec<f64>,
    v: Vec<f64>,
    /// ∂L/∂q at a kick's point, or at the two ends.
    force: Vec<f64>,
    force_end: Vec<f64>,
    /// ∂L/∂q̇ at the two ends.
    momentum: Vec<f64>,
    momentum_end: Vec<f64>,
    /// The trapezoid's next velocity.
    next: Vec<f64>,
    zeros: Vec<f64>,
}

/// Passes of the trapezoid's velocity iteration at most; it contracts by O(τ‖q₁ − q₀‖) and
/// stops at round-off well before.
const PASSES: usize = 50;

impl DiscreteEnergy {
    /// The discrete energy of `method`'s step on n coordinates; None where the method has none
    /// ([`Feature::DiscreteEnergy`]: the kick–drift methods, the midpoint and trapezoidal rules
    /// and the Galerkin rules have one).
    pub fn new(method: Method, n: usize) -> Option<DiscreteEnergy> {
        if !method.supports(Feature::DiscreteEnergy) {
            return None;
        }
        let rule = match method {
            Method::Midpoint => Rule::Midpoint,
            Method::Trapezoid => Rule::Trapezoid,
            Method::Galerkin4 | Method::Galerkin6 => Rule::Galerkin(Box::new(Integrator::new(method, n))),
            _ => Rule::KickDrift(Splitting::of(method)?),
        };
        let buffer = || vec![0.0; n];
        Some(DiscreteEnergy {
            rule,
            q: buffer(),
            p: buffer(),
            v: buffer(),
            force: buffer(),
            force_end: buffer(),
            momentum: buffer(),
            momentum_end: buffer(),
            next: buffer(),
            zeros: buffer(),
        })
    }

    /// E_d of the method's step of size τ from `start` = (q₀, p₀) to `end` = (q₁, p₁) at time
    /// t (L autonomous): a kick–drift method replays its stages and a Galerkin rule solves its
    /// step again from `start` (`end` unused); a two-point rule takes both ends. For τ = 0 (and
    /// a two-point rule's end = start) it is H(q₀, p₀).
    ///
    /// # Errors
    /// The model's own error, the trapezoid's velocity iteration failing to converge (a step
    /// too large for it), or the Galerkin step's own failure.
    pub fn energy<S: Dynamics + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        tau: f64,
        start: (&[f64], &[f64]),
        end: (&[f64], &[f64]),
    ) -> Result<f64, StepError> {
        let lagrangian = sys.as_lagrangian();
        Ok(match &mut self.rule {
            Rule::KickDrift(splitting) => {
                let buffers = (&mut self.q[..], &mut self.p[..], &mut self.v[..], &mut self.force[..]);
                match sys.as_mechanical() {
                    Some(separable) => kick_drift(splitting, buffers, &Separable(separable), t, tau, start)?,
                    None => kick_drift(splitting, buffers, &ThroughL(lagrangian, &self.zeros), t, tau, start)?,
                }
            }
            Rule::Midpoint => {
                self.mean(start, end);
                lagrangian.energy_terms(&self.q, &self.p, t)?.energy
            }
            Rule::Trapezoid => self.trapezoid(lagrangian, t, tau, start, end)?,
            Rule::Galerkin(_) if tau == 0.0 => lagrangian.energy(start.0, start.1, t)?,
            Rule::Galerkin(integrator) => {
                let step = StepStart {
                    t,
                    h: tau,
                    q: start.0,
                    p: start.1,
                };
                let mut increment = Increment {
                    dq: &mut self.q,
                    dp: &mut self.p,
                };
                integrator.reset();
                sys.increment(integrator, &step, &mut increment)?;
                integrator
                    .galerkin_energy(lagrangian, step)
                    .expect("a Galerkin method")?
            }
        })
    }

    /// q̄ = (q₀ + q₁)/2 into `q`, p̄ = (p₀ + p₁)/2 into `p`.
    fn mean(&mut self, (q0, p0): (&[f64], &[f64]), (q1, p1): (&[f64], &[f64])) {
        for (m, (a, b)) in self.q.iter_mut().zip(q0.iter().zip(q1)) {
            *m = 0.5 * (a + b);
        }
        for (m, (a, b)) in self.p.iter_mut().zip(p0.iter().zip(p1)) {
            *m = 0.5 * (a + b);
        }
    }

    /// ½[E(q₀, v) + E(q₁, v)], E(q, v) = v·∂L/∂q̇ − L, with v solved from the half-sum of the
    /// trapezoid's momenta p₀,₁ = ∂L/∂q̇(q₀,₁, v) ∓ (τ/2)∂L/∂q(q₀,₁, v):
    /// ½[∂L/∂q̇(q₀, v) + ∂L/∂q̇(q₁, v)] = p̄ + (τ/4)[∂L/∂q(q₀, v) − ∂L/∂q(q₁, v)], by the
    /// inverse Legendre map at q̄ iterated ([`fixed_point::iterate`]), v ← q̇(q̄, p̄ + shift(v)) with
    /// shift = (τ/4)[∂L/∂q(q₀, v) − ∂L/∂q(q₁, v)] + ∂L/∂q̇(q̄, v) − ½[∂L/∂q̇(q₀, v) + ∂L/∂q̇(q₁, v)]:
    /// a contraction by O(τ‖q₁ − q₀‖) and O(‖q₁ − q₀‖²), exact in one pass for a constant mass.
    fn trapezoid(
        &mut self,
        sys: &dyn Lagrangian,
        t: f64,
        tau: f64,
        (q0, p0): (&[f64], &[f64]),
        (q1, p1): (&[f64], &[f64]),
    ) -> Result<f64, ModelError> {
        self.mean((q0, p0), (q1, p1));
        let Self {
            q: mean,
            p: target,
            v,
            force,
            force_end,
            momentum,
            momentum_end,
            next: new,
            ..
        } = self;
        v.fill(0.0);
        sys.velocity(mean, target, t, v)?;
        // Settled at no change, or where the changes stop falling (round-off): judged below.
        let settled = fixed_point::iterate(PASSES, || {
            sys.gradients(q0, v, t, force, momentum)?;
            sys.gradients(q1, v, t, force_end, momentum_end)?;
            // `new` holds ∂L/∂q̇(q̄, v), then the target p̄ + shift, then the next v.
            sys.dl_dv(mean, v, t, new)?;
            for i in 0..new.len() {
                new[i] = 0.5 * (p0[i] + p1[i]) + 0.25 * tau * (force[i] - force_end[i]) + new[i]
                    - 0.5 * (momentum[i] + momentum_end[i]);
            }
            target.copy_from_slice(new);
            new.copy_from_slice(v);
            sys.velocity(mean, target, t, new)?;
            let change = new.iter().zip(v.iter()).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            v.copy_from_slice(new);
            Ok::<_, ModelError>(Pass {
                change,
                floor: 0.0,
                stall: f64::INFINITY,
                give_up: false,
            })
        })?;
        let step = settled.change;
        let scale = v.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        if step.is_nan() || step > 1e-6 * scale {
            return Err(format!(
                "the trapezoid's discrete energy: its velocity iteration stalled at a change of \
                 {step:.3e} (a step τ = {tau} too large for it)"
            )
            .into());
        }
        sys.dl_dv(q0, v, t, momentum)?;
        sys.dl_dv(q1, v, t, momentum_end)?;
        let e0 = dot(momentum, v) - sys.lagrangian(q0, v, t)?;
        let e1 = dot(momentum_end, v) - sys.lagrangian(q1, v, t)?;
        Ok(0.5 * (e0 + e1))
    }
}

/// What a kick–drift step's E_d reads of a model: q̇(q, p), V(q) and −∇V(q), from a separable
/// model's own M and V (a fifth of the calls through L), or through a Lagrangian's L at q̇ = 0.
trait Stages {
    fn velocity(&self, q: &[f64], p: &[f64], t: f64, v: &mut [f64]) -> Result<(), ModelError>;
    fn potential(&self, q: &[f64], t: f64) -> Result<f64, ModelError>;
    fn force(&self, q: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError>;
}

struct Separable<'a>(&'a dyn MechanicalSystem);

impl Stages for Separable<'_> {
    fn velocity(&self, _q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        self.0.mass().velocity(p, v);
        Ok(())
    }
    fn potential(&self, q: &[f64], _t: f64) -> Result<f64, ModelError> {
        self.0.potential(q)
    }
    fn force(&self, q: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.0.gradient(q, out)?;
        out.iter_mut().for_each(|x| *x = -*x);
        Ok(())
    }
}

/// A Lagrangian, with the zero velocity its V = −L(q, 0) is read at.
struct ThroughL<'a>(&'a dyn Lagrangian, &'a [f64]);

impl Stages for ThroughL<'_> {
    fn velocity(&self, q: &[f64], p: &[f64], t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        self.0.velocity(q, p, t, v)
    }
    fn potential(&self, q: &[f64], t: f64) -> Result<f64, ModelError> {
        Ok(-self.0.lagrangian(q, self.1, t)?)
    }
    fn force(&self, q: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.0.dl_dq(q, self.1, t, out)
    }
}

/// Σᵢ bᵢ T(pᵢ) + Σⱼ aⱼ V(q⁽ʲ⁾) along the stages from (q₀, p₀), with T = ½p·q̇(q, p): the last
/// kick's force is not needed.
fn kick_drift<S: Stages>(
    splitting: &Splitting,
    (q, p, v, force): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
    sys: &S,
    t: f64,
    tau: f64,
    (q0, p0): (&[f64], &[f64]),
) -> Result<f64, ModelError> {
    let (kicks, drifts) = (splitting.kicks(), splitting.drifts());
    q.copy_from_slice(q0);
    p.copy_from_slice(p0);
    let mut energy = 0.0;
    for (j, &a) in kicks.iter().enumerate() {
        if j > 0 {
            let b = drifts[j - 1];
            sys.velocity(q, p, t, v)?;
            energy += b * 0.5 * dot(p, v);
            for (x, y) in q.iter_mut().zip(v.iter()) {
                *x += b * tau * y;
            }
        }
        if a == 0.0 {
            continue;
        }
        energy += a * sys.potential(q, t)?;
        if j + 1 < kicks.len() {
            sys.force(q, t, force)?;
            for (x, f) in p.iter_mut().zip(force.iter()) {
                *x += a * tau * f;
            }
        }
    }
    Ok(energy)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
