use std::fmt;

use crate::model::Scale;

/// What a conserved quantity did along a run, judged against its scale (see [`Statistics`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The error stays within the floating-point noise of the quantity's terms.
    ConservedToRoundOff,
    /// The error oscillates in a band that does not grow and is small against the scale.
    Bounded,
    /// The run cannot tell a band from a drift: it took no step, or its error trends over
    /// fewer than [`Statistics::OSCILLATIONS`] oscillations of the motion, or it rose and then
    /// levelled off.
    TooShort,
    /// The error grows: the drift rate differs from zero by more than four standard errors.
    SecularDrift,
    /// The error is of the order of the scale ([`Statistics::TOO_COARSE`] of it or more),
    /// whatever its trend: the step does not resolve the motion.
    TooCoarse,
    /// The error reaches the quantity's scale, or a value is not finite.
    Failed,
}

impl Verdict {
    /// The verdicts in order, best first.
    pub const ALL: [Verdict; 6] = [
        Verdict::ConservedToRoundOff,
        Verdict::Bounded,
        Verdict::TooShort,
        Verdict::SecularDrift,
        Verdict::TooCoarse,
        Verdict::Failed,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Verdict::ConservedToRoundOff => "conserved to round-off",
            Verdict::Bounded => "bounded",
            Verdict::TooShort => "too short to judge",
            Verdict::SecularDrift => "secular drift",
            Verdict::TooCoarse => "too coarse",
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
/// The scale and the round-off level are [`Scale`]'s. The scale is measured on the run's own
/// states, whose J is off by the error, so it is off by as much (Kepler's virial theorem makes
/// the mean kinetic energy −E: an orbit that lost energy is deeper, faster, and its scale
/// larger); the level of the error is therefore judged against `judged_scale`, the scale less
/// the mean |error|. The verdict is the first that applies of:
/// - **failed**: an error is not finite (`first_non_finite` says where), or max |error| reaches
///   [`Scale::FAILURE`] × `judged_scale` and exceeds round-off: the quantity is wrong by its
///   own size;
/// - **conserved to round-off**: max |error| ≤ `round_off`;
/// - **too coarse**: max |error| reaches [`Statistics::TOO_COARSE`] × `judged_scale`: an error
///   of the order of the scale, whatever its trend;
/// - **too short to judge**: the run took no step; or the drift test below fires but the motion
///   oscillates fewer than [`Statistics::OSCILLATIONS`] times over the run (`oscillations`):
///   over a fraction of its motion's recurrence, a bounded error's rise cannot be told from a
///   drift; or the error levelled off: over the run's second half its batch means moved by
///   less than a quarter of what the fitted slope predicts (a transient's rise and plateau);
/// - **secular drift**: the error grows: split into [`Statistics::BATCHES`] batches in time, the
///   least-squares slope of the batch means differs from zero by more than four of its standard
///   errors (batch means make the standard error honest for an error that oscillates, which
///   successive samples are not independent of), the drift over the run exceeds both
///   `round_off` and what biased rounding could add ([`Scale::BIASED_ROUND_OFF`] ε of the
///   terms a step) and the error's oscillation (the median over the batches of the band within
///   a batch: a bounded error that wanders with the state, as on a chaotic orbit, moves its
///   batch means by less than it oscillates), and the largest |error| in the last batch is
///   more than twice that in the first;
/// - **bounded** otherwise: the band does not grow and stays below `TOO_COARSE × judged_scale`.
#[derive(Clone, Debug, PartialEq)]
pub struct Statistics {
    /// The scale of J (see [`Scale`]).
    pub scale: f64,
    /// The scale less the mean |error| over the run, what the error's level is judged against
    /// (see above; zero or less when the error is as large as the scale).
    pub judged_scale: f64,
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
    /// How many times the motion oscillates over the run: half the crossings of J's size
    /// through its mean (infinite when the size varies by no more than round-off or twice
    /// the error's band: there is no recurrence to wait for).
    pub oscillations: f64,
    /// The first sample whose error is not finite.
    pub first_non_finite: Option<usize>,
    pub verdict: Verdict,
}

impl Statistics {
    /// Batches of the drift test (at least four samples each; fewer samples: no drift test).
    pub const BATCHES: usize = 8;
    /// An error this large against `judged_scale` is of the order of the scale (within a
    /// factor √10 of it): "too coarse".
    pub const TOO_COARSE: f64 = 0.3;
    /// The oscillations of the motion a drift needs to be told from a bounded error's rise.
    pub const OSCILLATIONS: f64 = 2.0;

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
        let mean_abs_error = error.iter().map(|x| x.abs()).sum::<f64>() / error.len() as f64;
        let judged_scale = scale - mean_abs_error;
        let (lo, hi) = error.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        let batches = Batches::new(t, error);
        let (drift_rate, drift_rate_stderr) = batches.as_ref().map_or((0.0, f64::INFINITY), |b| (b.slope, b.stderr));
        let floor = judge.biased_round_off(steps).max(round_off);
        let oscillations = oscillations(size, round_off.max(2.0 * (hi - lo)));
        let reaches = |level: f64| judge.fails_against(max_abs_error, judged_scale, steps, level);
        let verdict = if first_non_finite.is_some() || reaches(Scale::FAILURE) {
            Verdict::Failed
        } else if steps == 0 || t.len() < 2 {
            Verdict::TooShort
        } else if max_abs_error <= round_off {
            Verdict::ConservedToRoundOff
        } else if reaches(Self::TOO_COARSE) {
            Verdict::TooCoarse
        } else if let Some(b) = batches.as_ref().filter(|b| b.drifts(t[t.len() - 1] - t[0], floor)) {
            if oscillations < Self::OSCILLATIONS || b.levels_off() {
                Verdict::TooShort
            } else {
                Verdict::SecularDrift
            }
        } else {
            Verdict::Bounded
        };
        Ok(Statistics {
            scale,
            judged_scale,
            round_off,
            max_abs_error,
            max_rel_error: max_abs_error / scale,
            band: hi - lo,
            drift_rate,
            drift_rate_stderr,
            oscillations,
            first_non_finite,
            verdict,
        })
    }
}

/// Half the crossings of `size` through its mean: how many times the motion oscillates;
/// infinite when `size` varies by no more than `noise`, round-off or what the error itself
/// moves it by (a motion at constant size, as a free body's kinetic energy, which is its
/// energy: there is no recurrence to wait for).
fn oscillations(size: &[f64], noise: f64) -> f64 {
    let (lo, hi) = size.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
        (lo.min(x), hi.max(x))
    });
    let range = hi - lo;
    if range.is_nan() || range <= noise {
        return f64::INFINITY;
    }
    let mean = size.iter().sum::<f64>() / size.len() as f64;
    let above: Vec<bool> = size.iter().map(|&x| x > mean).collect();
    0.5 * above.windows(2).filter(|w| w[0] != w[1]).count() as f64
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
    /// How far the batch means moved over the run's second half, as a fraction of what the
    /// slope predicts: about 1 for a steady drift, about 0 for an error that levelled off.
    late: f64,
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
        let half = k / 2 - 1;
        let late = (yb[k - 1] - yb[half]) / (slope * (tb[k - 1] - tb[half]));
        Some(Batches {
            slope,
            stderr,
            growth,
            band: 0.5 * (bands[k / 2 - 1] + bands[k / 2]),
            late,
        })
    }

    /// Whether the error rose and then levelled off: over the second half of the run its batch
    /// means moved by less than a quarter of what the slope predicts. Over such a run a
    /// transient cannot be told from a drift.
    fn levels_off(&self) -> bool {
        self.late.is_nan() || self.late < 0.25
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
        // Too coarse and failed: at 0.3 and 1 times the scale less the mean |error|, or a NaN.
        let big: Vec<f64> = wave.iter().map(|x| x * 1e6).collect();
        let top = big.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let mean = big.iter().map(|x| x.abs()).sum::<f64>() / big.len() as f64;
        let at = |level: f64, factor: f64| verdict(&t, &big, factor * top / level + mean, 999);
        assert_eq!(at(1.0, 0.9999), Verdict::Failed);
        assert_eq!(at(1.0, 1.0001), Verdict::TooCoarse);
        assert_eq!(at(Statistics::TOO_COARSE, 0.9999), Verdict::TooCoarse);
        assert_eq!(at(Statistics::TOO_COARSE, 1.0001), Verdict::Bounded);
        let mut nan = wave.clone();
        nan[7] = f64::NAN;
        let s = statistics(&t, &nan, 1.0, 999);
        assert_eq!((s.verdict, s.first_non_finite), (Verdict::Failed, Some(7)));
    }

    #[test]
    fn an_error_of_a_few_subnormal_spacings_is_round_off() {
        // A motion decayed to 1e-310 rounds at η = 2⁻¹⁰⁷⁴ (4.9e-324), not at ε of its size: a
        // closure chain's energy error of 4η after 106 steps.
        let t: Vec<f64> = (0..107).map(|k| k as f64).collect();
        let error: Vec<f64> = t
            .iter()
            .map(|x| if x % 3.0 == 0.0 { 4.0 * f64::from_bits(1) } else { 0.0 })
            .collect();
        let (size, terms) = (vec![2.75e-312; t.len()], vec![3e-312; t.len()]);
        let series = Series {
            t: &t,
            error: &error,
            size: &size,
            terms: &terms,
            steps: 106,
        };
        assert_eq!(Statistics::new(&series).unwrap().verdict, Verdict::ConservedToRoundOff);
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
    fn an_error_that_inflates_its_own_scale_still_fails() {
        // Midpoint on Kepler e = 0.9 at h = 2π/200 (measured): the first pericentre passage
        // takes H from −0.5 to −1.94, onto a deeper orbit whose mean kinetic energy is 2.38.
        // Against that the error is 0.61; against the scale less the error, 1.5: failed.
        let t: Vec<f64> = (0..400).map(|k| k as f64).collect();
        let error: Vec<f64> = t.iter().map(|&x| if x > 0.0 { -1.44 } else { 0.0 }).collect();
        let s = statistics(&t, &error, 2.38, 399);
        assert!((s.max_rel_error - 1.44 / 2.38).abs() < 1e-12 && s.judged_scale < 1.44);
        assert_eq!(s.verdict, Verdict::Failed);
    }

    #[test]
    fn a_drift_over_less_than_the_motions_recurrence_is_too_short_to_judge() {
        // An error that rises with a size that grows throughout (a ball rolling down a slope):
        // no recurrence of the motion in the run, so no verdict on its trend. The same rise
        // under a size that oscillates ten times is a drift.
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.01).collect();
        let ramp: Vec<f64> = t.iter().map(|x| 1e-6 * x * x).collect();
        let growing: Vec<f64> = t.iter().map(|x| 1.0 + x * x).collect();
        let waving: Vec<f64> = t
            .iter()
            .map(|x| 1.0 + 0.5 * (std::f64::consts::TAU * x).sin())
            .collect();
        let judged = |size: &[f64]| {
            let terms = vec![1.0; t.len()];
            Statistics::new(&Series {
                t: &t,
                error: &ramp,
                size,
                terms: &terms,
                steps: 999,
            })
            .unwrap()
        };
        let (rolling, swinging) = (judged(&growing), judged(&waving));
        assert_eq!((rolling.verdict, rolling.oscillations), (Verdict::TooShort, 0.5));
        assert_eq!(swinging.verdict, Verdict::SecularDrift);
        assert!(swinging.oscillations >= 9.5);
        // A free body's kinetic energy is its energy: the size moves only by the error, which
        // is no motion to wait for. The drift stands.
        let free: Vec<f64> = ramp.iter().map(|e| 1.0 + e).collect();
        let sliding = judged(&free);
        assert_eq!(
            (sliding.verdict, sliding.oscillations),
            (Verdict::SecularDrift, f64::INFINITY)
        );
        // The Chaplygin sleigh over a tenth of its t_end (measured): the error falls to
        // −3.1e-6 by mid-run and levels off there. A plateau, not a drift; the same fall
        // carried on at its pace is one.
        let plateau: Vec<f64> = t.iter().map(|x| -1.5e-6 * (1.0 + ((x - 3.0) / 0.8).tanh())).collect();
        let steady: Vec<f64> = t.iter().map(|x| -3e-7 * x).collect();
        let flat = vec![1.0; t.len()];
        let run = |error: &[f64]| {
            Statistics::new(&Series {
                t: &t,
                error,
                size: &flat,
                terms: &flat,
                steps: 999,
            })
            .unwrap()
            .verdict
        };
        assert_eq!(
            (run(&plateau), run(&steady)),
            (Verdict::TooShort, Verdict::SecularDrift)
        );
        // A run that took no step has nothing to judge.
        assert_eq!(verdict(&[0.0], &[0.0], 1.0, 0), Verdict::TooShort);
        assert_eq!(verdict(&[0.0], &[f64::NAN], 1.0, 0), Verdict::Failed);
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
