use std::fmt;

use crate::model::Scale;

/// What a conserved quantity did along a run, judged against its scale (see [`Statistics`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The error stays within the floating-point noise of the quantity's terms.
    ConservedToRoundOff,
    /// The error oscillates in a band that does not grow and is small against the scale.
    Bounded,
    /// The error grows: the drift rate differs from zero by more than four standard errors.
    SecularDrift,
    /// The error reaches the quantity's scale, or a value is not finite.
    Failed,
}

impl Verdict {
    /// The verdicts in order, best first.
    pub const ALL: [Verdict; 4] = [
        Verdict::ConservedToRoundOff,
        Verdict::Bounded,
        Verdict::SecularDrift,
        Verdict::Failed,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Verdict::ConservedToRoundOff => "conserved to round-off",
            Verdict::Bounded => "bounded",
            Verdict::SecularDrift => "secular drift",
            Verdict::Failed => "failed",
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A quantity J that should be conserved, sampled at the saved states of a run.
#[derive(Clone, Copy, Debug)]
pub struct Series<'a> {
    /// The times of the samples, increasing.
    pub t: &'a [f64],
    /// The error of J at each sample: J − J₀ for a first integral, the residual itself for a
    /// constraint.
    pub error: &'a [f64],
    /// J's size at each sample, whose mean is its scale ([`Scale`]): the kinetic energy |T|
    /// for the energy, Σ|pᵢξᵢ| for a Noether momentum.
    pub size: &'a [f64],
    /// The size of the terms J is computed from at each sample (|T| + |V| for the energy,
    /// Σ|pᵢξᵢ| for a Noether momentum): J's rounding error is a few ε times it.
    pub terms: &'a [f64],
    /// Steps taken from the first sample to the last: round-off accumulates over them.
    pub steps: u64,
}

/// The error of a conserved quantity along a run, with its scale and verdict.
///
/// The scale and the round-off level are [`Scale`]'s. The verdict is the first that applies of:
/// - **failed**: an error is not finite (`first_non_finite` says where), or max |error| reaches
///   [`Scale::FAILURE`] × `scale` and exceeds round-off: the quantity is wrong by its own size;
/// - **conserved to round-off**: max |error| ≤ `round_off`;
/// - **secular drift**: the error grows: split into [`Statistics::BATCHES`] batches in time, the
///   least-squares slope of the batch means differs from zero by more than four of its standard
///   errors (batch means make the standard error honest for an error that oscillates, which
///   successive samples are not independent of), the drift over the run exceeds both
///   `round_off` and what biased rounding could add ([`Scale::BIASED_ROUND_OFF`] ε of the
///   terms a step) and the error's oscillation (the median over the batches of the band within
///   a batch: a bounded error that wanders with the state, as on a chaotic orbit, moves its
///   batch means by less than it oscillates), and the largest |error| in the last batch is
///   more than twice that in the first. The test needs the run to span several oscillations of the error: over a fraction
///   of one, a bounded error's rise cannot be told from a drift;
/// - **bounded** otherwise: the band does not grow and stays below `FAILURE × scale`.
#[derive(Clone, Debug, PartialEq)]
pub struct Statistics {
    /// The scale of J (see [`Scale`]).
    pub scale: f64,
    /// The round-off level of the run, absolute (see above).
    pub round_off: f64,
    /// max |error| over the run, absolute and relative to `scale`.
    pub max_abs_error: f64,
    pub max_rel_error: f64,
    /// max error − min error over the run.
    pub band: f64,
    /// The drift rate d(error)/dt from the batch means, and its standard error (absolute, per
    /// unit time; zero and infinite when there are too few samples to fit).
    pub drift_rate: f64,
    pub drift_rate_stderr: f64,
    /// The first sample whose error is not finite.
    pub first_non_finite: Option<usize>,
    pub verdict: Verdict,
}

impl Statistics {
    /// Batches of the drift test (at least four samples each; fewer samples: no drift test).
    pub const BATCHES: usize = 8;

    /// The statistics and verdict of `series` (see [`Statistics`]). Errors when the series'
    /// lengths differ or it is empty.
    pub fn new(series: &Series<'_>) -> Result<Self, crate::Error> {
        let Series {
            t,
            error,
            size,
            terms,
            steps,
        } = *series;
        if t.is_empty() || [error.len(), size.len(), terms.len()].iter().any(|&k| k != t.len()) {
            return Err(crate::Error::invalid(
                "error",
                format!(
                    "needs one error, size and terms' size per time, at least one: got {} times, {} errors, {} sizes, {} terms' sizes",
                    t.len(),
                    error.len(),
                    size.len(),
                    terms.len()
                ),
            ));
        }
        let mut judge = Scale::default();
        size.iter().zip(terms).for_each(|(&s, &x)| judge.push(s, x));
        let (scale, round_off) = (judge.scale(), judge.round_off(steps));
        let first_non_finite = error.iter().position(|x| !x.is_finite());
        let max_abs_error = error.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let (lo, hi) = error.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        let batches = Batches::new(t, error);
        let (drift_rate, drift_rate_stderr) = batches.as_ref().map_or((0.0, f64::INFINITY), |b| (b.slope, b.stderr));
        let floor = judge.biased_round_off(steps).max(round_off);
        let verdict = if first_non_finite.is_some() || judge.fails(max_abs_error, steps, Scale::FAILURE) {
            Verdict::Failed
        } else if max_abs_error <= round_off {
            Verdict::ConservedToRoundOff
        } else if batches.is_some_and(|b| b.drifts(t[t.len() - 1] - t[0], floor)) {
            Verdict::SecularDrift
        } else {
            Verdict::Bounded
        };
        Ok(Statistics {
            scale,
            round_off,
            max_abs_error,
            max_rel_error: max_abs_error / scale,
            band: hi - lo,
            drift_rate,
            drift_rate_stderr,
            first_non_finite,
            verdict,
        })
    }
}

/// What the batches of an error series say about its growth.
struct Batches {
    /// The slope of the batch means against their mean times, and its standard error.
    slope: f64,
    stderr: f64,
    /// max |y| over the last batch over max |y| over the first.
    growth: f64,
    /// The median over the batches of max y − min y within a batch: the error's oscillation.
    band: f64,
}

impl Batches {
    /// `y` at times `t` in [`Statistics::BATCHES`] batches; None with fewer than four samples a
    /// batch.
    fn new(t: &[f64], y: &[f64]) -> Option<Self> {
        let k = Statistics::BATCHES;
        if t.len() < 4 * k {
            return None;
        }
        let size = t.len() / k;
        let batch = |j: usize| {
            let range = j * size..if j + 1 == k { t.len() } else { (j + 1) * size };
            (&t[range.clone()], &y[range])
        };
        let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len() as f64;
        let max_abs = |s: &[f64]| s.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let spread = |s: &[f64]| {
            let (lo, hi) = s.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            });
            hi - lo
        };
        let (tb, yb): (Vec<f64>, Vec<f64>) = (0..k)
            .map(|j| {
                let (t, y) = batch(j);
                (mean(t), mean(y))
            })
            .unzip();
        let (slope, stderr) = linear_fit_slope(&tb, &yb);
        let (first, last) = (max_abs(batch(0).1), max_abs(batch(k - 1).1));
        let growth = if first > 0.0 {
            last / first
        } else if last > 0.0 {
            f64::INFINITY
        } else {
            1.0
        };
        let mut bands: Vec<f64> = (0..k).map(|j| spread(batch(j).1)).collect();
        bands.sort_by(f64::total_cmp);
        Some(Batches {
            slope,
            stderr,
            growth,
            band: 0.5 * (bands[k / 2 - 1] + bands[k / 2]),
        })
    }

    /// A drift: the trend is significant, carries the error past its own oscillation and past
    /// what rounding could add (`floor`), and the band at the end is more than twice that at
    /// the start.
    fn drifts(&self, duration: f64, floor: f64) -> bool {
        let drift = self.slope.abs() * duration;
        self.slope.abs() > 4.0 * self.stderr && drift > floor.max(self.band) && self.growth > 2.0
    }
}

/// Slope b of the least-squares line y ≈ a + b·t, and its standard error
/// σ_b = √(Σr²/(N−2) / Σ(t − t̄)²). Zero slope and infinite error with fewer than three points.
fn linear_fit_slope(t: &[f64], y: &[f64]) -> (f64, f64) {
    let n = t.len() as f64;
    if t.len() < 3 {
        return (0.0, f64::INFINITY);
    }
    let tm = t.iter().sum::<f64>() / n;
    let ym = y.iter().sum::<f64>() / n;
    let stt: f64 = t.iter().map(|x| (x - tm).powi(2)).sum();
    if stt == 0.0 {
        return (0.0, f64::INFINITY);
    }
    let sty: f64 = t.iter().zip(y).map(|(x, v)| (x - tm) * (v - ym)).sum();
    let b = sty / stt;
    let a = ym - b * tm;
    let rss: f64 = t.iter().zip(y).map(|(x, v)| (v - a - b * x).powi(2)).sum();
    (b, (rss / (n - 2.0) / stt).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn statistics(t: &[f64], error: &[f64], scale: f64, steps: u64) -> Statistics {
        let (size, terms) = (vec![scale; t.len()], vec![1.0; t.len()]);
        let series = Series {
            t,
            error,
            size: &size,
            terms: &terms,
            steps,
        };
        Statistics::new(&series).unwrap()
    }

    fn verdict(t: &[f64], error: &[f64], scale: f64, steps: u64) -> Verdict {
        statistics(t, error, scale, steps).verdict
    }

    #[test]
    fn fit_recovers_an_exact_line() {
        let t: Vec<f64> = (0..50).map(|k| k as f64).collect();
        let y: Vec<f64> = t.iter().map(|x| 2.0 - 0.25 * x).collect();
        let (b, sb) = linear_fit_slope(&t, &y);
        assert!((b + 0.25).abs() < 1e-14 && sb < 1e-14);
    }

    #[test]
    fn each_verdict_is_reached_at_its_threshold() {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.1).collect();
        let ramp: Vec<f64> = t.iter().map(|x| 1e-6 * x + 1e-7 * (3.0 * x).sin()).collect();
        let wave: Vec<f64> = t.iter().map(|x| 1e-6 * (3.0 * x).sin()).collect();
        assert_eq!(verdict(&t, &ramp, 1.0, 999), Verdict::SecularDrift);
        assert_eq!(verdict(&t, &wave, 1.0, 999), Verdict::Bounded);
        // Round-off: 10 ε √1000 ≈ 7.0e-14 of the terms' size.
        let level = statistics(&t, &wave, 1.0, 999).round_off;
        assert!((level / (10.0 * f64::EPSILON * 1000f64.sqrt()) - 1.0).abs() < 1e-15);
        let small: Vec<f64> = ramp.iter().map(|x| x * 0.99 * level / 1e-4).collect();
        assert_eq!(verdict(&t, &small, 1.0, 999), Verdict::ConservedToRoundOff);
        let above: Vec<f64> = ramp.iter().map(|x| x * 1.01 * level / 1e-4).collect();
        assert_ne!(verdict(&t, &above, 1.0, 999), Verdict::ConservedToRoundOff);
        // Failure: at the scale, or a NaN.
        let big: Vec<f64> = wave.iter().map(|x| x * 1e6).collect();
        let top = big.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert_eq!(verdict(&t, &big, 0.9999 * top, 999), Verdict::Failed);
        assert_eq!(verdict(&t, &big, 1.0001 * top, 999), Verdict::Bounded);
        let mut nan = wave.clone();
        nan[7] = f64::NAN;
        let s = statistics(&t, &nan, 1.0, 999);
        assert_eq!((s.verdict, s.first_non_finite), (Verdict::Failed, Some(7)));
    }

    #[test]
    fn an_oscillation_over_few_periods_is_not_drift() {
        // One slow period of the error over the run: its batch means swing, but do not trend.
        let t: Vec<f64> = (0..400).map(|k| k as f64 * 0.01).collect();
        let slow: Vec<f64> = t
            .iter()
            .map(|x| 1e-6 * (1.0 - (std::f64::consts::TAU * x / 4.0).cos()))
            .collect();
        assert_eq!(verdict(&t, &slow, 1.0, 399), Verdict::Bounded);
    }

    #[test]
    fn an_error_that_shifts_by_less_than_it_oscillates_is_bounded() {
        // As on a chaotic orbit: the band widens six-fold and the mean moves by 0.02, less than
        // the error oscillates; with the mean moving by 1, past the oscillation, it drifts.
        let t: Vec<f64> = (0..4000).map(|k| k as f64 * 0.025).collect();
        let wander = |rate: f64| -> Vec<f64> {
            t.iter()
                .map(|x| (0.05 + 0.25 * (x / 100.0)) * (5.0 * x).sin() + rate * x)
                .collect()
        };
        assert_eq!(verdict(&t, &wander(2e-4), 10.0, 3999), Verdict::Bounded);
        assert_eq!(verdict(&t, &wander(1e-2), 10.0, 3999), Verdict::SecularDrift);
    }

    #[test]
    fn malformed_series_are_refused() {
        let series = Series {
            t: &[0.0, 1.0],
            error: &[0.0],
            size: &[1.0],
            terms: &[1.0],
            steps: 1,
        };
        assert!(Statistics::new(&series).is_err());
    }
}
