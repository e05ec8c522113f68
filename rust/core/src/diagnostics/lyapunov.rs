//! Lyapunov exponents from the method's own tangent map (Benettin, Galgani, Giorgilli &
//! Strelcyn 1980): k tangent vectors carried along a run by the step's exact linearization
//! ([`Tangent`]), re-orthonormalized by a QR factorization every few steps, the logarithms of
//! R's diagonal summed.

use crate::error::check_vector;
use crate::integrators::{Dynamics, Method, Options, Poll, Stepper, Tangent};
use crate::solve::interrupt::InterruptPoll;
use crate::Error;

/// What [`lyapunov`] is asked: `steps` steps of size `dt` from time `t0`, `k` tangent vectors
/// (1 ≤ k ≤ 2n; 2n for the full spectrum), re-orthonormalized every `every` ≥ 1 steps.
#[derive(Clone, Copy, Debug)]
pub struct LyapunovOptions {
    pub t0: f64,
    pub dt: f64,
    pub steps: usize,
    pub k: usize,
    pub every: usize,
}

/// The stretching of k tangent vectors along a run: at each re-orthonormalization its time
/// `t` and the sums Σ ln Rⱼⱼ of the QR factorizations so far (`sums`, one row of k a time),
/// so that λⱼ(t) = sums/(t − t₀), in decreasing order for a long enough run; with the run's
/// end (q, p) and the tangent map's evaluations of ∇V and H.
#[derive(Clone, Debug)]
pub struct Stretching {
    pub k: usize,
    pub t: Vec<f64>,
    pub sums: Vec<f64>,
    pub q: Vec<f64>,
    pub p: Vec<f64>,
    pub evaluations: u64,
}

/// A vector past this is re-orthonormalized at once, before its growth can overflow.
const LARGE: f64 = 1e100;

/// The stretching of k tangent vectors along the run of `method` on `sys` from (q0, p0): each
/// step taken as a [`Stepper`] takes it (the run's states are the plain run's, bit for bit),
/// the vectors carried by the step's tangent map from its start. They start orthonormal, in
/// fixed pseudo-random directions (none is special to a model), and are re-orthonormalized
/// (modified Gram–Schmidt, twice) every `options.every` steps, at the run's end, and whenever
/// one grows past 10¹⁰⁰. `poll` is called every 10–40 ms.
///
/// # Errors
/// Invalid arguments, naming them (k outside 1 … 2n, `every` = 0, a model that is not
/// separable or a method without a tangent map); the model's errors and the run's, with the
/// step and time; [`Error::Interrupted`] from `poll`.
pub fn lyapunov<S: Dynamics + ?Sized, P: Poll>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &LyapunovOptions,
    mut poll: P,
) -> Result<Stretching, Error> {
    let n = sys.dim();
    check_vector("q0", q0, n)?;
    check_vector("p0", p0, n)?;
    let LyapunovOptions {
        t0,
        dt,
        steps,
        k,
        every,
    } = *options;
    if !(1..=2 * n).contains(&k) {
        let reason = format!("must be 1 … {} (the phase space's dimension 2n), got {k}", 2 * n);
        return Err(Error::invalid("k", reason));
    }
    if every == 0 {
        return Err(Error::invalid(
            "every",
            "must be at least 1 (steps between re-orthonormalizations)",
        ));
    }
    let mut tangent = Tangent::new(method, sys)?;
    let run = Options {
        t0,
        ..Options::new(dt, steps)
    };
    let mut stepper = Stepper::new(sys, method, q0, p0, &run)?;
    let dim = 2 * n;
    let mut x = start_vectors(dim, k);
    let mut row = vec![0.0; k];
    orthonormalize(&mut x, dim, &mut row);
    row.fill(0.0);
    let rows = steps / every + 2;
    let mut stretching = Stretching {
        k,
        t: Vec::with_capacity(rows),
        sums: Vec::with_capacity(rows * k),
        q: q0.to_vec(),
        p: p0.to_vec(),
        evaluations: 0,
    };
    let mut interrupt = InterruptPoll::new();
    for step in 1..=steps {
        let time = stepper.t();
        if interrupt.due() {
            poll.poll(step - 1)
                .map_err(|source| Error::Interrupted { step, time, source })?;
        }
        stepper.step_with_tangent(&mut tangent, &mut x)?;
        if step % every == 0 || step == steps || x.iter().any(|v| v.abs() > LARGE) {
            orthonormalize(&mut x, dim, &mut row);
            stretching.t.push(stepper.t());
            stretching.sums.extend_from_slice(&row);
        }
    }
    stretching.q.copy_from_slice(stepper.q());
    stretching.p.copy_from_slice(stepper.p());
    stretching.evaluations = tangent.evaluations();
    Ok(stretching)
}

/// k vectors of `dim` components in fixed pseudo-random directions (SplitMix64, uniform in
/// [−1, 1)), column-major: independent of any model's coordinates.
fn start_vectors(dim: usize, k: usize) -> Vec<f64> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    (0..dim * k)
        .map(|_| {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

/// The k columns of `x` (each of `dim`) orthonormalized in order by modified Gram–Schmidt,
/// each projection done twice (its R to working precision), ln Rⱼⱼ added to `sums[j]`.
fn orthonormalize(x: &mut [f64], dim: usize, sums: &mut [f64]) {
    for (j, sum) in sums.iter_mut().enumerate() {
        let (before, rest) = x.split_at_mut(j * dim);
        let column = &mut rest[..dim];
        for _ in 0..2 {
            for other in before.chunks_exact(dim) {
                let r = dot(other, column);
                column.iter_mut().zip(other).for_each(|(c, o)| *c -= r * o);
            }
        }
        let norm = dot(column, column).sqrt();
        *sum += norm.ln();
        column.iter_mut().for_each(|c| *c /= norm);
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
