//! Wisdom–Holman methods for near-Keplerian N-body problems: the Kepler drift, Jacobi
//! coordinates, the interaction kick and Wisdom, Holman & Touma's symplectic correctors.
//!
//! In Jacobi coordinates (x′, v′) ([`Jacobi`]) the N-body Hamiltonian splits as
//!
//!   H = H_K + H_I,  H_K = ½η_{N−1}|v′₀|² + Σ_{i≥1} (½m′ᵢ|v′ᵢ|² − Gm′ᵢηᵢ/|x′ᵢ|),
//!   H_I = −G Σ_{i<j} mᵢmⱼ/|xᵢ − xⱼ| + G Σ_{i≥1} mᵢηᵢ₋₁/|x′ᵢ|,
//!
//! H_K a sum of independent Kepler problems ([`kepler_drift`], μᵢ = Gηᵢ) and H_I of order
//! ε = m_planets/m₀ relative to it, a function of the positions alone
//! ([`interaction_accelerations`]). The Wisdom–Holman kernel (Wisdom & Holman 1991)
//! K(h/2) I(h) K(h/2) is symplectic, symmetric and of order 2 with error O(εh²), and the
//! [`corrector`] of Wisdom, Holman & Touma (1996) conjugating it removes the O(εhᵏ) terms up to
//! its order.

use serde::{Deserialize, Serialize};
mod corrector;
mod interaction;
mod jacobi;
mod kepler;
mod kernel;
mod stumpff;

pub use corrector::corrector;
pub use interaction::interaction_accelerations;
pub use jacobi::Jacobi;
pub use kepler::kepler_drift;
pub use kernel::Kernel;
pub use stumpff::{stumpff, universal_functions};

use super::checkpoint::derived::{same, Reached};
use super::{Increment, StepStart};
use crate::error::StepError;
use crate::model::NBody;
use kernel::{Variables, Work};

/// A Wisdom–Holman method with the symplectic corrector of Wisdom, Holman & Touma (1996) of a
/// given order, keeping its own (corrected, Jacobi) variables from step to step as WHFast does
/// with `safe_mode = 0` (Rein & Tamayo 2015, §4):
///
///   (q, p)ₙ = J⁻¹ C⁻¹ K(h/2) [I(h) K(h)]ⁿ⁻¹ I(h) K(h/2) C J (q, p)₀,
///
/// J the map to Jacobi coordinates, K and I the Kepler drift and interaction kick, C the
/// corrector: the inner variables w = [I(h)K(h)]ⁿ⁻¹I(h)K(h/2)CJ(q, p)₀ advance by one drift
/// and one kick a step (one force evaluation), and (q, p) are their image J⁻¹C⁻¹K(h/2)w, made
/// on a copy ([`WisdomHolman::synchronise`]) so that reading the state does not change the
/// steps that follow. The increments are added with compensated summation when asked.
///
/// A step allocates nothing.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WisdomHolman {
    kernel: Kernel,
    #[serde(with = "corrector::by_order")]
    corrector: &'static [(f64, f64)],
    /// The masses of the model the inner variables belong to; `None` until the first step.
    jacobi: Option<Jacobi>,
    /// The inner variables w, valid while `loaded`, for the step `h`.
    inner: Variables,
    /// w before the last step, restored when a step fails.
    last_good: Variables,
    /// Work copy for synchronisation.
    image: Variables,
    work: Work,
    h: f64,
    loaded: bool,
    compensated: bool,
    evaluations: u64,
}

impl WisdomHolman {
    /// The method with `kernel` and the corrector of `order` (see [`corrector`]) for `n` = 3N
    /// coordinates; None for an order without coefficients.
    pub fn new(kernel: Kernel, order: u32, n: usize) -> Option<Self> {
        let bodies = n / 3;
        Some(WisdomHolman {
            kernel,
            corrector: corrector(order)?,
            jacobi: None,
            inner: Variables::new(bodies),
            last_good: Variables::new(bodies),
            image: Variables::new(bodies),
            work: Work::new(bodies),
            h: f64::NAN,
            loaded: false,
            compensated: true,
            evaluations: 0,
        })
    }

    /// Holds the Jacobi coordinates' place, as after a first step (a template of the state's
    /// shape: their values are set by the next step's model).
    pub(in crate::integrators) fn prepare(&mut self, n: usize) {
        self.jacobi = Some(Jacobi::sized(n / 3));
    }

    /// Why a decoded state's derived values are not its own (see `checkpoint/derived.rs`), if
    /// they are not: its Jacobi masses and parameters the model's, and its inner variables,
    /// while valid, those whose image is the state's (q, p), to the bit.
    pub(in crate::integrators) fn misfit(&self, model: &NBody, at: &Reached<'_>) -> Option<String> {
        if self.jacobi.as_ref().is_some_and(|j| *j != Jacobi::new(model)) {
            return Some("its Jacobi masses and parameters are not the model's".to_string());
        }
        if !self.loaded {
            return None;
        }
        let (mut own, mut q, mut p) = (self.clone(), vec![0.0; at.q.len()], vec![0.0; at.p.len()]);
        own.synchronise(&mut q, &mut p);
        (!(same(&q, at.q) && same(&p, at.p))).then(|| {
            "its inner variables (the Jacobi coordinates it steps) are not those of its state (q, p)".to_string()
        })
    }

    /// Forgets the inner variables: the next step starts from the (q, p) it is given.
    pub fn reset(&mut self) {
        self.loaded = false;
    }

    /// Interaction kicks (evaluations of the pairwise forces) made so far.
    pub fn force_evaluations(&self) -> u64 {
        self.evaluations
    }

    /// Whether the inner variables are valid, so that [`WisdomHolman::synchronise`] has
    /// something to show.
    pub fn is_loaded(&self) -> bool {
        self.loaded
    }

    /// One step of size h of `model`. The inner variables continue from the last step when
    /// they are valid for this model and h; otherwise they start from (q, p): w = K(h/2)CJ(q, p)
    /// (the corrector's 2·order/… kicks counted). A step that makes them non-finite restores
    /// them and fails.
    pub fn step(&mut self, model: &NBody, q: &[f64], p: &[f64], h: f64, compensated: bool) -> Result<(), StepError> {
        let jacobi = match &mut self.jacobi {
            Some(j) if j.is_of(model) => j,
            Some(j) if j.bodies() == model.masses().len() => {
                j.set_model(model);
                self.loaded = false;
                j
            }
            slot => {
                self.loaded = false;
                slot.insert(Jacobi::new(model))
            }
        };
        let continuing = self.loaded && h == self.h && compensated == self.compensated;
        if continuing {
            self.last_good.copy_from(&self.inner);
            self.inner.drift(jacobi, h, compensated);
        } else {
            let w = &mut self.inner;
            jacobi.from_cartesian(q, p, &mut w.x, &mut w.v);
            w.ex.fill([0.0; 3]);
            w.ev.fill([0.0; 3]);
            self.evaluations += apply_corrector(w, jacobi, self.corrector, h, 1.0, compensated, &mut self.work);
            w.drift(jacobi, 0.5 * h, compensated);
            (self.h, self.compensated) = (h, compensated);
        }
        self.inner
            .kernel_kick(self.kernel, jacobi, h, compensated, &mut self.work);
        self.evaluations += self.kernel.force_evaluations();
        if self.inner.is_finite() {
            self.loaded = true;
            Ok(())
        } else {
            if continuing {
                self.inner.copy_from(&self.last_good);
            } else {
                self.loaded = false;
            }
            Err(StepError::NonFinite {
                reason: "the Wisdom–Holman step became non-finite (a close encounter, or a step beyond the orbits' \
                         periods)",
            })
        }
    }

    /// Writes the image (q, p) = J⁻¹C⁻¹K(h/2)w of the inner variables, computed on a copy; does
    /// nothing before the first step.
    pub fn synchronise(&mut self, q: &mut [f64], p: &mut [f64]) {
        let Some(jacobi) = &self.jacobi else { return };
        if !self.loaded {
            return;
        }
        let (h, compensated) = (self.h, self.compensated);
        let w = &mut self.image;
        w.copy_from(&self.inner);
        w.drift(jacobi, 0.5 * h, compensated);
        self.evaluations += apply_corrector(w, jacobi, self.corrector, h, -1.0, compensated, &mut self.work);
        // The carries hold the bits the sums lost.
        for (x, e) in w.x.iter_mut().zip(&w.ex).chain(w.v.iter_mut().zip(&w.ev)) {
            for k in 0..3 {
                x[k] += e[k];
            }
        }
        jacobi.to_cartesian(&w.x, &w.v, q, p);
    }

    /// One step from `start` written as increments, starting afresh from (q, p) (the
    /// corrected map J⁻¹C⁻¹K(h/2)I(h)K(h/2)CJ): for callers that take one step at a time from
    /// states of their own, the symplecticity check among them.
    pub fn increment(&mut self, model: &NBody, start: &StepStart, increment: &mut Increment) -> Result<(), StepError> {
        self.loaded = false;
        self.step(model, start.q, start.p, start.h, false)?;
        let Increment { dq, dp } = increment;
        self.synchronise(dq, dp);
        self.loaded = false;
        for (d, x) in dq.iter_mut().zip(start.q).chain(dp.iter_mut().zip(start.p)) {
            *d -= x;
        }
        Ok(())
    }
}

/// Applies the corrector C (`sign` = 1) or its inverse (`sign` = −1) to w; returns the kicks made.
fn apply_corrector(
    w: &mut Variables,
    jacobi: &Jacobi,
    pairs: &[(f64, f64)],
    h: f64,
    sign: f64,
    compensated: bool,
    work: &mut Work,
) -> u64 {
    for &(a, b) in pairs {
        let (a, b) = (a * h, sign * b * h);
        w.drift(jacobi, a, compensated);
        w.kick(jacobi, -b, compensated, work);
        w.drift(jacobi, -2.0 * a, compensated);
        w.kick(jacobi, b, compensated, work);
        w.drift(jacobi, a, compensated);
    }
    2 * pairs.len() as u64
}
