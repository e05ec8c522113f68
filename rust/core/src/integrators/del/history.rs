//! The run's own past for delayed forces: the state at each step's force node (the two-point
//! rules' midpoint), kept in a ring long enough for the longest delay, and read back at t − τ.

use serde::{Deserialize, Serialize};

use crate::model::Lagrangian;
use crate::solve::copy;
use crate::ModelError;

/// The states (q̄, v̄) at the force nodes of the last steps, oldest first, in a ring of `len`
/// nodes; with the buffers of one evaluation of the delayed forces.
///
/// The state τ ago is a node's own state where t − τ falls on a node (τ a whole number of
/// steps: exact, the method's own values), else the cubic Hermite interpolant of the two nodes
/// about it (their q̄ and v̄). Before the run's first node the model's history gives it where
/// the model has one ([`Lagrangian::history`]); otherwise nothing is known, and a term whose
/// past does not exist acts only once it does, as the source insists.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct History {
    n: usize,
    q: Vec<f64>,
    v: Vec<f64>,
    times: Vec<f64>,
    /// The ring's oldest node, and how many it holds (values, not sizes: taken modulo its
    /// length, so that a crafted checkpoint cannot index past it).
    head: usize,
    filled: usize,
    /// [q, q(t − τ₁) …] and [v, v(t − τ₁) …], the delayed forces' arguments, and their
    /// values [Q, the term of τ₁ …], Q's block then overwritten by the sum of the terms acting
    /// (kept for the step's later evaluations: no state of its own to checkpoint).
    past_q: Vec<f64>,
    past_v: Vec<f64>,
    terms: Vec<f64>,
    /// Whether each term's past exists at this evaluation.
    acting: Vec<bool>,
    /// The time whose past the arguments hold (NaN: none): a step evaluates its forces at one
    /// node many times (Newton's iterations, a differenced Jacobian), its past read once, and
    /// the delayed terms too where they read the past alone.
    #[serde(skip, default = "no_past")]
    read_at: f64,
}

fn no_past() -> f64 {
    f64::NAN
}

impl History {
    /// A history for n coordinates, the delays `delays` and the step h: it holds the
    /// longest delay's ⌈τ/h⌉ steps and two more, for the interpolant.
    pub(super) fn new(n: usize, delays: &[f64], h: f64) -> Self {
        let longest = delays.iter().fold(0.0_f64, |a, &b| a.max(b));
        let len = (longest / h).ceil() as usize + 2;
        let d = delays.len();
        History {
            n,
            q: vec![0.0; len * n],
            v: vec![0.0; len * n],
            times: vec![0.0; len],
            head: 0,
            filled: 0,
            past_q: vec![0.0; (1 + d) * n],
            past_v: vec![0.0; (1 + d) * n],
            terms: vec![0.0; (1 + d) * n],
            acting: vec![false; d],
            read_at: no_past(),
        }
    }

    fn len(&self) -> usize {
        self.times.len()
    }

    /// The ring's slot of the node i < len (0 the oldest), for head < len (see `state_at`).
    fn slot(&self, i: usize) -> usize {
        let i = self.head + i;
        if i >= self.len() {
            i - self.len()
        } else {
            i
        }
    }

    /// Brings `head` into the ring: a value a checkpoint brings may lie past it. A division
    /// only then, not at every read and record.
    fn settle(&mut self) {
        if self.head >= self.len() {
            self.head %= self.len();
        }
    }

    fn held(&self) -> usize {
        self.filled.min(self.len())
    }

    /// Writes the force at the node (q, v, t) into `f`: Q and each delayed term whose past
    /// exists.
    pub(super) fn forces<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        (q, v, t): (&[f64], &[f64], f64),
        f: &mut [f64],
    ) -> Result<(), ModelError> {
        let n = self.n;
        if t != self.read_at {
            for (j, tau) in sys.delays().iter().enumerate() {
                self.acting[j] = self.state_at(sys, t - tau, j)?;
            }
            self.read_at = t;
        } else if sys.delayed_of_past_alone() {
            sys.force(q, v, t, f)?;
            f.iter_mut().zip(&self.terms[..n]).for_each(|(f, d)| *f += d);
            return Ok(());
        }
        copy(&mut self.past_q[..n], q);
        copy(&mut self.past_v[..n], v);
        sys.delayed_force(&self.past_q, &self.past_v, t, &mut self.terms)?;
        // f = Q + the sum of the terms acting, which Q's block then keeps.
        let (sum, terms) = self.terms.split_at_mut(n);
        for (i, (f, sum)) in f.iter_mut().zip(sum).enumerate() {
            let acting = terms[i..].iter().step_by(n).zip(&self.acting).filter(|(_, on)| **on);
            let now = *sum;
            *sum = acting.fold(0.0, |s, (x, _)| s + x);
            *f = now + *sum;
        }
        Ok(())
    }

    /// Writes the state at time s into the block j + 1 of the arguments; false where s is
    /// before the run's first node and the model gives no history. Refuses a history that no
    /// longer reaches s (a step made smaller since the ring was sized).
    fn state_at<S: Lagrangian + ?Sized>(&mut self, sys: &S, s: f64, j: usize) -> Result<bool, ModelError> {
        self.settle();
        let (n, held) = (self.n, self.held());
        let block = (j + 1) * n;
        let before = |this: &mut Self| {
            sys.history(
                s,
                &mut this.past_q[block..block + n],
                &mut this.past_v[block..block + n],
            )
        };
        if held == 0 {
            return before(self);
        }
        let time = |i: usize| self.times[self.slot(i)];
        let first = time(0);
        let spacing = if held > 1 { time(1) - first } else { 0.0 };
        let tolerance = 1e-9 * spacing.abs().max(f64::MIN_POSITIVE);
        if s < first - tolerance {
            if self.filled > self.len() {
                return Err(format!(
                    "delays: the history of {} steps no longer reaches t − τ = {s} (the step was made smaller \
                     than the run's first; keep dt)",
                    self.len()
                )
                .into());
            }
            return before(self);
        }
        // The last node at or before s: the nodes are a step apart (the step is kept), so its
        // index is the quotient, corrected by one either way for round-off in the times.
        let last = held - 1;
        // The cast truncates: the floor of a quotient ≥ 0, and 0 for one just below it as the
        // floor's −1 would saturate to; without `floor`, which is a call to libm on x86-64.
        let guess = if spacing > 0.0 {
            ((s - first) / spacing + 1e-9) as usize
        } else {
            0
        };
        let mut lo = guess.min(last);
        if lo > 0 && time(lo) > s + tolerance {
            lo -= 1;
        } else if lo < last && time(lo + 1) <= s + tolerance {
            lo += 1;
        }
        let a = self.slot(lo) * n;
        if (time(lo) - s).abs() <= tolerance || lo + 1 >= held {
            copy(&mut self.past_q[block..block + n], &self.q[a..a + n]);
            copy(&mut self.past_v[block..block + n], &self.v[a..a + n]);
            return Ok(true);
        }
        let b = self.slot(lo + 1) * n;
        let (t0, t1) = (time(lo), time(lo + 1));
        let h = t1 - t0;
        let x = (s - t0) / h;
        // Cubic Hermite basis and its derivative (per unit time).
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * x) * (1.0 - x) * (1.0 - x),
            x * (1.0 - x) * (1.0 - x),
            x * x * (3.0 - 2.0 * x),
            x * x * (x - 1.0),
        );
        let (d00, d10, d01, d11) = (
            6.0 * x * (x - 1.0) / h,
            (1.0 - x) * (1.0 - 3.0 * x),
            6.0 * x * (1.0 - x) / h,
            x * (3.0 * x - 2.0),
        );
        for k in 0..n {
            let (q0, v0, q1, v1) = (self.q[a + k], self.v[a + k], self.q[b + k], self.v[b + k]);
            self.past_q[block + k] = h00 * q0 + h10 * h * v0 + h01 * q1 + h11 * h * v1;
            self.past_v[block + k] = d00 * q0 + d10 * v0 + d01 * q1 + d11 * v1;
        }
        Ok(true)
    }

    /// Records the node (q, v, t) of a step taken, the oldest one leaving a full ring.
    pub(super) fn record(&mut self, q: &[f64], v: &[f64], t: f64) {
        let n = self.n;
        self.settle();
        let slot = if self.filled < self.len() {
            self.slot(self.filled)
        } else {
            let oldest = self.head;
            self.head = self.slot(1);
            oldest
        };
        copy(&mut self.q[slot * n..(slot + 1) * n], q);
        copy(&mut self.v[slot * n..(slot + 1) * n], v);
        self.times[slot] = t;
        self.filled = self.filled.saturating_add(1);
        self.read_at = no_past();
    }
}
