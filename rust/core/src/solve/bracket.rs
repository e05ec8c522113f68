//! A root of a continuous function on a bracket: by the Illinois method, by Newton's method
//! kept in the bracket, or by bisection (of a bracket found by doubling, or of a predicate).

use std::convert::Infallible;

/// A root x* of f on the bracket [a, b] with f(a) < 0 ≤ f(b) (or f(a) > 0 ≥ f(b)), by the
/// Illinois method (Dowell & Jarratt 1971): regula falsi, with the function value at an end
/// kept twice in a row halved, which restores superlinear convergence (order ≈ 1.44); a secant
/// point that rounds onto an end of the bracket moves one ulp inside. Stops when f vanishes or
/// the bracket is within `tolerance` ≥ 0 (at least a few ulps of its ends), or after 100
/// evaluations (a function that is not continuous); returns the end of the final bracket with
/// the smaller |f|, and that value.
///
/// `f` may fail (e.g. a model error); its first error is returned.
pub fn illinois<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    tolerance: f64,
) -> Result<(f64, f64), E> {
    // The ends' values (ga, gb); (fa, fb) are their weights in the secant, halved by Illinois.
    let (mut ga, mut gb) = (fa, fb);
    // Which end the last new point replaced: −1 a, +1 b, 0 none yet.
    let mut side = 0;
    for _ in 0..MAX_EVALUATIONS {
        if ga == 0.0 || gb == 0.0 || converged(a, b, tolerance) {
            break;
        }
        let mut c = b - fb * (b - a) / (fb - fa);
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if !(lo < c && c < hi) {
            // The secant point rounded onto an end (the root is within an ulp or so of it):
            // one ulp inside from that end brackets it. NaN (fa = fb after halving): bisect.
            c = if c.is_nan() {
                0.5 * (a + b)
            } else if (c - a).abs() < (c - b).abs() {
                toward(a, b)
            } else {
                toward(b, a)
            };
            if !(lo < c && c < hi) {
                break;
            }
        }
        let fc = f(c)?;
        if (fc < 0.0) == (gb < 0.0) && fc != 0.0 {
            (b, fb, gb) = (c, fc, fc);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            (a, fa, ga) = (c, fc, fc);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    Ok(if ga.abs() < gb.abs() { (a, ga) } else { (b, gb) })
}

/// A root x* of f on the bracket [a, b], as [`illinois`], by Newton's method kept inside the
/// bracket: `f` gives the value and an estimate of the derivative at a point. From `guess`
/// where it lies inside the bracket (an interpolant's root: an impact's is the quadratic's
/// through φ at both ends with the rate at the start, exact on a straight or parabolic flight),
/// else from the secant point, each next point is the Newton point from the last; where that leaves the bracket, or
/// moves more than half the step before (convergence slower than bisection's), the bracket's
/// midpoint. Once a Newton step is within half the tolerance (or 4 ulps), the next point goes a
/// quarter of it past, to close the bracket on the root's other side. With an exact
/// derivative the convergence is quadratic, with one off by a factor δ linear at rate
/// |1 − 1/δ|: an impact's location (∇φ·q̇, off by the method's error) takes about 30% fewer
/// evaluations than the Illinois method's (5 to 7 against 7 to 10 on a circle's chords).
/// Stops and returns as [`illinois`].
pub fn newton<E>(
    mut f: impl FnMut(f64) -> Result<(f64, f64), E>,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    guess: Option<f64>,
    tolerance: f64,
) -> Result<(f64, f64), E> {
    let inside = |x: f64| a.min(b) < x && x < a.max(b);
    let mut x = guess.filter(|&x| inside(x)).unwrap_or(b - fb * (b - a) / (fb - fa));
    let mut last_step = f64::INFINITY;
    for _ in 0..MAX_EVALUATIONS {
        if fa == 0.0 || fb == 0.0 || converged(a, b, tolerance) {
            break;
        }
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if !(lo < x && x < hi) {
            x = 0.5 * (a + b);
            if !(lo < x && x < hi) {
                break;
            }
        }
        let (fx, slope) = f(x)?;
        if (fx < 0.0) == (fb < 0.0) && fx != 0.0 {
            (b, fb) = (x, fx);
        } else {
            (a, fa) = (x, fx);
        }
        let step = -fx / slope;
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        // The width `converged` takes for the root's: the tolerance, or 4 ulps.
        let reach = tolerance.max(4.0 * f64::EPSILON * x.abs());
        let next = if step.abs() <= 0.5 * reach {
            x + step + 0.25 * reach.copysign(step)
        } else {
            x + step
        };
        x = if lo < next && next < hi && step.abs() <= 0.5 * last_step {
            next
        } else {
            0.5 * (a + b)
        };
        last_step = step.abs();
    }
    Ok(if fa.abs() < fb.abs() { (a, fa) } else { (b, fb) })
}

/// The root of an increasing f on the side of 0 that `guess` is on (f(0) < 0 for guess ≥ 0,
/// f(0) > 0 for guess < 0): bracketed from [0, guess] by doubling its far end, then
/// [`bisect`]ed to adjacent doubles, each at most `limit` times (2·1100 halvings span the
/// doubles); the midpoint of the last bracket. NaN where f is not finite at a far end, or no
/// bracket is found.
pub(crate) fn bisection(f: impl Fn(f64) -> f64, guess: f64, limit: usize) -> f64 {
    let sign = if guess < 0.0 { -1.0 } else { 1.0 };
    let (mut near, mut far) = (0.0, if guess == 0.0 { f64::MIN_POSITIVE } else { guess });
    let beyond = |value: f64| sign * value >= 0.0;
    let mut bracketed = false;
    for _ in 0..limit {
        let value = f(far);
        if !value.is_finite() {
            return f64::NAN;
        }
        if beyond(value) {
            bracketed = true;
            break;
        }
        near = far;
        far *= 2.0;
    }
    if !bracketed {
        return f64::NAN;
    }
    let beyond = |x: f64| Ok::<_, Infallible>(beyond(f(x)));
    let Ok((far, near)) = bisect(beyond, (far, near), limit, |_, _| true);
    0.5 * (near + far)
}

/// The boundary of the set where `holds`, between an end `inside` it and one `outside`, by
/// bisection: the midpoint replaces the end on its side, at most `limit` times, while
/// `wide(inside, outside)` and the midpoint does not round onto an end (the ends adjacent).
/// Returns the last (inside, outside).
///
/// `holds` may fail (e.g. a model error); its first error is returned.
pub(crate) fn bisect<E>(
    mut holds: impl FnMut(f64) -> Result<bool, E>,
    (mut inside, mut outside): (f64, f64),
    limit: usize,
    wide: impl Fn(f64, f64) -> bool,
) -> Result<(f64, f64), E> {
    for _ in 0..limit {
        if !wide(inside, outside) {
            break;
        }
        let mid = 0.5 * (inside + outside);
        if mid == inside || mid == outside {
            break;
        }
        if holds(mid)? {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    Ok((inside, outside))
}

/// Whether [a, b] is within `tolerance`, or within 4 ulps of its larger end.
fn converged(a: f64, b: f64, tolerance: f64) -> bool {
    let width = (b - a).abs();
    width <= tolerance || width <= 4.0 * f64::EPSILON * a.abs().max(b.abs())
}

/// The cap on evaluations, against a function that is not continuous: a smooth root takes a
/// handful (superlinear convergence from the first secant step).
const MAX_EVALUATIONS: usize = 100;

/// The float next to x in the direction of y.
fn toward(x: f64, y: f64) -> f64 {
    if y > x {
        x.next_up()
    } else {
        x.next_down()
    }
}

#[cfg(test)]
mod tests {
    use super::{bisect, bisection};

    #[test]
    fn bisection_finds_a_cube_root_either_side_of_zero() {
        let root = bisection(|x| x * x * x - 10.0, 0.5, 2200);
        assert!((root - 10.0_f64.cbrt()).abs() <= 4.0 * f64::EPSILON * root, "{root}");
        let root = bisection(|x| x * x * x + 10.0, -0.5, 2200);
        assert!(
            (root + 10.0_f64.cbrt()).abs() <= 4.0 * f64::EPSILON * root.abs(),
            "{root}"
        );
        assert!(bisection(|_| f64::NAN, 1.0, 2200).is_nan());
    }

    #[test]
    fn bisect_stops_at_its_width_and_passes_an_error_on() {
        let holds = |x: f64| Ok::<_, ()>(x * x <= 2.0);
        let (inside, outside) = bisect(holds, (1.0, 2.0), usize::MAX, |a, b| b - a > 1e-6).unwrap();
        assert!(inside * inside <= 2.0 && outside * outside > 2.0 && outside - inside <= 1e-6);
        assert_eq!(bisect(|_| Err(7), (1.0, 2.0), usize::MAX, |_, _| true), Err(7));
    }
}
