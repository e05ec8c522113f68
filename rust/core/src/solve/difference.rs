//! Derivatives by central differences, for models and equations that do not supply them.
//!
//! Every difference here steps by hᵢ = ε^{1/3}·max(|xᵢ|, floor) (ε the machine epsilon), which
//! balances the O(h²) truncation against the O(ε/h) round-off, for an error of order
//! ε^{2/3} ≈ 4e-11 relative.

use std::cell::Cell;

use nalgebra::DMatrix;

use crate::ModelError;

thread_local! {
    /// The largest rounding error of a derivative taken by [`central_gradient`] on this thread
    /// since the last [`take_noise`].
    static NOISE: Cell<f64> = const { Cell::new(0.0) };
}

/// The largest rounding error of the derivatives taken by differences on this thread since the
/// last call, and a fresh start: what an equation built from them carries as noise
/// (`crate::solve::newton` judges a stall against it). Not the O(h²) truncation: that is
/// smooth, and Newton solves through it; the rounding of f at x ± h, which the difference
/// divides by 2h, is in steps, too flat over a Newton correction to sample (see
/// [`central_gradient`] for its bound).
pub fn take_noise() -> f64 {
    NOISE.with(|n| n.replace(0.0))
}

/// Records `noise`, the rounding error of a derivative just taken by differences (or of a
/// solution an equation takes from a solve of its own).
#[inline]
pub(crate) fn record(noise: f64) {
    NOISE.with(|n| n.set(n.get().max(noise)));
}

/// F's rounding about x, measured: the second differences |F(x + sδ) + F(x − sδ) − 2F(x)|/2
/// at s = 1, …, 8, their largest component, at δ and at 1e-2 and 1e-4 of it, the largest of
/// the scales that measure one. `f0` is the residual F(x) the caller judges; `at(shift, out)`
/// writes F(x + shift) (every unknown shifted alike), `plus`, `minus` are scratch of F's
/// length, and x has norm `x` and is added to values of norm `offset` (δ: `measuring_step`).
/// F is evaluated at x first, for the rounding it records, and last, to leave the caller's
/// caches at x. The rounding of every evaluation inside F changes with x: what `record`'s
/// estimate from the sizes of values cannot see, a closure's own cancellation (g(1 − cos q) at
/// |q| ≈ 1e-6 rounds at εg), shows. A difference's rounding comes in quanta (f's ulp over 2h),
/// flat over some shifts and met by others: hence eight samples at three scales. Rounding does
/// not grow with s, and F's smooth part s²δᵀF''δ/2 does: where the largest at s = 5 … 8 is over
/// twice the largest at s = 1 … 4 (four times for curvature alone), the differences are
/// curvature, and that scale measures none. Neither curvature nor a jump of F within reach
/// shrinks as the shift grows, and rounding σ moves a sample by σ at most: a sample a larger
/// shift's undercuts by d proves σ ≥ d/2, though a quantum met only at large s reads as
/// curvature to the test above.
pub fn measured_noise<E>(
    f0: &[f64],
    (plus, minus): (&mut [f64], &mut [f64]),
    (x, offset): (f64, f64),
    mut at: impl FnMut(f64, &mut [f64]) -> Result<(), E>,
) -> Result<f64, E> {
    take_noise();
    at(0.0, plus)?;
    let delta = measuring_step(x, offset, recorded());
    let mut noise = 0.0_f64;
    // The least sample at a larger shift than those of the scale in hand.
    let mut beyond = f64::INFINITY;
    for scale in [1.0, 1e-2, 1e-4] {
        let mut sizes = [0.0_f64; 8];
        for (k, size) in sizes.iter_mut().enumerate() {
            let shift = scale * (k + 1) as f64 * delta;
            at(shift, plus)?;
            at(-shift, minus)?;
            for ((a, b), c) in plus.iter().zip(minus.iter()).zip(f0) {
                *size = size.max(((a + b) - 2.0 * c).abs() / 2.0);
            }
        }
        let largest = |x: &[f64]| x.iter().fold(0.0_f64, |a, &b| a.max(b));
        let (near, far) = (largest(&sizes[..4]), largest(&sizes[4..]));
        if far <= 2.0 * near {
            noise = noise.max(far.max(near));
        }
        for &size in sizes.iter().rev() {
            noise = noise.max((size - beyond) / 2.0);
            beyond = beyond.min(size);
        }
    }
    at(0.0, plus)?;
    Ok(noise)
}

/// The δ of [`measured_noise`] for unknowns of norm `x` added to values of norm `offset` (a
/// step's increments to q₀: an increment alone may be below q₀'s rounding): 1e-6 of their sum.
/// Where F's evaluation records rounding ([`recorded`]: derivatives by differences, a nested
/// solve), the offset is taken at least at the differences' floor ([`unit`]): a shift far
/// below their step leaves every evaluation of f rounding alike, and no sample meets its
/// quanta. Not otherwise: a larger δ would reach across a kink of exact derivatives and read
/// its jump as noise.
fn measuring_step(x: f64, offset: f64, recorded: bool) -> f64 {
    1e-6 * (x + if recorded { unit(0, offset) } else { offset })
}

/// Whether rounding was recorded ([`record`]) on this thread since the last [`take_noise`].
fn recorded() -> bool {
    NOISE.with(|n| n.get() > 0.0)
}

/// ε^{1/3}, written out: `f64::cbrt` is not a `const fn`, and a libm call per difference costs
/// as much as a cheap model's gradient.
pub const CBRT_EPSILON: f64 = 6.055_454_452_393_339_5e-6;

/// The central-difference step for a variable of magnitude `size`: ε^{1/3}·size.
#[inline]
pub fn step(size: f64) -> f64 {
    CBRT_EPSILON * size
}

/// The forward-difference step for a variable of magnitude `size`: √ε·size, which balances a
/// one-sided difference's O(h) truncation against its O(ε/h) round-off (error about √ε).
#[inline]
pub fn forward_step(size: f64) -> f64 {
    f64::EPSILON.sqrt() * size
}

/// The magnitude a variable's difference step is relative to: max(|x|, 1).
pub fn unit(_: usize, x: f64) -> f64 {
    x.abs().max(1.0)
}

/// ∇f(q) by central differences, ∂f/∂qᵢ ≈ [f(q + hᵢeᵢ) − f(q − hᵢeᵢ)] / 2hᵢ, with the step
/// hᵢ = ε^{1/3}·max(|qᵢ|, 1).
///
/// Its rounding error is recorded for [`take_noise`]: f rounded at the size of its terms, which
/// f's value alone understates where they cancel (L = T − V near T = V); they are bounded by
/// |f| + Σⱼ|qⱼ∂f/∂qⱼ| (for L in q̇: |T − V| + 2T), and each difference divides their rounding,
/// a few ε of them, by 2hᵢ.
///
/// `work` (length n) is scratch space, so the call allocates nothing.
pub fn central_gradient<F>(mut f: F, q: &[f64], work: &mut [f64], grad: &mut [f64]) -> Result<(), ModelError>
where
    F: FnMut(&[f64]) -> Result<f64, ModelError>,
{
    work.copy_from_slice(q);
    let (mut size, mut least) = (0.0_f64, f64::INFINITY);
    for i in 0..q.len() {
        let h = step(unit(i, q[i]));
        work[i] = q[i] + h;
        let forward = f(work)?;
        work[i] = q[i] - h;
        let backward = f(work)?;
        work[i] = q[i];
        grad[i] = (forward - backward) / (2.0 * h);
        size = size.max(forward.abs()).max(backward.abs());
        least = least.min(h);
    }
    let terms = size + q.iter().zip(grad.iter()).map(|(x, g)| (x * g).abs()).sum::<f64>();
    record(2.0 * f64::EPSILON * terms / (2.0 * least));
    Ok(())
}

/// The two evaluations of a central difference, f(x + hⱼeⱼ) and f(x − hⱼeⱼ) (length m each):
/// scratch space, so that a Jacobian allocates nothing.
#[derive(Debug)]
pub struct Evaluations<'a> {
    pub plus: &'a mut [f64],
    pub minus: &'a mut [f64],
}

/// ∂f/∂x (m × n) of f: ℝⁿ → ℝᵐ by central differences, column by column,
///
/// ∂f/∂xⱼ ≈ [f(x + hⱼeⱼ) − f(x − hⱼeⱼ)] / 2hⱼ,   hⱼ = ε^{1/3}·size(j, xⱼ),
///
/// `size` the magnitude the step is relative to ([`fn@unit`] for max(|xⱼ|, 1)). x is moved and
/// restored in place; nothing is allocated.
pub fn central_jacobian<E, F>(
    mut f: F,
    x: &mut [f64],
    size: impl Fn(usize, f64) -> f64,
    at: Evaluations<'_>,
    jac: &mut DMatrix<f64>,
) -> Result<(), E>
where
    F: FnMut(&[f64], &mut [f64]) -> Result<(), E>,
{
    for j in 0..x.len() {
        let xj = x[j];
        let h = step(size(j, xj));
        x[j] = xj + h;
        f(x, at.plus)?;
        x[j] = xj - h;
        f(x, at.minus)?;
        x[j] = xj;
        for (i, (a, b)) in at.plus.iter().zip(at.minus.iter()).enumerate() {
            jac[(i, j)] = (a - b) / (2.0 * h);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::measured_noise;

    #[test]
    fn cbrt_epsilon_is_the_cube_root_of_epsilon() {
        assert_eq!(super::CBRT_EPSILON.to_bits(), f64::EPSILON.cbrt().to_bits());
    }

    /// F(x + shift) for x = 1, δ = 1e-6 (nothing recorded): `f(shift)`.
    fn measured(f: impl Fn(f64) -> f64) -> f64 {
        let f0 = [f(0.0)];
        let (mut plus, mut minus) = ([0.0], [0.0]);
        measured_noise::<()>(&f0, (&mut plus, &mut minus), (1.0, 0.0), |shift, out| {
            out[0] = f(shift);
            Ok(())
        })
        .unwrap()
    }

    #[test]
    fn curvature_and_a_jump_within_reach_measure_no_noise() {
        assert_eq!(measured(|s| 3.0 * s * s), 0.0);
        // A jump of 1e-9 at 5.5δ: met by the five largest shifts alone.
        assert_eq!(measured(|s| if s > 5.5e-6 { 1e-9 } else { 0.0 }), 0.0);
    }

    #[test]
    fn a_quantum_met_only_at_large_shifts_is_measured() {
        // Seed 99's damped chain at g = 4.86: a quantum of 6.6e-12 at s = 5, 6 and 8 of δ's
        // scale (and at 7 of 1e-2 δ's), where the halves' test reads curvature.
        let met = [5e-6, 6e-6, 8e-6, 7e-8];
        let f = |s: f64| {
            if met.iter().any(|m| (s.abs() - m).abs() < 1e-15) {
                1.32e-11
            } else {
                0.0
            }
        };
        let noise = measured(f);
        assert!((6.5e-12..=6.7e-12).contains(&noise), "{noise:e}");
    }
}
