//! Contacts held closed: a unilateral constraint φ(q) ≥ 0 kept as the equality φ(q) = 0 while
//! its multiplier pushes (λ ≥ 0), the motion of a body resting, sliding or rolling on a surface.
//!
//! The held step is RATTLE (Andersen 1983; HLW VII.1.4) on the closed surfaces Φ = (φₖ),
//!
//! p½ = p₀ + (τ/2)∂L/∂q(q₀) + ∇Φ(q₀)ᵀc,   q₁ = q₀ + τq̇(q₀, p½),   Φ(q₁) = 0,
//! p₁ = p½ + (τ/2)∂L/∂q(q₁) + ∇Φ(q₁)ᵀμ,   ∇Φ(q₁)q̇(q₁, p₁) = 0,
//!
//! composed with the fractions γ of the run's method where it is Verlet or a composition of it
//! (yoshida4, …): symplectic on the contact manifold at the method's order. The held state's
//! multipliers λ are those of [`crate::model::Reaction`] (the state's own), on the closed
//! surfaces; a contact is released where its λ crosses 0.
//!
//! Coulomb friction ([`super::Friction`]) adds to it: a sliding contact's force F = −μ_k N u
//! (u = Jᵀŝ, the slip's direction; N = λ|∇φ|) enters both kicks, the second implicitly at the
//! step's end (F(q₁, p₁), by fixed point), so the step stays symmetric (order 2, and its
//! compositions' order); a sticking contact's slip rows J join ∇Φ as constraints, on the
//! velocities at both kicks. The work of the sliding forces is ½(F₀ + F₁)·(q₁ − q₀) a step.

use nalgebra::DMatrix;

use super::friction::slip_after_kick;
use super::unsolved::{diagnosis, Cause, Unsolved};
use super::{Contact, Friction};
use crate::integrators::{Composition, Feature, Method};
use crate::model::Lagrangian;
use crate::solve::difference;
use crate::solve::fixed_point::{self, Pass};
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::solve::newton::{self, plain::Ended};
use crate::ModelError;

/// Newton iterations of the position constraint at most: it starts O(τ²) off and converges
/// quadratically, so a step that needs more is far too large for the surface's curvature.
const ITERATIONS: usize = 30;

/// A residual within this many times its round-off floor that no longer falls is at its
/// floor: φ rounds more than the coordinates it combines (10³ε relative).
const STALLED: f64 = 1e3;

/// The solves of a held step, as an [`Unsolved`] names them.
const POSITION: &str = "position constraint Φ(q₁) = 0";
const FRICTION: &str = "sliding friction's fixed point at a step's end";
const PROJECTION: &str = "momentum projection onto the contacts' tangent space";
const MULTIPLIERS: &str = "multipliers λ";

/// What a held step holds: the `closed` contacts (indices into `contacts`, in order), those of
/// them whose friction `stuck`, and each contact's slip direction u at the piece's start
/// (`directions`, n entries a contact, the j-th at j·n: the direction a sliding contact's
/// force keeps while its slip has not turned against it).
#[derive(Clone, Copy)]
pub(super) struct Held<'h, 's> {
    pub contacts: &'h [Contact<'s>],
    pub closed: &'h [usize],
    pub stuck: &'h [usize],
    pub directions: &'h [f64],
}

impl Held<'_, '_> {
    /// The friction of the a-th closed contact, if it slides.
    #[inline]
    fn sliding(&self, a: usize) -> Option<&Friction> {
        let j = self.closed[a];
        self.contacts[j].friction.as_ref().filter(|_| !self.stuck.contains(&j))
    }

    /// Whether any closed contact slides with friction (a force in the kicks).
    #[inline]
    fn slides(&self) -> bool {
        (0..self.closed.len()).any(|a| self.sliding(a).is_some())
    }
}

/// Whose slip a sliding force opposes: the state's, or, at a step's end, the slip that the
/// state before the friction kick (`Hold::along`) has after a kick of `kick` times the force
/// ([`slip_after_kick`]).
#[derive(Clone, Copy)]
enum Slipping {
    Now,
    Before { kick: f64 },
}

/// The held step of one method on a run's contacts, with every buffer it needs (made once: a
/// step allocates nothing).
#[derive(Debug)]
pub(super) struct Hold {
    gamma: Vec<f64>,
    /// The state a step advances, in place.
    pub(super) q: Vec<f64>,
    pub(super) p: Vec<f64>,
    v: Vec<f64>,
    w: Vec<f64>,
    zeros: Vec<f64>,
    /// ∂L/∂q and the sliding contacts' friction force at the state.
    force: Vec<f64>,
    friction: Vec<f64>,
    /// The friction force at a step's start, where its end's fixed point starts.
    initial: Vec<f64>,
    start: Vec<f64>,
    half: Vec<f64>,
    /// q̇ at p̃, the step's end before its friction kick, whose slip the force opposes.
    along: Vec<f64>,
    previous: Vec<f64>,
    /// The rounding of each coordinate of the position Newton's iterate.
    rounding: Vec<f64>,
    /// A point beside the state, and the rows there (as `rows`).
    shifted: Vec<f64>,
    shifted_rows: Vec<f64>,
    /// The constraint rows at q, k-th at k·n: ∇φ of the closed contacts, then the slip rows J
    /// of those stuck; and M⁻¹ times each.
    rows: Vec<f64>,
    inverse: Vec<f64>,
    /// The sliding contacts' directions u at the state, and M⁻¹u, a-th at a·n.
    units: Vec<f64>,
    units_inverse: Vec<f64>,
    /// The R × R systems and their pivots, the (R−1)-th for R rows.
    systems: Vec<(DMatrix<f64>, Vec<usize>)>,
    c: Vec<f64>,
    r: Vec<f64>,
    /// The multipliers of the state: λ of the closed contacts, then of the stuck slip rows.
    lambda: Vec<f64>,
    gradient: Vec<f64>,
    slip: Vec<f64>,
    /// The slip's metric JM⁻¹Jᵀ (k × k) and its factor, and [`slip_after_kick`]'s vectors.
    metric: Vec<f64>,
    factor: Vec<f64>,
    kicked: Vec<f64>,
    /// The work of the sliding forces in the last step.
    pub(super) work: f64,
    /// The time t at which `force`, `rows` and `inverse` hold ∂L/∂q and the rows of the
    /// contacts `cached_for` (closed, then stuck) at `q` (the end of the last step, where the
    /// run checks λ and the next step starts), if they do.
    cached: Option<f64>,
    cached_for: Vec<usize>,
}

impl Hold {
    /// The held step of `method` on n coordinates and `contacts` (any of them closed at once,
    /// and stuck if they have friction); None where the method has no held step
    /// ([`Feature::HeldStep`]: Verlet and its compositions have one).
    pub(super) fn new(method: Method, n: usize, contacts: &[Contact<'_>]) -> Option<Hold> {
        if !method.supports(Feature::HeldStep) {
            return None;
        }
        let gamma = Composition::of(method)?.gamma().to_vec();
        let m = contacts.len();
        let rows = m + contacts
            .iter()
            .filter_map(|c| c.friction.as_ref().map(|f| f.rows(n)))
            .sum::<usize>();
        let slip = contacts
            .iter()
            .filter_map(|c| c.friction.as_ref().map(|f| f.rows(n)))
            .max()
            .unwrap_or(0);
        let v = || vec![0.0; n];
        Some(Hold {
            gamma,
            q: v(),
            p: v(),
            v: v(),
            w: v(),
            zeros: v(),
            force: v(),
            friction: v(),
            initial: v(),
            start: v(),
            half: v(),
            along: v(),
            previous: v(),
            rounding: v(),
            shifted: v(),
            shifted_rows: vec![0.0; n * rows],
            rows: vec![0.0; n * rows],
            inverse: vec![0.0; n * rows],
            units: vec![0.0; n * m],
            units_inverse: vec![0.0; n * m],
            systems: (1..=rows).map(|k| (DMatrix::zeros(k, k), vec![0; k])).collect(),
            c: vec![0.0; rows],
            r: vec![0.0; rows],
            lambda: vec![0.0; rows],
            gradient: v(),
            slip: vec![0.0; slip * n],
            metric: vec![0.0; slip * slip],
            factor: vec![0.0; slip * slip],
            kicked: vec![0.0; 4 * slip],
            work: 0.0,
            cached: None,
            cached_for: Vec::with_capacity(2 * m),
        })
    }

    /// The methods that hold a contact ([`Feature::HeldStep`]), as an error names them: the held
    /// step is RATTLE composed as the method composes Verlet, so they are Verlet and its
    /// compositions.
    pub(super) fn methods() -> String {
        let names = Method::names(|m| m.supports(Feature::HeldStep));
        format!("{} and its compositions ({})", names[0], names[1..].join(", "))
    }

    /// The held step of size τ from (t, q, p) on `held`: its end in `q` and `p`, the work of
    /// its sliding forces in `work`.
    ///
    /// # Errors
    /// The model's or a surface's own error; an [`Unsolved`] solve: the position constraint
    /// or the friction's fixed point not reached, or rows dependent there.
    pub(super) fn step(
        &mut self,
        model: &dyn Lagrangian,
        held: Held<'_, '_>,
        (t, tau): (f64, f64),
        (q, p): (&[f64], &[f64]),
    ) -> Result<(), ModelError> {
        // The last step's end, where the next starts: its force and rows are kept.
        let mut warm = self.at(q, t, held);
        if !warm {
            self.q.copy_from_slice(q);
            model.dl_dq(&self.q, &self.zeros, t, &mut self.force)?;
        }
        self.p.copy_from_slice(p);
        self.work = 0.0;
        let sliding = held.slides();
        if sliding {
            if !warm {
                self.rows_at(model, held, t)?;
                warm = true;
            }
            self.forces(model, held, t, Slipping::Now)?;
        } else {
            self.friction.fill(0.0);
        }
        self.cached = None;
        let mut time = t;
        for k in 0..self.gamma.len() {
            let s = self.gamma[k] * tau;
            self.substep(model, held, (time, s), warm, sliding)?;
            time += s;
            warm = true;
        }
        self.cache(t + tau, held);
        Ok(())
    }

    /// Whether `force`, `rows` and `inverse` are those of `held` at (q, t): the last step
    /// ended there.
    #[inline]
    fn at(&self, q: &[f64], t: f64, held: Held<'_, '_>) -> bool {
        let m = held.closed.len();
        self.cached == Some(t)
            && self.q == q
            && self.cached_for.len() == m + held.stuck.len()
            && self.cached_for[..m] == *held.closed
            && self.cached_for[m..] == *held.stuck
    }

    /// `force`, `rows` and `inverse` marked as those of `held` at (q, t).
    fn cache(&mut self, t: f64, held: Held<'_, '_>) {
        self.cached = Some(t);
        self.cached_for.clear();
        self.cached_for.extend_from_slice(held.closed);
        self.cached_for.extend_from_slice(held.stuck);
    }

    /// One RATTLE step of size s from (q, p) at t, with ∂L/∂q(q) in `force` and the friction
    /// there in `friction` (and the rows at q in `rows` and `inverse` if `warm`), left at its
    /// end, its work added to `work`.
    fn substep(
        &mut self,
        model: &dyn Lagrangian,
        held: Held<'_, '_>,
        (t, s): (f64, f64),
        warm: bool,
        sliding: bool,
    ) -> Result<(), ModelError> {
        let n = self.q.len();
        for ((x, f), g) in self.p.iter_mut().zip(&self.force).zip(&self.friction) {
            *x += 0.5 * s * (f + g);
        }
        let rows = if warm {
            held.closed.len() + self.stuck_rows(held)
        } else {
            self.rows_at(model, held, t)?
        };
        let m = held.closed.len();
        // q₁(c) = q₀ + s(q̇(q₀, p½) + Σ c_b M⁻¹row_b(q₀)): Newton on Φ(q₁(c)) = 0 and, for the
        // stuck rows, J(q½)(q₁ − q₀) = 0 at the midpoint q½: rows that turn with q (a wheel's)
        // then hold along the chord, and the step stays symmetric. The others are J(q₀): constant,
        // or a particle's tangent plane, which does not move while it sticks.
        let midpoint = rows > m
            && held
                .stuck
                .iter()
                .any(|&j| held.contacts[j].friction.as_ref().is_some_and(Friction::turns));
        model.velocity(&self.q, &self.p, t, &mut self.v)?;
        self.start.copy_from_slice(&self.q);
        self.c[..rows].fill(0.0);
        // Each residual is judged against its round-off floor, the rounding of q₁'s every
        // coordinate (of the terms q₀ + s(q̇ + shift) it sums) through its row: Newton stops
        // where it reaches that floor, or where it stops falling within 10³ of it (a φ rounding
        // more than its terms), whatever the coordinates' sizes.
        let mut worst = (f64::NAN, f64::NAN, 0);
        let (system, pivots) = &mut self.systems[rows - 1];
        let ended = newton::plain::solve(
            ITERATIONS,
            (4.0, STALLED),
            &mut self.c[..rows],
            (system, pivots, &mut self.r[..rows]),
            |c, jacobian, r| {
                for i in 0..n {
                    let (mut shift, mut size) = (0.0, 0.0);
                    for (k, ck) in c.iter().enumerate() {
                        let x = ck * self.inverse[k * n + i];
                        shift += x;
                        size += x.abs();
                    }
                    self.q[i] = self.start[i] + s * (self.v[i] + shift);
                    self.rounding[i] =
                        f64::EPSILON * (self.start[i].abs() + self.q[i].abs() + s.abs() * (self.v[i].abs() + size));
                }
                if midpoint {
                    for ((x, x0), x1) in self.shifted.iter_mut().zip(&self.start).zip(&self.q) {
                        *x = 0.5 * (x0 + x1);
                    }
                    rows_into(held, &self.shifted, &mut self.shifted_rows, false)?;
                }
                let mut ratio = 0.0_f64;
                for a in 0..rows {
                    let row = if a < m {
                        let surface = &held.contacts[held.closed[a]].surface;
                        surface.gradient(&self.q, &mut self.gradient)?;
                        r[a] = -surface.phi(&self.q)?;
                        &self.gradient[..]
                    } else {
                        let rows = if midpoint { &self.shifted_rows } else { &self.rows };
                        let row = &rows[a * n..(a + 1) * n];
                        r[a] = -(0..n).map(|i| row[i] * (self.q[i] - self.start[i])).sum::<f64>();
                        row
                    };
                    let floor: f64 = row.iter().zip(&self.rounding).map(|(g, d)| (g * d).abs()).sum();
                    let against = if r[a] == 0.0 { 0.0 } else { r[a].abs() / floor };
                    // NaN (a residual that left the numbers) is the worst.
                    if against > ratio || against.is_nan() {
                        ratio = against;
                        worst = (r[a].abs(), floor, a);
                    }
                    for b in 0..rows {
                        let w = &self.inverse[b * n..(b + 1) * n];
                        jacobian[(a, b)] = s * row.iter().zip(w).map(|(g, w)| g * w).sum::<f64>();
                    }
                }
                Ok::<_, ModelError>(ratio)
            },
        )?;
        if ended == Ended::Singular {
            return Err(Unsolved::dependent(POSITION));
        }
        if ended == Ended::Unconverged {
            let (residual, floor, a) = worst;
            let stuck = (a >= m).then(|| &self.rows[a * n..(a + 1) * n]);
            let cause = diagnosis(
                (held.contacts, held.closed),
                (&self.q, &self.v, s),
                (a, stuck, residual),
            )?;
            return Err(Box::new(Unsolved {
                solve: POSITION,
                cause,
                residual,
                floor,
                iterations: ITERATIONS,
            }));
        }
        for i in 0..n {
            let shift: f64 = (0..rows).map(|k| self.c[k] * self.inverse[k * n + i]).sum();
            self.q[i] = self.start[i] + s * (self.v[i] + shift);
            self.p[i] += (0..rows).map(|k| self.c[k] * self.rows[k * n + i]).sum::<f64>();
        }
        model.dl_dq(&self.q, &self.zeros, t + s, &mut self.force)?;
        for (x, f) in self.p.iter_mut().zip(&self.force) {
            *x += 0.5 * s * f;
        }
        if !sliding {
            return self.project(model, held, t + s);
        }
        // p₁ = p̃ + (s/2)F(q₁, p₁), projected, p̃ = p½ + (s/2)∂L/∂q(q₁): by fixed point from
        // F(q₀, p₀), the force against p₁'s own slip. Where the kick turns the slip more than
        // the slip is (it is about to stop), that iteration does not contract: p₁'s slip is
        // then found from p̃'s, the kick's in the slip's metric solved for, and the iteration
        // settles N alone.
        self.project(model, held, t + s)?;
        self.half.copy_from_slice(&self.p);
        model.velocity(&self.q, &self.p, t + s, &mut self.along)?;
        let mut work = 0.5
            * (0..n)
                .map(|i| self.friction[i] * (self.q[i] - self.start[i]))
                .sum::<f64>();
        self.initial.copy_from_slice(&self.friction);
        if self.settle(model, held, (t + s, s), Slipping::Now)?.is_some() {
            self.friction.copy_from_slice(&self.initial);
            if let Some(unsettled) = self.settle(model, held, (t + s, s), Slipping::Before { kick: 0.5 * s })? {
                return Err(Box::new(unsettled));
            }
        }
        work += 0.5
            * (0..n)
                .map(|i| self.friction[i] * (self.q[i] - self.start[i]))
                .sum::<f64>();
        self.work += work;
        Ok(())
    }

    /// The fixed point p = p̃ + (s/2)F(q, p) at t, projected (p̃ in `half`, F from `friction`), F
    /// against the slip `slipping` names: None where it settled, else why not. Against p₁'s own
    /// slip it gives up as soon as it stops contracting.
    fn settle(
        &mut self,
        model: &dyn Lagrangian,
        held: Held<'_, '_>,
        (t, s): (f64, f64),
        slipping: Slipping,
    ) -> Result<Option<Unsolved>, ModelError> {
        let outcome = fixed_point::iterate(ITERATIONS, || {
            for ((x, h), f) in self.p.iter_mut().zip(&self.half).zip(&self.friction) {
                *x = h + 0.5 * s * f;
            }
            self.project(model, held, t)?;
            self.previous.copy_from_slice(&self.friction);
            self.forces(model, held, t, slipping)?;
            // Against the force's own size: its rounding, whatever the coordinates' sizes.
            let size = self.previous.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
            let change = self
                .previous
                .iter()
                .zip(&self.friction)
                .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()));
            // λ's curvature term is a difference, smooth in p to ε^(2/3) only: the iteration
            // settles where its change stops falling, within that.
            Ok::<_, ModelError>(Pass {
                change,
                floor: 4.0 * f64::EPSILON * size,
                stall: 1e-8 * size,
                give_up: matches!(slipping, Slipping::Now) || !change.is_finite(),
            })
        })?;
        if outcome.settled {
            return Ok(None);
        }
        Ok(Some(Unsolved {
            solve: FRICTION,
            cause: Cause::Step {
                past: "the sliding force's turn (a slip about to stop, or a curvature it does not resolve)",
            },
            residual: outcome.change,
            floor: outcome.floor,
            iterations: outcome.passes,
        }))
    }

    /// The number of slip rows of the stuck contacts.
    fn stuck_rows(&self, held: Held<'_, '_>) -> usize {
        let n = self.q.len();
        held.stuck
            .iter()
            .map(|&j| held.contacts[j].friction.as_ref().map_or(0, |f| f.rows(n)))
            .sum()
    }

    /// p made tangent to the closed contacts at q and free of the stuck ones' slip: p + Σ c_b
    /// row_b with rows · q̇(q, p + Σ c_b row_b) = 0.
    pub(super) fn project(&mut self, model: &dyn Lagrangian, held: Held<'_, '_>, t: f64) -> Result<(), ModelError> {
        let n = self.q.len();
        self.cached = None;
        let rows = self.rows_at(model, held, t)?;
        model.velocity(&self.q, &self.p, t, &mut self.v)?;
        let (system, pivots) = &mut self.systems[rows - 1];
        for a in 0..rows {
            let row = &self.rows[a * n..(a + 1) * n];
            for b in 0..rows {
                let w = &self.inverse[b * n..(b + 1) * n];
                system[(a, b)] = row.iter().zip(w).map(|(g, w)| g * w).sum();
            }
            self.c[a] = -row.iter().zip(&self.v).map(|(g, v)| g * v).sum::<f64>();
        }
        if lu_in_place(system, pivots).is_none() {
            return Err(Unsolved::dependent(PROJECTION));
        }
        lu_solve(system, pivots, &mut self.c[..rows]);
        for i in 0..n {
            self.p[i] += (0..rows).map(|k| self.c[k] * self.rows[k * n + i]).sum::<f64>();
        }
        Ok(())
    }

    /// The rows at q (∇φ of the closed contacts, then the stuck ones' slip rows) and M⁻¹
    /// times each, q̇(q, row) (q̇ linear in p: the kick–drift methods' models have
    /// T = ½pᵀM⁻¹p): their number.
    fn rows_at(&mut self, model: &dyn Lagrangian, held: Held<'_, '_>, t: f64) -> Result<usize, ModelError> {
        let n = self.q.len();
        let next = rows_into(held, &self.q, &mut self.rows, true)?;
        for a in 0..next {
            model.velocity(
                &self.q,
                &self.rows[a * n..(a + 1) * n],
                t,
                &mut self.inverse[a * n..(a + 1) * n],
            )?;
        }
        Ok(next)
    }

    /// The multipliers of the state (q, p) at t (`q` and `p`, the rows at q in `rows`, ∂L/∂q
    /// in `force`) into `lambda`, and the sliding contacts' friction force into `friction`.
    ///
    /// [`Reaction::solve`]'s equations, for the models a held step integrates (H = ½pᵀM⁻¹p +
    /// V(q), M constant, no forces of their own): row_a·q̈ + (d row_a/dt)·q̇ = 0 with
    /// q̈ = M⁻¹(∂L/∂q + Σ_b f_b λ_b), f_b = ∇φ_b − μ_k|∇φ_b|u_b for a closed contact (its
    /// sliding force with it), row_b for a stuck slip row. The curvature term is a central
    /// difference of row_a·q̇ along q̇, exact for quadrics: two gradients a row instead of the
    /// general difference's four evaluations of the whole motion.
    fn forces(
        &mut self,
        model: &dyn Lagrangian,
        held: Held<'_, '_>,
        t: f64,
        slipping: Slipping,
    ) -> Result<usize, ModelError> {
        let (n, m) = (self.q.len(), held.closed.len());
        let rows = m + self.stuck_rows(held);
        model.velocity(&self.q, &self.p, t, &mut self.v)?;
        model.velocity(&self.q, &self.force, t, &mut self.w)?;
        let slides = held.slides();
        if slides {
            self.directions(model, held, t, slipping)?;
        }
        let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
        let speed = amax(&self.v);
        // The difference's step: truncation (s²) and rounding (ε/s) both near ε^(2/3).
        let s = difference::step(amax(&self.q).max(1.0)) / speed;
        // The curvature terms (d row_a/dt)·q̇ into `r`.
        self.r[..rows].fill(0.0);
        if speed > 0.0 {
            for sign in [1.0, -1.0] {
                for (x, (qi, vi)) in self.shifted.iter_mut().zip(self.q.iter().zip(&self.v)) {
                    *x = qi + sign * s * vi;
                }
                rows_into(held, &self.shifted, &mut self.shifted_rows, true)?;
                for (curvature, shifted) in self.r[..rows].iter_mut().zip(self.shifted_rows.chunks_exact(n)) {
                    *curvature += sign * shifted.iter().zip(&self.v).map(|(g, v)| g * v).sum::<f64>();
                }
            }
            self.r[..rows].iter_mut().for_each(|c| *c /= 2.0 * s);
        }
        let (system, pivots) = &mut self.systems[rows - 1];
        for a in 0..rows {
            let row = &self.rows[a * n..(a + 1) * n];
            self.lambda[a] = -(self.r[a] + row.iter().zip(&self.w).map(|(g, x)| g * x).sum::<f64>());
            for b in 0..rows {
                let w = &self.inverse[b * n..(b + 1) * n];
                let mut entry: f64 = row.iter().zip(w).map(|(g, w)| g * w).sum();
                if let Some(friction) = (slides && b < m).then(|| held.sliding(b)).flatten() {
                    let u = &self.units_inverse[b * n..(b + 1) * n];
                    entry -= friction.kinetic
                        * normal_force(&self.rows, n, b, 1.0)
                        * row.iter().zip(u).map(|(g, u)| g * u).sum::<f64>();
                }
                system[(a, b)] = entry;
            }
        }
        if lu_in_place(system, pivots).is_none() {
            return Err(Unsolved::dependent(MULTIPLIERS));
        }
        lu_solve(system, pivots, &mut self.lambda[..rows]);
        self.friction.fill(0.0);
        for b in (0..m).filter(|_| slides) {
            if let Some(friction) = held.sliding(b) {
                let size = friction.kinetic * normal_force(&self.rows, n, b, self.lambda[b]);
                for (f, u) in self.friction.iter_mut().zip(&self.units[b * n..(b + 1) * n]) {
                    *f -= size * u;
                }
            }
        }
        Ok(rows)
    }

    /// N = λ|∇φ|, the normal force of the a-th closed contact's multiplier λ at the state whose
    /// rows `rows` holds (its ∇φ the a-th).
    #[inline]
    pub(super) fn normal_force(&self, a: usize, lambda: f64) -> f64 {
        normal_force(&self.rows, self.q.len(), a, lambda)
    }

    /// The sliding contacts' directions u = Jᵀŝ at the state (ŝ = s/|s|, s = Jq̇, of the
    /// velocity `slipping` names), or, where the slip has turned against the piece's direction
    /// u₀ (or stopped), u₀ on the rows at the state, ŝ = Ju₀/|Ju₀| (the same rows as the slip's,
    /// so that the force does not jump between the two as the slip hovers at 0); and M⁻¹u, into
    /// `units` and `units_inverse`.
    fn directions(
        &mut self,
        model: &dyn Lagrangian,
        held: Held<'_, '_>,
        t: f64,
        slipping: Slipping,
    ) -> Result<(), ModelError> {
        let n = self.q.len();
        for a in 0..held.closed.len() {
            let Some(friction) = held.sliding(a) else {
                continue;
            };
            let k = friction.rows(n);
            friction.jacobian(&self.q, &self.rows[a * n..(a + 1) * n], &mut self.slip[..k * n])?;
            let j = held.closed[a];
            let given = &held.directions[j * n..(j + 1) * n];
            let along = |unit: &mut [f64], x: &[f64]| {
                unit.fill(0.0);
                let mut size = 0.0;
                for row in self.slip[..k * n].chunks_exact(n) {
                    let s: f64 = row.iter().zip(x).map(|(j, x)| j * x).sum();
                    size += s * s;
                    for (u, j) in unit.iter_mut().zip(row) {
                        *u += s * j;
                    }
                }
                size.sqrt()
            };
            let unit = &mut self.units[a * n..(a + 1) * n];
            let mut size = match slipping {
                Slipping::Now => along(unit, &self.v),
                Slipping::Before { kick } => {
                    // s̃ = Jq̇(p̃), W = JM⁻¹Jᵀ, and ŝ after the kick −kick μ_k N Jᵀŝ.
                    let (slipped, rest) = self.kicked.split_at_mut(k);
                    let rows = &self.slip[..k * n];
                    for (x, row) in slipped.iter_mut().zip(rows.chunks_exact(n)) {
                        *x = row.iter().zip(&self.along).map(|(j, v)| j * v).sum();
                    }
                    for (c, column) in rows.chunks_exact(n).enumerate() {
                        model.velocity(&self.q, column, t, &mut self.gradient)?;
                        for (r, row) in rows.chunks_exact(n).enumerate() {
                            self.metric[r * k + c] = row.iter().zip(&self.gradient).map(|(j, w)| j * w).sum();
                        }
                    }
                    let c = kick * friction.kinetic * normal_force(&self.rows, n, a, self.lambda[a]).max(0.0);
                    let (direction, work) = rest.split_at_mut(k);
                    slip_after_kick(
                        (&self.metric[..k * k], &mut self.factor[..k * k]),
                        slipped,
                        c,
                        (direction, work),
                    );
                    unit.fill(0.0);
                    for (x, row) in direction.iter().zip(rows.chunks_exact(n)) {
                        unit.iter_mut().zip(row).for_each(|(u, j)| *u += x * j);
                    }
                    f64::from(u8::from(direction.iter().any(|x| *x != 0.0)))
                }
            };
            if !(size > 0.0 && unit.iter().zip(given).map(|(u, g)| u * g).sum::<f64>() > 0.0) {
                size = along(unit, given);
            }
            if size > 0.0 {
                unit.iter_mut().for_each(|u| *u /= size);
            }
            model.velocity(&self.q, unit, t, &mut self.units_inverse[a * n..(a + 1) * n])?;
        }
        Ok(())
    }

    /// Whether every closed contact of `held` still presses (λ ≥ 0) at the end of the step just
    /// taken, at time t: its multipliers from the force and rows the step kept there, the
    /// numbers [`Hold::multipliers`] gives for that state.
    pub(super) fn pressing(&mut self, model: &dyn Lagrangian, held: Held<'_, '_>, t: f64) -> Result<bool, ModelError> {
        debug_assert!(self.at(&self.q, t, held), "the last step ended at t");
        self.forces(model, held, t, Slipping::Now)?;
        Ok(self.lambda[..held.closed.len()].iter().all(|&l| l >= 0.0))
    }

    /// The multipliers of `held` at (q, p, t) into `out`: λ of the closed contacts (the k-th
    /// into `out[k]`), then of the stuck contacts' slip rows (the force along each); the
    /// number written.
    pub(super) fn multipliers(
        &mut self,
        model: &dyn Lagrangian,
        held: Held<'_, '_>,
        (q, p, t): (&[f64], &[f64], f64),
        out: &mut [f64],
    ) -> Result<usize, ModelError> {
        if !self.at(q, t, held) {
            self.q.copy_from_slice(q);
            self.rows_at(model, held, t)?;
            model.dl_dq(q, &self.zeros, t, &mut self.force)?;
            self.cache(t, held);
        }
        self.p.copy_from_slice(p);
        let rows = self.forces(model, held, t, Slipping::Now)?;
        out[..rows].copy_from_slice(&self.lambda[..rows]);
        Ok(rows)
    }

    /// The slip s = J(q)q̇ of a contact at (q, p, t) into `out` (k entries), and its direction
    /// in q, Jᵀs, into `direction`: the size of J's entries, max |J|.
    pub(super) fn slip(
        &mut self,
        model: &dyn Lagrangian,
        (contact, friction): (&Contact<'_>, &Friction),
        (q, p, t): (&[f64], &[f64], f64),
        (out, direction): (&mut [f64], &mut [f64]),
    ) -> Result<f64, ModelError> {
        let k = self.slip_rows((contact, friction), q)?;
        let n = q.len();
        model.velocity(q, p, t, &mut self.v)?;
        direction.fill(0.0);
        for (s, row) in out.iter_mut().zip(self.slip[..k * n].chunks_exact(n)) {
            *s = row.iter().zip(&self.v).map(|(j, v)| j * v).sum();
            for (d, j) in direction.iter_mut().zip(row) {
                *d += *s * j;
            }
        }
        Ok(self.slip[..k * n].iter().fold(0.0_f64, |a, x| a.max(x.abs())))
    }

    /// Jᵀx for a contact's slip rows at q, x given (k entries), into `out`.
    pub(super) fn slip_force(
        &mut self,
        (contact, friction): (&Contact<'_>, &Friction),
        q: &[f64],
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let k = self.slip_rows((contact, friction), q)?;
        let n = q.len();
        out.fill(0.0);
        for (x, row) in x.iter().zip(self.slip[..k * n].chunks_exact(n)) {
            for (o, j) in out.iter_mut().zip(row) {
                *o += x * j;
            }
        }
        Ok(())
    }

    /// A contact's slip rows J at q into `slip`: their number k.
    fn slip_rows(&mut self, (contact, friction): (&Contact<'_>, &Friction), q: &[f64]) -> Result<usize, ModelError> {
        let k = friction.rows(q.len());
        if friction.on_gradient() {
            contact.surface.gradient(q, &mut self.gradient)?;
        }
        friction.jacobian(q, &self.gradient, &mut self.slip[..k * q.len()])?;
        Ok(k)
    }
}

/// The rows of `held` at q into `out` (the k-th at k·n): ∇φ of the closed contacts, then the
/// stuck ones' slip rows, each contact's J evaluated once; their number. Without `normals` the
/// closed contacts' rows are not evaluated, but for a stuck contact whose J is made from its ∇φ.
fn rows_into(held: Held<'_, '_>, q: &[f64], out: &mut [f64], normals: bool) -> Result<usize, ModelError> {
    let n = q.len();
    if normals {
        for (a, &j) in held.closed.iter().enumerate() {
            held.contacts[j].surface.gradient(q, &mut out[a * n..(a + 1) * n])?;
        }
    }
    let mut next = held.closed.len();
    for &j in held.stuck {
        let a = held
            .closed
            .iter()
            .position(|&k| k == j)
            .expect("a stuck contact is closed");
        let friction = held.contacts[j]
            .friction
            .as_ref()
            .expect("a stuck contact has friction");
        let k = friction.rows(n);
        let (front, slips) = out.split_at_mut(next * n);
        let normal = &mut front[a * n..(a + 1) * n];
        if !normals && friction.on_gradient() {
            held.contacts[j].surface.gradient(q, normal)?;
        }
        friction.jacobian(q, normal, &mut slips[..k * n])?;
        next += k;
    }
    Ok(next)
}

/// N = λ|∇φ| of row a of `rows` (n entries a row).
#[inline]
fn normal_force(rows: &[f64], n: usize, a: usize, lambda: f64) -> f64 {
    lambda * rows[a * n..(a + 1) * n].iter().map(|g| g * g).sum::<f64>().sqrt()
}
