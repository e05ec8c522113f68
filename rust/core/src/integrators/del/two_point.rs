use super::history::History;
use super::{segment, StepEquations};
use crate::discrete::{DiscreteLagrangian, Quadrature, Segment, Vector, Workspace};
use crate::integrators::StepStart;
use crate::model::{delayed_block, delayed_slots, Lagrangian};
use crate::ModelError;
use serde::{Deserialize, Serialize};

/// The generalized force at a step's midpoint, f(q₀ + δq/2, δq/h, t + h/2), with its buffers,
/// and the delayed forces' history of the midpoints of the steps taken.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Forcing {
    /// The force's arguments as a compiled function's slots ([`delayed_block`]): the midpoint,
    /// then m − n more (the past states the history writes, m = n(1 + d)), the velocity and its
    /// past likewise, the past accelerations (after n slots never read), t.
    state: Vec<f64>,
    f: Vec<f64>,
    /// The time f was last evaluated at (NaN: none), with `state` its arguments: the
    /// solution's force is Newton's last evaluation's, taken again only where the arguments
    /// differ. A cache, not state: a restored step evaluates afresh.
    #[serde(skip, default = "nothing_evaluated")]
    at: f64,
    history: Option<History>,
}

fn nothing_evaluated() -> f64 {
    f64::NAN
}

impl Forcing {
    fn new(n: usize) -> Self {
        Forcing {
            state: vec![0.0; delayed_slots(n, 0)],
            f: vec![0.0; n],
            at: nothing_evaluated(),
            history: None,
        }
    }

    /// The force's arguments on the segment `at`: the midpoint, the velocity and the time.
    #[inline(always)]
    fn arguments(at: Segment<'_>) -> impl Iterator<Item = (f64, f64)> + '_ {
        at.q0.iter().zip(at.dq).map(move |(q, d)| (q + 0.5 * d, d / at.h))
    }

    /// The midpoint's block of `state`, the velocity's, and t's slot.
    #[inline(always)]
    fn blocks(&mut self) -> (&mut [f64], &mut [f64], &mut f64) {
        let n = self.f.len();
        let m = delayed_block(self.state.len());
        let (q, rest) = self.state.split_at_mut(m);
        let (v, rest) = rest.split_at_mut(m);
        (&mut q[..n], &mut v[..n], &mut rest[m])
    }

    fn evaluate<S: Lagrangian + ?Sized>(&mut self, sys: &S, at: Segment<'_>) -> Result<&[f64], ModelError> {
        let (mid, vel, time) = self.blocks();
        for ((m, v), (x, u)) in mid.iter_mut().zip(vel.iter_mut()).zip(Self::arguments(at)) {
            (*m, *v) = (x, u);
        }
        let t = at.t + 0.5 * at.h;
        *time = t;
        self.at = f64::NAN;
        match &mut self.history {
            Some(history) => history.forces(sys, &mut self.state, &mut self.f)?,
            None => {
                let n = self.f.len();
                sys.force(&self.state[..n], &self.state[n..2 * n], t, &mut self.f)?
            }
        }
        self.at = t;
        Ok(&self.f)
    }

    /// The force on `at`: the last evaluation's where its arguments were the same (Newton's
    /// last, at the solution: the same bits, one evaluation fewer a step), else a new one.
    fn on<S: Lagrangian + ?Sized>(&mut self, sys: &S, at: Segment<'_>) -> Result<&[f64], ModelError> {
        // Compared by their bits: 0.0 and −0.0 are equal as numbers, not as a force's arguments.
        let same = (at.t + 0.5 * at.h).to_bits() == self.at.to_bits() && {
            let (mid, vel, _) = self.blocks();
            Self::arguments(at)
                .zip(mid.iter().zip(vel.iter()))
                .all(|((m, v), (mid, vel))| m.to_bits() == mid.to_bits() && v.to_bits() == vel.to_bits())
        };
        if same {
            return Ok(&self.f);
        }
        self.evaluate(sys, at)
    }

    /// Records the step just solved, whose midpoint [`Forcing::evaluate`] holds, in the history.
    fn record(&mut self) {
        if let Some(history) = &mut self.history {
            history.record(&self.state);
        }
    }
}

/// The variational integrator of a two-point discrete Lagrangian (midpoint, trapezoid) with
/// forcing: F(δq) = p₀ + D₁L_d(q₀, q₀ + δq) + f_d⁻, then p₁ = D₂L_d + f_d⁺ (the forced DEL
/// equations of the discrete Lagrange–d'Alembert principle, f_d^± = (h/2)f(q̄, v, t + h/2) at
/// the midpoint). The work of the forces is f(q̄, v)·δq a step.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TwoPoint<R> {
    rule: R,
    ws: Workspace,
    forcing: Forcing,
    quadrature: Quadrature,
}

impl<R: DiscreteLagrangian> TwoPoint<R> {
    pub fn new(rule: R, n: usize) -> Self {
        let (nodes, weights) = rule.quadrature();
        TwoPoint {
            quadrature: Quadrature::new(1, nodes, weights, n),
            rule,
            ws: Workspace::new(n),
            forcing: Forcing::new(n),
        }
    }
}

impl<R: DiscreteLagrangian> super::Del<TwoPoint<R>> {
    /// Keeps the history that the delayed forces of `sys` read, at the step h (none without
    /// delays): sized here, before the run's loop.
    pub(in crate::integrators) fn keep_history(&mut self, n: usize, sys: &dyn Lagrangian, h: f64) {
        let forcing = &mut self.scheme.forcing;
        forcing.history = (!sys.delays().is_empty()).then(|| History::new(n, sys, h));
        // Resized, not made anew: a stepper's reset keeps its buffers (the values are written
        // before each evaluation).
        forcing.state.resize(delayed_slots(n, sys.delays().len()), 0.0);
    }
}

impl<R: DiscreteLagrangian> TwoPoint<R> {
    /// [`StepEquations::equations`] with the scratch space `ws`: arrays, for the fixed-size step.
    #[inline(always)]
    pub(super) fn equations_in<S: Lagrangian + ?Sized, V: Vector>(
        &mut self,
        ws: &mut Workspace<V>,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        equations(&self.rule, &mut self.forcing, ws, sys, start, x, out)
    }

    /// [`StepEquations::momentum_change`] with the scratch space `ws` of the last
    /// [`TwoPoint::equations_in`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn momentum_change_in<S: Lagrangian + ?Sized, V: Vector>(
        &mut self,
        ws: &mut Workspace<V>,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError> {
        let TwoPoint {
            rule,
            forcing,
            quadrature,
            ..
        } = self;
        momentum_change(rule, (forcing, quadrature), ws, sys, start, x, residual, dp)
    }
}

/// F(δq) = p₀ + D₁L_d(q₀, q₀ + δq) + f_d⁻ into `out`.
#[inline(always)]
fn equations<R: DiscreteLagrangian, S: Lagrangian + ?Sized, V: Vector>(
    rule: &R,
    forcing: &mut Forcing,
    ws: &mut Workspace<V>,
    sys: &S,
    start: StepStart<'_>,
    x: &[f64],
    out: &mut [f64],
) -> Result<(), ModelError> {
    let at = segment(&start, x);
    rule.d1(sys, at, out, ws)?;
    out.iter_mut().zip(start.p).for_each(|(o, p)| *o += p);
    if sys.is_forced() {
        let f = forcing.evaluate(sys, at)?;
        out.iter_mut().zip(f).for_each(|(o, f)| *o += 0.5 * start.h * f);
    }
    Ok(())
}

/// p₁ − p₀ = D₁L_d + D₂L_d + h·f(q̄, v) − F into `dp`, since F = p₀ + D₁L_d + f_d⁻; returns the
/// energy put in over the step: the forces' work, less ∂L_d/∂t where L depends on t (on the
/// rule's own `quadrature`). Called after [`equations`] at the same x, as Newton's method leaves
/// it: the rule reuses that D₁L_d's evaluation in `ws`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn momentum_change<R: DiscreteLagrangian, S: Lagrangian + ?Sized, V: Vector>(
    rule: &R,
    (forcing, quadrature): (&mut Forcing, &mut Quadrature),
    ws: &mut Workspace<V>,
    sys: &S,
    start: StepStart<'_>,
    x: &[f64],
    residual: &[f64],
    dp: &mut [f64],
) -> Result<f64, ModelError> {
    let at = segment(&start, x);
    rule.momentum_change_after_d1(sys, at, dp, ws)?;
    dp.iter_mut().zip(residual).for_each(|(d, r)| *d -= r);
    let time = quadrature.time_derivative(sys, at, rule.kept_dl_dt(ws))?;
    if !sys.is_forced() {
        return Ok(-time);
    }
    let f = forcing.on(sys, at)?;
    let mut work = -time;
    for ((d, f), x) in dp.iter_mut().zip(f).zip(x) {
        *d += start.h * f;
        work += f * x;
    }
    forcing.record();
    Ok(work)
}

impl<R: DiscreteLagrangian> StepEquations for TwoPoint<R> {
    fn unknowns(&self, n: usize) -> usize {
        n
    }

    // Inlined into Newton's iteration, whose chain of dependent evaluations a call would lengthen.
    #[inline(always)]
    fn equations<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let TwoPoint { rule, ws, forcing, .. } = self;
        equations(rule, forcing, ws, sys, start, x, out)
    }

    fn momentum_change<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        start: StepStart<'_>,
        x: &[f64],
        residual: &[f64],
        dp: &mut [f64],
    ) -> Result<f64, ModelError> {
        let TwoPoint {
            rule,
            ws,
            forcing,
            quadrature,
        } = self;
        momentum_change(rule, (forcing, quadrature), ws, sys, start, x, residual, dp)
    }

    fn predict(&self, dq: &[f64], x: &mut [f64]) {
        crate::solve::copy(x, dq);
    }

    fn quadrature(&mut self) -> &mut Quadrature {
        &mut self.quadrature
    }

    fn finishing(&mut self) {
        self.ws.keep_dl_dt();
    }
}
