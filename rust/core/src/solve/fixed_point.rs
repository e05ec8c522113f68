//! Fixed-point iteration x ← G(x) on the caller's buffers, stopped at its round-off floor.

/// What one pass of G made: the change of the iterate (or of what the caller measures it by)
/// and how it is judged.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pass {
    /// The change, ‖G(x) − x‖ in the caller's norm.
    pub change: f64,
    /// Settled at once where the change is at most this (its rounding).
    pub floor: f64,
    /// Settled where the change has stopped falling within this: at the noise of a G that is
    /// smooth only to some precision.
    pub stall: f64,
    /// Where the change stops falling (or is NaN) above `stall`: give up, or iterate on.
    pub give_up: bool,
}

/// How a fixed-point iteration ended: settled or not, its last change and floor, its passes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Outcome {
    pub settled: bool,
    pub change: f64,
    pub floor: f64,
    pub passes: usize,
}

/// Picard's iteration x ← G(x), at most `passes` times: `pass` applies G once, in the caller's
/// buffers, and measures its [`Pass`]. A contraction's changes fall geometrically to the floor
/// of G's rounding; settled where a change is within `floor`, or no smaller than the one before
/// and within `stall`. Not settled where `give_up` says so at a change that stopped falling, or
/// after the last pass.
///
/// `pass` may fail (e.g. a model error); its first error is returned.
pub(crate) fn iterate<E>(passes: usize, mut pass: impl FnMut() -> Result<Pass, E>) -> Result<Outcome, E> {
    let (mut last, mut floor) = (f64::INFINITY, 0.0);
    for done in 1..=passes {
        let Pass {
            change,
            floor: rounding,
            stall,
            give_up,
        } = pass()?;
        floor = rounding;
        if change <= floor || (change >= last && change <= stall) {
            return Ok(Outcome {
                settled: true,
                change,
                floor,
                passes: done,
            });
        }
        let stopped = change >= last || change.is_nan();
        last = change;
        if stopped && give_up {
            return Ok(Outcome {
                settled: false,
                change,
                floor,
                passes: done,
            });
        }
    }
    Ok(Outcome {
        settled: false,
        change: last,
        floor,
        passes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settles_a_contraction_and_gives_up_on_a_divergence() {
        // x ← cos x, to its fixed point 0.739…
        let mut x = 1.0_f64;
        let mut cosine = || {
            let next = x.cos();
            let change = (next - x).abs();
            x = next;
            Ok::<_, ()>(Pass {
                change,
                floor: 4.0 * f64::EPSILON,
                stall: 1e-12,
                give_up: true,
            })
        };
        let outcome = iterate(200, &mut cosine).unwrap();
        assert!(outcome.settled && outcome.change <= 1e-12, "{outcome:?}");
        let mut y = 1.0_f64;
        let doubling = || {
            y *= 2.0;
            Ok::<_, ()>(Pass {
                change: y,
                floor: 0.0,
                stall: 0.0,
                give_up: true,
            })
        };
        let outcome = iterate(200, doubling).unwrap();
        assert_eq!((outcome.settled, outcome.passes), (false, 2));
    }
}
