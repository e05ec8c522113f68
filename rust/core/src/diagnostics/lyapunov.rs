//! Lyapunov exponents from the method's own tangent map (Benettin, Galgani, Giorgilli &
//! Strelcyn 1980): k tangent vectors carried along a run by the step's exact linearization
//! ([`Tangent`]), re-orthonormalized by a QR factorization every few steps, the logarithms of
//! R's diagonal summed.

use crate::error::check_vector;
use crate::integrators::{Counting, Dynamics, Method, Options, Poll, Stepper, Tangent};
use crate::model::Lagrangian;
use crate::solve::{difference, sized, splitmix};
use crate::{Error, ModelError};

/// What [`lyapunov`] is asked: `steps` steps of size `dt` from time `t0`, `k` tangent vectors
/// (1 ≤ k ≤ 2n; 2n for the full spectrum), re-orthonormalized every `every` ≥ 1 steps, starting
/// from the columns (δq, δq̇) of `start` (2n × k, column-major) where given.
#[derive(Clone, Copy, Debug)]
pub struct LyapunovOptions<'a> {
    pub t0: f64,
    pub dt: f64,
    pub steps: usize,
    pub k: usize,
    pub every: usize,
    pub start: Option<&'a [f64]>,
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

/// The stretching of k tangent vectors along the run of `method` on `sys` from (q0, p0): the
/// steps taken as a [`Stepper`] takes them (the run's states are the plain run's, bit for bit),
/// the vectors carried by each step's tangent map from its start
/// ([`Stepper::advance_with_tangent_below`], inside the method's own loop where it has one). They start in fixed
/// pseudo-random directions of (δq, δq̇) (none special to a model), their δp the Legendre
/// transform's differential at (q0, p0), so that no small mass makes its velocity's
/// perturbation dominate (REBOUND's MEGNO starts so too); then they are orthonormal, and are
/// re-orthonormalized (modified Gram–Schmidt, twice) every `options.every` steps, at the run's
/// end, and whenever one grows past 10¹⁰⁰. `poll` is called every 10–40 ms.
///
/// A step that stretches the vectors past the largest float (10²⁰⁸ from 10¹⁰⁰: h·λ beyond
/// 480, a step far too long for the motion), or a column that contracts past the smallest
/// between re-orthonormalizations, stops the run with [`Error::Divergence`] saying what to
/// change: its exponents would be NaN.
///
/// # Errors
/// Invalid arguments, naming them (k outside 1 … 2n, `every` = 0, a model or method without a
/// tangent map, [`Tangent::new`]); the model's errors and the run's, with the step and time;
/// [`Error::Divergence`] for vectors that overflow or collapse (above); [`Error::Interrupted`]
/// from `poll`.
pub fn lyapunov<S: Dynamics + ?Sized, P: Poll>(
    sys: &S,
    method: Method,
    q0: &[f64],
    p0: &[f64],
    options: &LyapunovOptions<'_>,
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
        start,
    } = *options;
    let m = sys.holonomic().map_or(0, |c| c.count());
    if !(1..=2 * (n - m.min(n))).contains(&k) {
        let reason = match m {
            0 => format!("must be 1 … {} (the phase space's dimension 2n), got {k}", 2 * n),
            _ => format!(
                "must be 1 … {} (the constraint manifold's phase space, 2(n − m) for n = {n} coordinates and m = {m} \
                 constraints), got {k}",
                2 * (n - m.min(n))
            ),
        };
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
    let mut x = match start {
        None => start_vectors(dim, k),
        Some(given) => {
            let independent = given.len() == dim * k && given.iter().all(|x| x.is_finite()) && rank(given, dim) == k;
            if !independent {
                let reason = format!(
                    "must be {k} finite, linearly independent columns (δq, δq̇) of {dim} entries, got {} entries",
                    given.len()
                );
                return Err(Error::invalid("tangent0", reason));
            }
            given.to_vec()
        }
    };
    to_momenta(sys.as_lagrangian(), (t0, q0, p0), &mut x).map_err(|source| Error::Model {
        step: 1,
        time: t0,
        source,
    })?;
    onto_tangent_space(sys, (q0, p0), &mut x)?;
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
    // To the next re-orthonormalization, or sooner where a vector grows past LARGE.
    let mut done = 0;
    while done < steps {
        let due = (done / every + 1) * every;
        let carry = (&mut tangent, &mut x[..]);
        stepper.advance_with_tangent_below(due.min(steps) - done, carry, LARGE, Counting(|s| poll.poll(s)))?;
        done = stepper.steps();
        orthonormalize(&mut x, dim, &mut row);
        // A column contracted to zero (or past the smallest float) since the last
        // re-orthonormalization has no direction left: its ln R is −∞ and the rest NaN.
        if !row.iter().all(|s| s.is_finite()) {
            let reason = format!(
                "the tangent vectors collapsed: a column contracted past the smallest float in the {every} steps \
                 since the last re-orthonormalization, and its exponent would be NaN; re-orthonormalize more often \
                 (a smaller every) or take a smaller dt"
            );
            return Err(Error::Divergence {
                step: done,
                time: stepper.t(),
                reason,
            });
        }
        stretching.t.push(stepper.t());
        stretching.sums.extend_from_slice(&row);
    }
    stretching.q.copy_from_slice(stepper.q());
    stretching.p.copy_from_slice(stepper.p());
    stretching.evaluations = tangent.evaluations();
    Ok(stretching)
}

/// k vectors of `dim` components in fixed pseudo-random directions (SplitMix64, uniform in
/// [−1, 1)), column-major: independent of any model's coordinates.
fn start_vectors(dim: usize, k: usize) -> Vec<f64> {
    // 2u − 1: the doubling is exact, so these are SplitMix64's 53 bits over 2⁵² less 1.
    splitmix::uniform(dim * k).map(|u| 2.0 * u - 1.0).collect()
}

/// On holonomic constraints, each column of `x` taken into the constraint manifold's tangent
/// space at (q, p): the derivative of the model's projection onto the manifold along it, by a
/// central difference, so that the vectors start where the motion's tangent map acts (off it,
/// a step would collapse them onto it at once, and that collapse would count as stretching).
fn onto_tangent_space<S: Dynamics + ?Sized>(sys: &S, (q, p): (&[f64], &[f64]), x: &mut [f64]) -> Result<(), Error> {
    if sys.holonomic().is_none() {
        return Ok(());
    }
    let n = q.len();
    let size = q.iter().chain(p).fold(1.0_f64, |m, x| m.max(x.abs()));
    let h = difference::step(size);
    for column in x.chunks_exact_mut(2 * n) {
        let moved = |sign: f64| -> Result<Vec<f64>, Error> {
            let (dq, dp) = column.split_at(n);
            let at: Vec<f64> = q.iter().zip(dq).map(|(q, d)| q + sign * h * d).collect();
            let rate: Vec<f64> = p.iter().zip(dp).map(|(p, d)| p + sign * h * d).collect();
            let (q, p) = sys
                .project(&at, &rate)
                .expect("a model with holonomic constraints projects")?;
            Ok(q.into_iter().chain(p).collect())
        };
        let (plus, minus) = (moved(1.0)?, moved(-1.0)?);
        column
            .iter_mut()
            .zip(plus.iter().zip(&minus))
            .for_each(|(c, (a, b))| *c = (a - b) / (2.0 * h));
    }
    Ok(())
}

/// The number of the columns of `x` (each of `dim`) independent to working precision: those
/// whose Gram–Schmidt remainder keeps more than 1e-12 of their norm.
fn rank(x: &[f64], dim: usize) -> usize {
    let mut work = x.to_vec();
    let mut sums = vec![0.0; x.len() / dim];
    let norms: Vec<f64> = x.chunks_exact(dim).map(|c| dot(c, c).sqrt()).collect();
    orthonormalize(&mut work, dim, &mut sums);
    sums.iter()
        .zip(&norms)
        .filter(|(ln_r, norm)| ln_r.exp() > 1e-12 * **norm)
        .count()
}

/// Each column (δq, δq̇) of `x` made (δq, δp), δp = ∂p/∂q δq + ∂p/∂q̇ δq̇ the differential of
/// p = ∂L/∂q̇ at (q, q̇(q, p), t): a central difference along the column (exact for an L
/// quadratic in q̇ but for round-off; a start direction needs no more).
fn to_momenta(sys: &dyn Lagrangian, (t, q, p): (f64, &[f64], &[f64]), x: &mut [f64]) -> Result<(), ModelError> {
    let n = q.len();
    let mut v = vec![0.0; n];
    sys.velocity(q, p, t, &mut v)?;
    let size = q.iter().chain(&v).fold(1.0_f64, |m, x| m.max(x.abs()));
    let h = difference::step(size);
    let (mut at, mut rate, mut plus, mut minus) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for column in x.chunks_exact_mut(2 * n) {
        let (dq, dv) = column.split_at_mut(n);
        for (sign, out) in [(1.0, &mut plus), (-1.0, &mut minus)] {
            at.iter_mut()
                .zip(q.iter().zip(dq.iter()))
                .for_each(|(a, (q, d))| *a = q + sign * h * d);
            rate.iter_mut()
                .zip(v.iter().zip(dv.iter()))
                .for_each(|(r, (v, d))| *r = v + sign * h * d);
            sys.dl_dv(&at, &rate, t, out)?;
        }
        dv.iter_mut()
            .zip(plus.iter().zip(&minus))
            .for_each(|(d, (a, b))| *d = (a - b) / (2.0 * h));
    }
    Ok(())
}

/// The k columns of `x` (each of `dim`) orthonormalized in order by modified Gram–Schmidt,
/// each projection done twice (its R to working precision), ln Rⱼⱼ added to `sums[j]`.
fn orthonormalize(x: &mut [f64], dim: usize, sums: &mut [f64]) {
    sized!(gram_schmidt(x, sums; dim));
}

/// [`orthonormalize`] with `dim` a literal for small dimensions ([`sized!`]): the columns'
/// loops unroll.
#[inline(always)]
fn gram_schmidt(x: &mut [f64], sums: &mut [f64], dim: usize) {
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
