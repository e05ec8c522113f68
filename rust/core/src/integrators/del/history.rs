//! The run's own past for delayed forces: the state at each step's force node (the two-point
//! rules' midpoint), kept in a ring long enough for the longest delay, and read back at t − τ.

use serde::{Deserialize, Serialize};

use crate::model::{delayed_block, Lagrangian};
use crate::solve::copy;
use crate::ModelError;

/// The states (q̄, v̄) at the force nodes of the last steps, oldest first, in a ring of `len`
/// nodes; with the buffers of one evaluation of the delayed forces.
///
/// The step is kept while the history lives (a delayed model's stepper refuses another), so
/// the nodes are a step apart and t − τ lies a fixed number of nodes back ([`Lag`]): on a node
/// where τ is a whole number of steps (exact, the method's own values), else between two, read
/// through the cubic Hermite interpolant of their q̄ and v̄. The acceleration, for a term that
/// reads it, is the derivative of the parabola through the velocities of the three nodes about
/// t − τ ([`Rate`]). Before the nodes a term reads exist, the model's history gives its past
/// where the model has one ([`Lagrangian::history`]); otherwise nothing is known, and a term
/// whose past does not exist acts only once it does, as the source insists.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct History {
    n: usize,
    q: Vec<f64>,
    v: Vec<f64>,
    /// The ring's oldest node, and how many it holds (values, not sizes: taken modulo its
    /// length, so that a crafted checkpoint cannot index past it).
    head: usize,
    filled: usize,
    /// The ring's length in nodes, q.len()/n: kept so that a step divides by n only once a
    /// restored history's life (0 until `settle` takes it).
    #[serde(skip)]
    len: usize,
    /// Where each delay's past lies, from τ and the step.
    lags: Vec<Lag>,
    /// Whether the delayed terms read the past alone ([`Lagrangian::delayed_of_past_alone`]).
    past_alone: bool,
    /// The delayed forces' values [Q, the term of τ₁ …], Q's block then overwritten by the sum
    /// of the terms acting (kept for the step's later evaluations: no state of its own to
    /// checkpoint).
    terms: Vec<f64>,
    /// Whether each term's past exists at this evaluation.
    acting: Vec<bool>,
    /// The time whose past the arguments hold (NaN: none): a step evaluates its forces at one
    /// node many times (Newton's iterations, a differenced Jacobian), its past read once, and
    /// the delayed terms too where they read the past alone.
    #[serde(skip, default = "no_past")]
    read_at: f64,
}

/// Where t − τ lies for τ = (steps − x)·h with x ∈ [0, 1): `steps` nodes back from the step's
/// own force node where x = 0, else between the nodes `steps` and `steps − 1` back, at x from
/// the older, where the interpolant's basis, the same at every step, is `hermite`; and, for a
/// term that reads the acceleration, how it is taken.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Lag {
    steps: usize,
    hermite: Option<Hermite>,
    rate: Option<Rate>,
}

/// The acceleration at t − τ from the velocities v̄ of the nodes `back` + 1, `back` and
/// `back` − 1 steps back (the node nearest t − τ and its neighbours), at y ∈ [−½, ½] steps from
/// the middle one: the derivative of the parabola through them, ((y − ½)v̄₋ − 2y v̄₀ + (y + ½)v̄₊)/h,
/// which `weights` hold. It is the linear interpolant of the second differences
/// (v̄ₖ₊₁ − v̄ₖ)/h = (qₖ₊₂ − 2qₖ₊₁ + qₖ)/h², the discrete Euler–Lagrange equations' own
/// acceleration, at the grid times between the nodes: O(h²), the method's order.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Rate {
    back: usize,
    weights: [f64; 3],
}

/// The cubic Hermite basis at x ∈ (0, 1) of an interval of length h: the value's weights of
/// (q₀, v₀, q₁, v₁), then the derivative's.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Hermite {
    value: [f64; 4],
    rate: [f64; 4],
}

impl Hermite {
    fn at(x: f64, h: f64) -> Self {
        Hermite {
            value: [
                (1.0 + 2.0 * x) * (1.0 - x) * (1.0 - x),
                x * (1.0 - x) * (1.0 - x) * h,
                x * x * (3.0 - 2.0 * x),
                x * x * (x - 1.0) * h,
            ],
            rate: [
                6.0 * x * (x - 1.0) / h,
                (1.0 - x) * (1.0 - 3.0 * x),
                6.0 * x * (1.0 - x) / h,
                x * (3.0 * x - 2.0),
            ],
        }
    }
}

impl Lag {
    /// The lag of τ at the step h (τ ≥ h, and τ ≥ 3h/2 for one that reads the acceleration,
    /// whose newest node must have been taken): a whole number of steps where τ/h is one to
    /// within its round-off (10⁻⁹ of it, and of a step at least).
    fn new(tau: f64, h: f64, acceleration: bool) -> Self {
        let steps = tau / h;
        let whole = steps.round();
        let (steps, x) = if (steps - whole).abs() <= 1e-9 * whole.max(1.0) {
            (whole, 0.0)
        } else {
            (steps.ceil(), steps.ceil() - steps)
        };
        let rate = acceleration.then(|| {
            // The tolerance takes τ = 3h/2 to its node whatever τ/h rounds to.
            let (back, y) = if x <= 0.5 + 1e-9 {
                (steps, x)
            } else {
                (steps - 1.0, x - 1.0)
            };
            Rate {
                back: back as usize,
                weights: [(y - 0.5) / h, -2.0 * y / h, (y + 0.5) / h],
            }
        });
        Lag {
            steps: steps as usize,
            hermite: (x > 0.0).then(|| Hermite::at(x, h)),
            rate,
        }
    }

    /// The most nodes back the lag reads.
    fn reach(&self) -> usize {
        self.rate.as_ref().map_or(self.steps, |rate| rate.back + 1)
    }
}

/// Refuses a delay that the history cannot read at the step h, naming `delays`: one shorter
/// than the step (the history holds whole steps), or, for a term that reads the acceleration,
/// than 3h/2 (the velocity a node after the one nearest t − τ must be known before the step).
///
/// Refuses too, naming `delays`, a history longer than the memory available: it holds the
/// longest delay's τ/h steps of (q̄, v̄), 2n floats a step ([`crate::memory::check_allocation`]),
/// and a long delay at a short step (τ = 10¹⁰ at h = 0.01: 10¹² steps) would abort the process
/// at its allocation.
pub(in crate::integrators) fn check_delays(sys: &dyn Lagrangian, h: f64) -> Result<(), crate::Error> {
    let longest = sys.delays().iter().fold(0.0_f64, |a, &tau| a.max(tau));
    // The ring's nodes, as `History::new` counts them: ⌈τ/h⌉, one more for the acceleration's
    // neighbour, and two.
    let nodes = (longest / h).ceil() + 3.0;
    let bytes = 2 * sys.dim().max(1) * std::mem::size_of::<f64>();
    // A count past usize (τ/h of 10³⁰⁰) is refused as one beyond the address space.
    let count = if nodes < usize::MAX as f64 {
        nodes as usize
    } else {
        usize::MAX
    };
    if let Err(crate::Error::InvalidArgument { reason, .. }) = crate::memory::check_allocation("delays", count, bytes) {
        let reason = format!(
            "{reason}: the history of τ = {longest:e} holds τ/dt = {:.3e} past states at dt = {h:e}; take a \
             larger dt or a shorter τ",
            longest / h
        );
        return Err(crate::Error::invalid("delays", reason));
    }
    for (j, &tau) in sys.delays().iter().enumerate() {
        if tau < h {
            let reason =
                format!("τ = {tau} is shorter than the step dt = {h}: the history holds whole steps; take dt ≤ τ");
            return Err(crate::Error::invalid("delays", reason));
        }
        if (Lag::new(tau, h, sys.delayed_reads_acceleration(j)).rate).is_some_and(|rate| rate.back < 2) {
            let reason = format!(
                "τ = {tau} reads q̈(t − τ) and is shorter than 1.5 steps dt = {h}: the acceleration comes from \
                 the velocities on either side of t − τ, the newer a step old at least; take dt ≤ τ/1.5"
            );
            return Err(crate::Error::invalid("delays", reason));
        }
    }
    Ok(())
}

fn no_past() -> f64 {
    f64::NAN
}

impl History {
    /// A history for n coordinates and the delayed forces of `sys` at the step h: it holds
    /// the longest delay's ⌈τ/h⌉ steps and two more.
    pub(super) fn new<S: Lagrangian + ?Sized>(n: usize, sys: &S, h: f64) -> Self {
        let delays = sys.delays();
        let lags: Vec<Lag> = (delays.iter().enumerate())
            .map(|(j, &tau)| Lag::new(tau, h, sys.delayed_reads_acceleration(j)))
            .collect();
        let len = lags.iter().map(Lag::reach).max().unwrap_or(0) + 2;
        let d = delays.len();
        History {
            n,
            q: vec![0.0; len * n],
            v: vec![0.0; len * n],
            head: 0,
            filled: 0,
            len,
            lags,
            past_alone: sys.delayed_of_past_alone(),
            terms: vec![0.0; (1 + d) * n],
            acting: vec![false; d],
            read_at: no_past(),
        }
    }

    /// The ring's slot of the node i < len (0 the oldest), for head < len (see `settle`).
    fn slot(&self, i: usize) -> usize {
        let i = self.head + i;
        if i >= self.len {
            i - self.len
        } else {
            i
        }
    }

    /// Brings `head` into the ring: a value a checkpoint brings may lie past it. A division
    /// only then, not at every read and record. Takes the ring's length where a checkpoint
    /// left it out.
    fn settle(&mut self) {
        if self.len == 0 {
            self.len = self.q.len() / self.n;
        }
        if self.head >= self.len {
            self.head %= self.len;
        }
    }

    /// Writes the force at the node `state` into `f`: Q and each delayed term whose past
    /// exists. `state` holds the node's slots as [`Lagrangian::delayed_force`] reads them
    /// ([`delayed_block`]); the past blocks are written here.
    pub(super) fn forces<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        state: &mut [f64],
        f: &mut [f64],
    ) -> Result<(), ModelError> {
        let (n, m) = (self.n, delayed_block(state.len()));
        let t = state[3 * m];
        if t != self.read_at {
            self.settle();
            let (q, rest) = state.split_at_mut(m);
            let (v, a) = rest.split_at_mut(m);
            // The blocks after the state now's, one a delay.
            let past = (q[n..].chunks_exact_mut(n))
                .zip(v[n..].chunks_exact_mut(n))
                .zip(a[n..m].chunks_exact_mut(n));
            for (j, (tau, ((q, v), a))) in sys.delays().iter().zip(past).enumerate() {
                self.acting[j] = self.state_at(sys, t - tau, j, (q, v, a))?;
            }
            self.read_at = t;
        } else if self.past_alone {
            sys.force(&state[..n], &state[m..m + n], t, f)?;
            f.iter_mut().zip(&self.terms[..n]).for_each(|(f, d)| *f += d);
            return Ok(());
        }
        sys.delayed_force(state, &mut self.terms)?;
        // f = Q + the sum of the terms acting, which Q's block then keeps.
        let (sum, terms) = self.terms.split_at_mut(n);
        for i in 0..n {
            let mut acting = 0.0;
            for (j, on) in self.acting.iter().enumerate() {
                if *on {
                    acting += terms[j * n + i];
                }
            }
            f[i] = sum[i] + acting;
            sum[i] = acting;
        }
        Ok(())
    }

    /// Writes the state at s = t − τⱼ into `(q, v, a)` (the acceleration for a term that reads
    /// it); false where a node it reads is before the run's first and the model gives no
    /// history.
    fn state_at<S: Lagrangian + ?Sized>(
        &self,
        sys: &S,
        s: f64,
        j: usize,
        (q, v, acceleration): (&mut [f64], &mut [f64], &mut [f64]),
    ) -> Result<bool, ModelError> {
        let n = self.n;
        // The step's own force node would be the held + 1st: the past lies `steps` nodes back
        // from it, the interpolant's newer node one after, the acceleration's `back` ± 1. None
        // so far back: before the run.
        let held = self.filled.min(self.len);
        let lag = &self.lags[j];
        if held < lag.reach() {
            return sys.history(s, q, v, acceleration);
        }
        if let Some(Rate { back, weights: w }) = &lag.rate {
            let [older, node, newer] = [back + 1, *back, back - 1].map(|k| self.slot(held - k) * n);
            for (k, a) in acceleration.iter_mut().enumerate() {
                *a = w[0] * self.v[older + k] + w[1] * self.v[node + k] + w[2] * self.v[newer + k];
            }
        }
        let a = held - lag.steps;
        let (b, a) = ((a + 1).min(held - 1), self.slot(a) * n);
        let Some(Hermite { value, rate }) = &lag.hermite else {
            copy(q, &self.q[a..a + n]);
            copy(v, &self.v[a..a + n]);
            return Ok(true);
        };
        let b = self.slot(b) * n;
        for k in 0..n {
            let (q0, v0, q1, v1) = (self.q[a + k], self.v[a + k], self.q[b + k], self.v[b + k]);
            q[k] = value[0] * q0 + value[1] * v0 + value[2] * q1 + value[3] * v1;
            v[k] = rate[0] * q0 + rate[1] * v0 + rate[2] * q1 + rate[3] * v1;
        }
        Ok(true)
    }

    /// Records the node (q, v) of a step taken, from its `state` as [`History::forces`] takes
    /// it, the oldest one leaving a full ring.
    pub(super) fn record(&mut self, state: &[f64]) {
        let (n, m) = (self.n, delayed_block(state.len()));
        let (q, v) = (&state[..n], &state[m..m + n]);
        self.settle();
        let slot = if self.filled < self.len {
            self.slot(self.filled)
        } else {
            let oldest = self.head;
            self.head = self.slot(1);
            oldest
        };
        copy(&mut self.q[slot * n..(slot + 1) * n], q);
        copy(&mut self.v[slot * n..(slot + 1) * n], v);
        self.filled = self.filled.saturating_add(1);
        self.read_at = no_past();
    }
}
