//! Impacts: the first contact a piece crosses, located to round-off, and the jump there by the
//! contact's law, which may close the contact (the body then held on it).

use std::ops::Deref;

use super::{dot, insert, Resolver};
use crate::integrators::clear::{below, floor};
use crate::integrators::jumps::hold::Hold;
use crate::integrators::jumps::reflect::{self, Reflection};
use crate::integrators::jumps::{Contact, Impact, MAX_IMPACTS};
use crate::integrators::Dynamics;
use crate::integrators::Switch;
use crate::model::Lagrangian;
use crate::solve::bracket::newton;
use crate::{Error, ModelError};

impl<'c, 's, M: Deref<Target: Dynamics>> Resolver<'c, 's, M> {
    /// The first contact the piece of size τ from ta crosses (φ at its end in `phi_end`, the
    /// scratch left where the location ends), and where: each located to round-off; `last`, the
    /// contact of the jump the piece starts from, and any it starts on or past, only where φ
    /// falls below its start.
    pub(super) fn first_crossing(
        &mut self,
        step: usize,
        (ta, tau): (f64, f64),
        last: Option<usize>,
    ) -> Result<Option<(f64, usize)>, Error> {
        let mut first: Option<(f64, usize)> = None;
        for j in 0..self.contacts.len() {
            let leaving = last == Some(j) || self.phi_start[j] <= 0.0;
            if self.closed.contains(&j) || !below(self.phi_end[j] - floor(self.phi_start[j], leaving), leaving) {
                continue;
            }
            let s = match self.locate(j, step, (ta, tau), leaving) {
                Ok(s) => s,
                Err(Located::Error(e)) => return Err(e),
                // A flight that ended exactly on the surface at the last step's end (φ = 0
                // there is no crossing of a piece leaving it) arrives, moving into it, at this
                // piece's start.
                Err(Located::Resting) if last != Some(j) && self.start_rate(j, step, ta)? < 0.0 => {
                    self.partial(step, ta, 0.0)?;
                    Some(0.0)
                }
                Err(Located::Resting) => return Err(self.contact_error(step, self.resting(j))),
            };
            if let Some(s) = s {
                if first.is_none_or(|(s0, _)| s < s0) {
                    first = Some((s, j));
                }
            }
        }
        Ok(first)
    }

    /// φⱼ's rate ∇φⱼ·q̇ at the piece's start (ta, `piece_q`, `piece_p`).
    fn start_rate(&mut self, j: usize, step: usize, ta: f64) -> Result<f64, Error> {
        let (model, time) = (self.scratch.model().as_lagrangian(), self.t);
        let vectors = (&mut self.normal[..], &mut self.v[..]);
        phi_rate(&self.contacts[j], model, (ta, &self.piece_q, &self.piece_p), vectors)
            .map_err(|source| Error::model(step, time, source))
    }

    /// Why a body leaving contact j that crosses it again at once cannot go on, and what helps.
    pub(super) fn resting(&self, j: usize) -> String {
        format!(
            "a body leaving the contact {} crosses it again at once (a resting or grazing contact, such as e = 0 \
             under a force pressing on it), which impacts cannot resolve; {}",
            self.contacts[j].name,
            // A method that holds contacts missed this one's closing: its bounces outran the step.
            if self.hold.is_some() {
                "this method holds such a contact closed once its bounces die out within a step: a smaller step \
                 (dt) helps"
                    .to_string()
            } else {
                format!(
                    "{} hold such a contact closed on a model without forces or constraints of its own",
                    Hold::methods()
                )
            }
        )
    }

    /// The impact on contact j at (q̃, p⁻) (the contact buffers), the end of the piece of size s
    /// from ta with `rest` of the step h after it: the jump ([`Resolver::jump`]) and what it
    /// does to the closed contacts, p⁺ into `piece_p`, the impact kept for the step's report.
    pub(super) fn impact(
        &mut self,
        j: usize,
        step: usize,
        (ta, s, rest): (f64, f64, f64),
        h: f64,
    ) -> Result<(), Error> {
        let (t, before) = (ta + s, self.step_work);
        self.jump(j, step, (ta, s, rest), h)?;
        self.after_jump(step, t)?;
        if !self.piece_p.iter().all(|x| x.is_finite()) {
            let reason = format!(
                "a non-finite state after the impact on {} at t = {t}",
                self.contacts[j].name
            );
            return Err(self.contact_error(step, reason));
        }
        self.pending
            .push(j, step, t, &self.contact_q, &self.contact_p, &self.piece_p);
        self.pending_work.push([before, self.step_work]);
        Ok(())
    }

    /// Why a step met more than [`MAX_IMPACTS`] impacts, and what helps: flights that shrink
    /// geometrically (each of the last [`SHRINKING`] shorter than the one before, or at t's
    /// resolution, at a mean ratio r below 0.999, so that they sum to within 10³ flights)
    /// accumulate at a finite time, as a body coming to rest does (r = e under a constant
    /// force), which no step resolves; flights that do not (a chatter of equal ones) are a step
    /// too long for them.
    pub(super) fn too_many_impacts(&self) -> String {
        let t = &self.pending.t;
        let k = t.len();
        let (first, last) = (t[1] - t[0], t[k - 1] - t[k - 2]);
        let ratio = (last / first).powf(1.0 / (k - 2) as f64);
        // Flights at t's resolution (0 or a few ulps, as t rounds): the series is at its
        // limit to round-off.
        let resolution = 4.0 * f64::EPSILON * t[k - 1].abs();
        let shrinking = t
            .windows(3)
            .rev()
            .take(SHRINKING)
            .all(|w| w[2] - w[1] < w[1] - w[0] || w[2] - w[1] <= resolution);
        if !(shrinking && ratio < 0.999) {
            return format!(
                "more than {MAX_IMPACTS} impacts in one step, in flights as short as {last:.3e}: shorten the step (dt)"
            );
        }
        // The geometric series of the flights' ratio sums to where they accumulate.
        let limit = format!(" at t ≈ {:.6}", t[k - 1] + last * ratio / (1.0 - ratio));
        let hold = if self.hold.is_some() {
            "; this method holds a contact closed only where e < 1 and the body presses on it".to_string()
        } else {
            format!(
                ", or hold the contact: {} hold such a contact closed on a model without forces or constraints of its \
                 own, with e < 1",
                Hold::methods()
            )
        };
        format!(
            "more than {MAX_IMPACTS} impacts in one step, their flights shrinking to an accumulation{limit} (a body \
             coming to rest on a surface), which no step resolves: stop the run before it{hold}"
        )
    }

    /// The jump on contact j at (q̃, p⁻) (the contact buffers), at the end of the piece of size s
    /// from ta with `rest` of the step after it: p⁺ into `piece_p`. The contact closes there
    /// ([`Resolver::closes`]) when the rest of its bounces would last less than the step h.
    pub(super) fn jump(&mut self, j: usize, step: usize, (ta, s, rest): (f64, f64, f64), h: f64) -> Result<(), Error> {
        let contacts = self.contacts;
        let contact = &contacts[j];
        let (t, time) = (ta + s, self.t);
        let model_error = |source| Error::model(step, time, source);
        let model = self.scratch.model();
        let (q, p) = (&self.contact_q[..], &self.contact_p[..]);
        contact.surface.gradient(q, &mut self.normal).map_err(model_error)?;
        // On a constrained model, the part of ∇φ the constraints let act: the surface's impulse
        // comes with the constraints' workless one that keeps the momenta on them, which adds up
        // to ∇φ projected M-orthogonally (the projection's affine part cancels).
        for (x, (a, b)) in self.v.iter_mut().zip(p.iter().zip(&self.normal)) {
            *x = a + b;
        }
        if let Some(projected) = model.project(q, &self.v) {
            let (_, with) = projected?;
            let (_, without) = model.project(q, p).expect("a constrained model projects")?;
            for (x, (a, b)) in self.normal.iter_mut().zip(with.iter().zip(&without)) {
                *x = a - b;
            }
        }
        let vectors = (&mut self.v[..], &mut self.w[..], &self.zeros[..]);
        let reflected = reflect::reflection(
            model.as_lagrangian(),
            (t, q, p),
            &self.normal,
            contact.restitution,
            vectors,
        )
        .map_err(model_error)?;
        let reflection = reflected.lambda;
        // A surface only pushes (λ ≥ 0, Signorini): a crossing whose momentum already leaves
        // (∇φ·q̇ > 0, a graze the partial steps of a coarse step dip through) takes no impulse,
        // where the reflection would kick the body into the surface.
        if reflection < 0.0 {
            self.piece_p.copy_from_slice(&self.contact_p);
            return Ok(());
        }
        let mut at = At {
            resolver: self,
            step,
            piece: (ta, s, rest),
            newton: (reflected, contact.restitution),
            last: f64::NAN,
        };
        let jump = contact.law.jump(&mut at)?;
        // The scratch holds the piece after the jump for the λ taken: the next piece's first step.
        if at.last == jump.lambda {
            self.keep(t, rest);
        }
        self.pending.grazing += usize::from(jump.grazing);
        let (lambda, mut loss) = (jump.lambda, jump.loss);
        for (x, (a, b)) in self.piece_p.iter_mut().zip(self.contact_p.iter().zip(&self.normal)) {
            *x = a + lambda * b;
        }
        // Newton's λ for the restitution the law took (the contact's own: the same bits).
        let e = (jump.restitution, contact.restitution);
        let newton = reflection * ((1.0 + e.0) / (1.0 + e.1));
        if let Some(t_rest) = self.closes(j, step, t, (newton, e.0, h))? {
            // The whole normal velocity gone: the Zeno series' losses summed.
            loss = reflected.loss(0.0);
            insert(&mut self.closed, j);
            self.switched(j, Switch::Closed, step, (t, t_rest));
            self.scratch.restart(t, &self.contact_q, &self.piece_p, h);
            if self.sticks(j, step, t)? {
                self.project_piece(step, t)?;
                self.switched(j, Switch::Stuck, step, (t, t_rest));
            }
        }
        self.step_work += loss;
        Ok(())
    }

    /// Whether contact j closes at its impact at time t, reflected with the multiplier
    /// `reflection` of Newton's law with restitution e, the law's (the normal, ∇φ, in
    /// `normal`): the body pressing on the surface once its normal velocity is gone (λ > 0),
    /// and the Zeno series of the rebounds, flights of
    /// 2v⁺/|a|, 2ev⁺/|a|, … under the normal acceleration a = −λ∇φᵀM⁻¹∇φ, summing to
    /// T∞ = 2v⁺/(|a|(1 − e)) ≤ h (at once for v⁺ = 0), or, for e near 1, where T∞ is longer,
    /// flights under h/[`MAX_IMPACTS`]: their bounces, of height |a|(2v⁺/|a|)²/8, are below the
    /// method's error in a step, and more of them than a step resolves would fall in it (for
    /// e > 1 − 1/[`MAX_IMPACTS`]). Then the momenta lose their normal
    /// velocity (`piece_p`: the reflection with e = 0) and the contact is held from t: the
    /// series' limit t + T∞, when the body comes to rest on the surface, is returned.
    pub(super) fn closes(
        &mut self,
        j: usize,
        step: usize,
        t: f64,
        (reflection, e, h): (f64, f64, f64),
    ) -> Result<Option<f64>, Error> {
        // Elastic contacts close only on an arrival without normal velocity.
        if self.hold.is_none() || (e == 1.0 && reflection != 0.0) {
            return Ok(None);
        }
        let time = self.t;
        let model_error = |source| Error::model(step, time, source);
        // p with the normal velocity gone, λ/(1 + e) along ∇φ; v⁺ = −e∇φ·q̇⁻ = eλ nᵀM⁻¹n/(1 + e).
        for (x, (a, b)) in self.w.iter_mut().zip(self.contact_p.iter().zip(&self.normal)) {
            *x = a + reflection / (1.0 + e) * b;
        }
        let model = self.scratch.model().as_lagrangian();
        model
            .velocity(&self.contact_q, &self.normal, t, &mut self.v)
            .map_err(model_error)?;
        let metric_plus = dot(&self.normal, &self.v);
        model
            .velocity(&self.contact_q, &self.zeros, t, &mut self.v)
            .map_err(model_error)?;
        let metric = metric_plus - dot(&self.normal, &self.v);
        let rebound = e * reflection * metric / (1.0 + e);
        insert(&mut self.closed, j);
        let a = self.closed.iter().position(|&k| k == j).expect("just inserted");
        self.scratch.restart(t, &self.contact_q, &self.w, h);
        let mut lambda = std::mem::take(&mut self.lambda);
        let pressed = self.multipliers(t, &mut lambda, step).map(|()| lambda[a]);
        self.lambda = lambda;
        self.closed.retain(|&k| k != j);
        let pressed = pressed?;
        if pressed.is_nan() || pressed <= 0.0 {
            return Ok(None);
        }
        let tail = if rebound == 0.0 {
            0.0
        } else if e < 1.0 {
            2.0 * rebound / (pressed * metric * (1.0 - e))
        } else {
            return Ok(None);
        };
        if tail.is_nan() || (tail > h && tail * (1.0 - e) * MAX_IMPACTS as f64 > h) {
            return Ok(None);
        }
        self.piece_p.copy_from_slice(&self.w);
        Ok(Some(t + tail))
    }

    /// The s ∈ (0, τ] where φⱼ along the piece from (ta, piece_q, piece_p) falls through 0,
    /// by Newton's method in the bracket ([`newton`]) to round-off. A piece that starts above the surface
    /// brackets it by its ends (φⱼ falls through 0 once in a step short against the path's
    /// curvature); one leaving it (`leaving`: it starts on that surface and only φⱼ < 0 counts)
    /// is bracketed by samples ([`Resolver::leaving_bracket`]). None when no sample is below
    /// (round-off at the piece's end).
    pub(super) fn locate(
        &mut self,
        j: usize,
        step: usize,
        (ta, tau): (f64, f64),
        leaving: bool,
    ) -> Result<Option<f64>, Located> {
        let floor = floor(self.phi_start[j], leaving);
        let start = (0.0, self.phi_start[j] - floor);
        let ((a, b), guess) = if leaving {
            match self.leaving_bracket(j, step, (ta, tau), start, floor)? {
                Some(bracket) => (bracket, None),
                None => return Ok(None),
            }
        } else {
            // The partial steps' q(s) leaves with the velocity q̇ at the piece's start.
            let rate = self.start_rate(j, step, ta)?;
            let end = (tau, self.phi_end[j]);
            ((start, end), Some(quadratic_root(start.1, rate, end)))
        };
        let tolerance = 4.0 * f64::EPSILON * tau;
        let mut least = f64::INFINITY;
        let (s, _) = newton(
            |s| {
                let (phi, rate) = self.phi_rate_along(j, step, ta, s)?;
                // The nearest so far, which the contact state will be.
                if (phi - floor).abs() < least {
                    least = (phi - floor).abs();
                    self.keep(ta, s);
                }
                Ok::<_, Error>((phi - floor, rate))
            },
            a,
            b,
            guess,
            tolerance,
        )?;
        Ok(Some(s))
    }

    /// φⱼ and its rate ∇φⱼ·q̇ at the end of the partial step of size s from the piece's start:
    /// the rate of the flow through that state, within the method's error of the partial
    /// steps' own rate in s, which is what [`newton`] needs.
    pub(super) fn phi_rate_along(&mut self, j: usize, step: usize, ta: f64, s: f64) -> Result<(f64, f64), Error> {
        let phi = self.phi_along(j, step, ta, s)?;
        let (model, time) = (self.scratch.model().as_lagrangian(), self.t);
        let state = (ta + s, self.scratch.q(), self.scratch.p());
        let rate = phi_rate(&self.contacts[j], model, state, (&mut self.normal, &mut self.v))
            .map_err(|source| Error::model(step, time, source))?;
        Ok((phi, rate))
    }

    /// The bracket of a crossing of φⱼ − `floor` (`start` its value at s = 0) on a piece
    /// leaving the surface: eight samples over (0, τ], refined towards 0 up to four times while
    /// the first is already below; a body below at every one crosses again at once
    /// ([`Located::Resting`]). None when no sample is below.
    pub(super) fn leaving_bracket(
        &mut self,
        j: usize,
        step: usize,
        (ta, tau): (f64, f64),
        start: (f64, f64),
        floor: f64,
    ) -> Result<Option<Bracket>, Located> {
        let mut hi = tau;
        for _ in 0..4 {
            let mut previous = start;
            let mut found = None;
            for k in 1..=8 {
                let x = hi * k as f64 / 8.0;
                let v = self.phi_along(j, step, ta, x)? - floor;
                if below(v, true) {
                    found = Some((k, x, v));
                    break;
                }
                previous = (x, v);
            }
            let Some((k, x, v)) = found else {
                return Ok(None);
            };
            if k > 1 {
                return Ok(Some((previous, (x, v))));
            }
            hi = x;
        }
        Err(Located::Resting)
    }

    /// φⱼ at the end of the partial step of size s from the piece's start.
    pub(super) fn phi_along(&mut self, j: usize, step: usize, ta: f64, s: f64) -> Result<f64, Error> {
        self.partial(step, ta, s)?;
        let surface = &self.contacts[j].surface;
        surface.phi(self.scratch.q()).map_err(|source| Error::Model {
            step,
            time: self.t,
            source,
        })
    }
}

/// The last flights of a step's impacts that must each shrink for an accumulation.
const SHRINKING: usize = 16;

/// Two points (s, φ − floor) on either side of a crossing.
pub(super) type Bracket = ((f64, f64), (f64, f64));

/// Why a crossing was not located.
pub(super) enum Located {
    Error(Error),
    /// Below the surface at every sample of a piece leaving it.
    Resting,
}

impl From<Error> for Located {
    fn from(e: Error) -> Self {
        Located::Error(e)
    }
}

/// ∇φ·q̇ of `contact` at the state (t, q, p), with ∇φ and q̇ left in `normal` and `v`.
pub(super) fn phi_rate(
    contact: &Contact<'_>,
    model: &dyn Lagrangian,
    (t, q, p): (f64, &[f64], &[f64]),
    (normal, v): (&mut [f64], &mut [f64]),
) -> Result<f64, ModelError> {
    contact.surface.gradient(q, normal)?;
    model.velocity(q, p, t, v)?;
    Ok(dot(normal, v))
}

/// The root in (0, τ) of the quadratic through φ(0) = φ₀ > 0 with φ′(0) = r₀ and φ(τ) = φ₁ ≤ 0
/// (NaN where round-off leaves it none): the crossing of a flight whose φ is quadratic in
/// time (a straight chord of a circle, a parabola over a wall) to round-off, in the form
/// 2φ₀/(√(r₀² − 4cφ₀) − r₀), which does not cancel.
pub(super) fn quadratic_root(phi0: f64, r0: f64, (tau, phi1): (f64, f64)) -> f64 {
    let c = (phi1 - phi0 - r0 * tau) / (tau * tau);
    2.0 * phi0 / ((r0 * r0 - 4.0 * c * phi0).sqrt() - r0)
}

/// An impact on the resolver's contact buffers (q̃, p⁻, ∇φ), as its law sees it.
struct At<'r, 'c, 's, M> {
    resolver: &'r mut Resolver<'c, 's, M>,
    step: usize,
    /// The piece's start ta, its size s to the impact, and the rest of the step after it.
    piece: (f64, f64, f64),
    newton: (Reflection, f64),
    /// The λ of the last piece after the impact taken, whose end the scratch holds.
    last: f64,
}

impl<M: Deref<Target: Dynamics>> Impact for At<'_, '_, '_, M> {
    fn newton(&self) -> (Reflection, f64) {
        self.newton
    }

    fn newton_only(&self) -> bool {
        !self.resolver.closed.is_empty() || self.piece.2 <= 0.0
    }

    /// E_d of the piece from ta to the impact; leaves `piece_q` at q̃, the next piece's start.
    fn discrete_energy(&mut self) -> Result<Option<(f64, f64)>, Error> {
        let (step, (ta, s, _)) = (self.step, self.piece);
        let r = &mut *self.resolver;
        let time = r.t;
        let Some(discrete) = r.discrete.as_mut() else {
            return Ok(None);
        };
        let before = (&r.piece_q[..], &r.piece_p[..]);
        let target = discrete
            .energy(r.scratch.model(), ta, s, before, (&r.contact_q, &r.contact_p))
            .map_err(|e| e.at(step, time))?;
        r.scratch
            .model()
            .as_lagrangian()
            .velocity(&r.contact_q, &r.contact_p, ta + s, &mut r.v)
            .map_err(|source| Error::model(step, time, source))?;
        r.piece_q.copy_from_slice(&r.contact_q);
        Ok(Some((target, dot(&r.contact_p, &r.v))))
    }

    fn discrete_energy_after(&mut self, lambda: f64) -> Result<f64, Error> {
        self.last = lambda;
        let (step, (ta, s, rest)) = (self.step, self.piece);
        let r = &mut *self.resolver;
        let (t, time) = (ta + s, r.t);
        for (x, (a, b)) in r.piece_p.iter_mut().zip(r.contact_p.iter().zip(&r.normal)) {
            *x = a + lambda * b;
        }
        r.scratch.restart(t, &r.piece_q, &r.piece_p, rest);
        r.scratch.step().map_err(|e| e.at(step, time))?;
        let discrete = r.discrete.as_mut().expect("asked for after discrete_energy");
        let end = (r.scratch.q(), r.scratch.p());
        discrete
            .energy(r.scratch.model(), t, rest, (&r.piece_q, &r.piece_p), end)
            .map_err(|e| e.at(step, time))
    }
}
