//! The state as a method's own loop advances it ([`Phase`]); what that loop checks after each
//! step is a [`crate::integrators::Clear`].

use super::{diverged, Clock};
use crate::integrators::clear::Clear;
use crate::integrators::{compensated, StepError};
use crate::Error;

/// A stepper's state as a method's own loop advances it: (qₙ, pₙ), the carries (e_q, e_p) of
/// compensated summation, and the steps done, counted up as the loop goes; `start_q`,
/// `start_p` receive the start of a step found not clear (see [`Phase::run`]).
pub(in crate::integrators) struct Phase<'a> {
    pub(in crate::integrators) q: &'a mut [f64],
    pub(in crate::integrators) p: &'a mut [f64],
    pub(in crate::integrators) eq: &'a mut [f64],
    pub(in crate::integrators) ep: &'a mut [f64],
    pub(in crate::integrators) start_q: &'a mut [f64],
    pub(in crate::integrators) start_p: &'a mut [f64],
    pub(in crate::integrators) compensated: bool,
    pub(in crate::integrators) steps: &'a mut usize,
    pub(in crate::integrators) clock: Clock,
}

impl Phase<'_> {
    /// `steps` steps of N coordinates with the state in fixed-size arrays: `increment(t, q, p,
    /// δq, δp)` writes each step's increments, which are added as [`StepperState::step`] adds
    /// them (the same bits), in one loop with no dispatch. Stops at the first failure, dated
    /// as the stepper dates it, with the last good state kept; and after the first step whose
    /// end q is not `clear`, kept, its start written to (`start_q`, `start_p`): true then. The
    /// loop of the methods' own fixed-size paths ([`super::KickDrift::run`], the DEL step's).
    #[inline(always)]
    pub(in crate::integrators) fn run<const N: usize, F, C>(
        self,
        steps: usize,
        mut increment: F,
        clear: &mut C,
    ) -> Result<bool, Error>
    where
        F: FnMut(f64, &[f64; N], &[f64; N], &mut [f64; N], &mut [f64; N]) -> Result<(), StepError>,
        C: Clear + ?Sized,
    {
        let Phase {
            q: state_q,
            p: state_p,
            eq: state_eq,
            ep: state_ep,
            start_q,
            start_p,
            compensated,
            steps: done,
            clock,
        } = self;
        let (mut q, mut p, mut eq, mut ep) = (array(state_q), array(state_p), array(state_eq), array(state_ep));
        let (mut dq, mut dp) = ([0.0; N], [0.0; N]);
        let (mut q_next, mut p_next, mut eq_next, mut ep_next) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        // The count in a local, written back once: through the pointer it would cost stores.
        let mut n = *done;
        let mut result = Ok(false);
        for _ in 0..steps {
            if let Err(e) = increment(clock.at(n), &q, &p, &mut dq, &mut dp) {
                result = Err(e.at(n + 1, clock.at(n)));
                break;
            }
            let finite = if compensated {
                compensated::add(&q, &eq, &dq, &mut q_next, &mut eq_next)
                    & compensated::add(&p, &ep, &dp, &mut p_next, &mut ep_next)
            } else {
                compensated::add_plain(&q, &dq, &mut q_next) & compensated::add_plain(&p, &dp, &mut p_next)
            };
            if !finite {
                result = Err(diverged(n + 1, clock.at(n)));
                break;
            }
            let stop = !clear.clear(&q_next, &p_next);
            if stop {
                start_q.copy_from_slice(&q);
                start_p.copy_from_slice(&p);
            }
            (q, p) = (q_next, p_next);
            if compensated {
                (eq, ep) = (eq_next, ep_next);
            }
            n += 1;
            if stop {
                result = Ok(true);
                break;
            }
        }
        *done = n;
        state_q.copy_from_slice(&q);
        state_p.copy_from_slice(&p);
        state_eq.copy_from_slice(&eq);
        state_ep.copy_from_slice(&ep);
        result
    }
}

/// The first N values of `x` as an array: the fixed-size loops' copy of a slice.
#[inline(always)]
pub(in crate::integrators) fn array<const N: usize>(x: &[f64]) -> [f64; N] {
    std::array::from_fn(|i| x[i])
}
