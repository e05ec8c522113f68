//! The extreme eigenvalues of a symmetric-definite pencil K x = κ B x by Lanczos's method in the
//! B inner product (Parlett, *The Symmetric Eigenvalue Problem*, §13.2; Ericsson & Ruhe 1980):
//! one product Kv and one application of B⁻¹ an iteration, B itself never formed or factorised.
//!
//! B⁻¹ may be a projected inverse H = PB⁻¹ (P the B-orthogonal projector onto a subspace, H
//! symmetric positive semidefinite): the iteration then runs on the pencil restricted to
//! range(H), the tangent space of a model's constraints. Only the extreme Ritz values are
//! wanted, so no vector is kept beyond the last two and none is reorthogonalised: a lost
//! orthogonality repeats Ritz values (ghosts) but moves no extreme one.

/// The extreme eigenvalues found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extremes {
    /// The smallest and largest Ritz values: bounds from within, κ_min ≤ smallest and
    /// largest ≤ κ_max.
    pub smallest: f64,
    pub largest: f64,
    /// The pencil's scale: the eigenvalues are `smallest`·2^`exponent` and
    /// `largest`·2^`exponent` (an even exponent, 0 but for a pencil whose products would
    /// leave the floats' range, κ of 10²⁰⁰, say).
    pub exponent: i32,
    /// Iterations taken (products Kv).
    pub iterations: usize,
    /// Whether both met the tolerance (their residual bounds β|s_k|, Parlett's (13.2.6), or
    /// their change over the last `CHECK` iterations), or the iteration found an invariant
    /// subspace; false at the iteration cap.
    pub converged: bool,
}

/// The Ritz values of the tridiagonal T_k (diagonal `alpha`, off-diagonal `beta`, one shorter)
/// are checked against the tolerance every `CHECK` iterations (and where the iteration ends): a
/// check bisects twice, O(k) a bisection step, which would otherwise cost more than the
/// iterations' products on a cheap model.
const CHECK: usize = 16;

/// The extreme eigenvalues of K x = κ B x from the covector `start` (r₀ with r₀ᵀHr₀ > 0, H the
/// given B⁻¹), to `tolerance` relative to the larger of their sizes, in at most
/// `max_iterations` iterations: `stiffness` writes Kv, `inverse` writes Hr, each to `noise`
/// relative (ε for exact products, √ε for forward differences). A next vector that the
/// products' noise could be all of (β ≤ 10³·noise·(|α| + β)) ends the iteration as an invariant
/// subspace would: continued from noise, the vectors would lose their orthogonality at once and
/// the Ritz values could leave the spectrum.
///
/// A pencil of any scale is taken: where the first product's size (|Kv|·|v|, about κ) lies
/// outside 2^±400, every product Kv is scaled by an exact power of two 2^−e that brings it to
/// 1 (the iteration is otherwise the same, bit for bit), and the eigenvalues are returned
/// with e ([`Extremes::exponent`]): the squares the inner products take of κ would overflow
/// from κ of 10¹⁵⁴ on, and the Ritz values would be lost.
///
/// # Errors
/// The first error of `stiffness` or `inverse`.
pub fn extremes<E>(
    start: &[f64],
    mut stiffness: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    mut inverse: impl FnMut(&[f64], &mut [f64]) -> Result<(), E>,
    max_iterations: usize,
    tolerance: f64,
    noise: f64,
) -> Result<Extremes, E> {
    let n = start.len();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // Vⱼ and Uⱼ = BVⱼ, the current and the last; r and z = Hr, the next before scaling.
    let mut r = start.to_vec();
    let mut z = vec![0.0; n];
    inverse(&r, &mut z)?;
    let norm = dot(&r, &z).max(0.0).sqrt();
    let mut found = Extremes {
        smallest: 0.0,
        largest: 0.0,
        exponent: 0,
        iterations: 0,
        converged: true,
    };
    if norm == 0.0 || !norm.is_finite() {
        return Ok(found);
    }
    let (mut v, mut u) = (scaled(&z, norm), scaled(&r, norm));
    let (mut v_last, mut u_last) = (vec![0.0; n], vec![0.0; n]);
    let mut kv = vec![0.0; n];
    let (mut alpha, mut beta) = (Vec::new(), Vec::new());
    let mut beta_last = 0.0;
    found.converged = false;
    for k in 1..=max_iterations.max(1) {
        stiffness(&v, &mut kv)?;
        if k == 1 {
            found.exponent = scale_exponent(&v, &kv);
        }
        if found.exponent != 0 {
            kv.iter_mut().for_each(|x| *x = times_power_of_two(*x, -found.exponent));
        }
        let a = dot(&v, &kv);
        for i in 0..n {
            r[i] = kv[i] - a * u[i] - beta_last * u_last[i];
        }
        inverse(&r, &mut z)?;
        let b = dot(&r, &z).max(0.0).sqrt();
        alpha.push(a);
        found.iterations = k;
        // An invariant subspace, to the products' noise: T_k's eigenvalues are exact there (NaN:
        // a model gone non-finite, nothing more to learn).
        let invariant = b <= 1e3 * noise * (a.abs() + beta_last) || b.is_nan();
        if invariant || k % CHECK == 0 || k == max_iterations.max(1) {
            let (smallest, largest) = ritz(&alpha, &beta, tolerance);
            let size = smallest.abs().max(largest.abs());
            // Met where each residual bound is within the tolerance, or where neither extreme
            // moved by more since the last check: once a Ritz value has converged its copies
            // (ghosts, where orthogonality is lost) no longer have small bounds, but they stay.
            let within = |theta: f64| b * last_component(&alpha, &beta, theta) <= tolerance * size;
            let settled = found.iterations > CHECK
                && (smallest - found.smallest).abs() <= tolerance * size
                && (largest - found.largest).abs() <= tolerance * size;
            found.smallest = smallest;
            found.largest = largest;
            if invariant || settled || (within(smallest) && within(largest)) {
                found.converged = true;
                break;
            }
        }
        beta.push(b);
        std::mem::swap(&mut v_last, &mut v);
        std::mem::swap(&mut u_last, &mut u);
        for i in 0..n {
            v[i] = z[i] / b;
            u[i] = r[i] / b;
        }
        beta_last = b;
    }
    Ok(found)
}

/// The even exponent e of 2 that brings the size of the product Kv, max|Kvᵢ|·max|vᵢ|, to 1
/// where that size lies outside 2^±400; 0 inside (or where it is 0 or not finite).
fn scale_exponent(v: &[f64], kv: &[f64]) -> i32 {
    let largest = |x: &[f64]| x.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let (a, b) = (largest(kv), largest(v));
    if !(a > 0.0 && b > 0.0 && a.is_finite() && b.is_finite()) {
        return 0;
    }
    let e = (a.log2() + b.log2()).round() as i32;
    if e.abs() <= 400 {
        0
    } else {
        e & !1
    }
}

/// x·2^e, exactly (but for underflow), in factors that are floats.
pub fn times_power_of_two(mut x: f64, mut e: i32) -> f64 {
    while e != 0 {
        let step = e.clamp(-1000, 1000);
        x *= 2.0_f64.powi(step);
        e -= step;
    }
    x
}

fn scaled(x: &[f64], by: f64) -> Vec<f64> {
    x.iter().map(|x| x / by).collect()
}

/// How many eigenvalues of T_k are below x and below y: the sign changes of the Sturm
/// sequences of its leading minors det(T_i − xI) (Givens), by their three-term recurrence
/// rescaled on the way, for two points at once (two independent chains of multiplications: a
/// division a step, or one chain, would cost several times as much). `coupling` holds β².
fn below(alpha: &[f64], coupling: &[f64], (x, y): (f64, f64)) -> (usize, usize) {
    let (mut x0, mut x1, mut y0, mut y1) = (1.0_f64, 1.0_f64, 1.0_f64, 1.0_f64);
    let (mut at_x, mut at_y) = (0, 0);
    for (i, a) in alpha.iter().enumerate() {
        let c = if i == 0 { 0.0 } else { coupling[i - 1] };
        let (xn, yn) = (sturm((a - x) * x1 - c * x0, x1), sturm((a - y) * y1 - c * y0, y1));
        at_x += usize::from((xn < 0.0) != (x1 < 0.0));
        at_y += usize::from((yn < 0.0) != (y1 < 0.0));
        (x0, x1, y0, y1) = (x1, xn, y1, yn);
        (x0, x1) = rescaled(x0, x1);
        (y0, y1) = rescaled(y0, y1);
    }
    (at_x, at_y)
}

/// The next minor, a zero one taking the sign that continues the count as a vanishing pivot
/// would.
#[inline(always)]
fn sturm(next: f64, minor: f64) -> f64 {
    if next == 0.0 {
        -minor * f64::MIN_POSITIVE
    } else {
        next
    }
}

/// Two consecutive minors scaled by the last's size when it leaves [1e-100, 1e100].
#[inline(always)]
fn rescaled(before: f64, minor: f64) -> (f64, f64) {
    let size = minor.abs();
    if (1e-100..=1e100).contains(&size) {
        (before, minor)
    } else {
        (before / size, minor / size)
    }
}

/// The smallest and largest eigenvalues of T_k, by two bisections side by side from its
/// Gershgorin bounds, to 10⁻³ of the `tolerance` they are checked against, relative to their size.
fn ritz(alpha: &[f64], beta: &[f64], tolerance: f64) -> (f64, f64) {
    let k = alpha.len();
    let coupling: Vec<f64> = beta.iter().map(|b| b * b).collect();
    let off = |i: usize| {
        let before = if i > 0 { beta[i - 1].abs() } else { 0.0 };
        let after = if i + 1 < k { beta[i].abs() } else { 0.0 };
        before + after
    };
    let (low, high) = (0..k).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), i| {
        (lo.min(alpha[i] - off(i)), hi.max(alpha[i] + off(i)))
    });
    let precision = 1e-3 * tolerance * low.abs().max(high.abs());
    // [lo, hi] about the smallest (s) and the largest (l).
    let (mut s, mut l) = ((low, high), (low, high));
    // At most a bisection a bit of the bounds' width: a bracket that rounding keeps from
    // shrinking ends it too.
    for _ in 0..128 {
        if s.1 - s.0 <= precision && l.1 - l.0 <= precision {
            break;
        }
        let (x, y) = (0.5 * (s.0 + s.1), 0.5 * (l.0 + l.1));
        let (at_x, at_y) = below(alpha, &coupling, (x, y));
        // Above the smallest where one eigenvalue is below; above the largest where all are.
        if at_x >= 1 {
            s.1 = x;
        } else {
            s.0 = x;
        }
        if at_y == k {
            l.1 = y;
        } else {
            l.0 = y;
        }
    }
    (s.1, l.0)
}

/// |s_k|, the last component of T_k's unit eigenvector for the eigenvalue θ, by the three-term
/// recurrence from its first (stable for an extreme θ, where every leading minor keeps its
/// sign), rescaled on the way.
fn last_component(alpha: &[f64], beta: &[f64], theta: f64) -> f64 {
    let (mut before, mut x) = (0.0, 1.0);
    let mut norm = 1.0;
    for i in 0..alpha.len() - 1 {
        let next = ((theta - alpha[i]) * x - if i > 0 { beta[i - 1] * before } else { 0.0 }) / beta[i];
        before = x;
        x = next;
        norm += x * x;
        if norm > 1e200 {
            let s = norm.sqrt();
            (before, x, norm) = (before / s, x / s, 1.0);
        }
    }
    x.abs() / norm.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The path graph's Laplacian (the chain of unit springs, fixed ends): κₖ = 4 sin²(kπ/2(n+1)).
    fn chain(n: usize) -> impl FnMut(&[f64], &mut [f64]) -> Result<(), ()> {
        move |v, out| {
            for i in 0..n {
                let left = if i > 0 { v[i - 1] } else { 0.0 };
                let right = if i + 1 < n { v[i + 1] } else { 0.0 };
                out[i] = 2.0 * v[i] - left - right;
            }
            Ok(())
        }
    }

    #[test]
    fn the_chains_extreme_eigenvalues_to_the_tolerance_with_a_mass() {
        let n = 100;
        // B = diag(mᵢ) with a varying mass: its inverse alone is given.
        let mass: Vec<f64> = (0..n).map(|i| 1.0 + (i % 3) as f64).collect();
        let start: Vec<f64> = (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect();
        let found = extremes(
            &start,
            chain(n),
            |r, out| {
                out.iter_mut().zip(r).zip(&mass).for_each(|((o, r), m)| *o = r / m);
                Ok::<(), ()>(())
            },
            300,
            1e-6,
            f64::EPSILON,
        )
        .unwrap();
        let dense = nalgebra::DMatrix::from_fn(n, n, |i, j| {
            let k = match i.abs_diff(j) {
                0 => 2.0,
                1 => -1.0,
                _ => 0.0,
            };
            k / (mass[i] * mass[j]).sqrt()
        });
        let eigen = nalgebra::SymmetricEigen::new(dense).eigenvalues;
        let (min, max) = (eigen.min(), eigen.max());
        assert!(found.converged, "{found:?}");
        assert!(
            found.largest <= max * (1.0 + 1e-14) && (found.largest / max - 1.0).abs() < 1e-6,
            "{found:?} {max}"
        );
        // The smallest, 5e-4 of the largest, to the tolerance of the largest's size.
        assert!((found.smallest - min).abs() < 1e-6 * max, "{found:?} {min}");
    }

    #[test]
    fn a_small_pencil_is_exact_when_the_iteration_finds_its_invariant_subspace() {
        let found = extremes(
            &[1.0, 0.3, -0.2],
            chain(3),
            |r, out| {
                out.copy_from_slice(r);
                Ok::<(), ()>(())
            },
            50,
            1e-12,
            f64::EPSILON,
        )
        .unwrap();
        let exact = |k: f64| 4.0 * (k * std::f64::consts::PI / 8.0).sin().powi(2);
        assert!(found.converged && found.iterations == 3, "{found:?}");
        assert!((found.largest - exact(3.0)).abs() < 1e-13 && (found.smallest - exact(1.0)).abs() < 1e-13);
    }

    #[test]
    fn a_projected_inverse_restricts_the_pencil_to_its_range() {
        // H = I − e₁e₁ᵀ: the chain with its first mass held (removed from the problem).
        let n = 6;
        let found = extremes(
            &[1.0; 6],
            chain(n),
            |r, out| {
                out.copy_from_slice(r);
                out[0] = 0.0;
                Ok::<(), ()>(())
            },
            50,
            1e-12,
            f64::EPSILON,
        )
        .unwrap();
        // The chain of n − 1 masses.
        let exact = 4.0 * (5.0 * std::f64::consts::PI / 12.0).sin().powi(2);
        assert!((found.largest - exact).abs() < 1e-12, "{found:?}");
    }
}
