use std::fmt;

/// Whether an invariant's error stays in a band or grows with time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Bounded,
    SecularDrift,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Verdict::Bounded => "bounded",
            Verdict::SecularDrift => "secular drift",
        })
    }
}

/// The energy error e(t) = (H(t) − H₀)/|H₀| of a run (absolute when H₀ = 0), summarised.
///
/// The verdict is "secular drift" when all of these hold, and "bounded" otherwise:
/// - the largest |e| in the last tenth of the run exceeds twice the largest |e| in the first
///   tenth (`growth` > 2): a bounded error oscillates in the same band throughout;
/// - the least-squares slope of e(t) differs from zero by more than three standard errors;
/// - the error in the last tenth exceeds `noise_floor`: errors at round-off level (which grow
///   like √N with compensated summation) are not a method's drift.
#[derive(Clone, Debug, PartialEq)]
pub struct EnergyStatistics {
    pub initial: f64,
    /// max |e| over the run.
    pub max_error: f64,
    /// max e − min e over the run.
    pub band: f64,
    /// max |e| over the first and the last tenth of the run.
    pub max_error_first_tenth: f64,
    pub max_error_last_tenth: f64,
    /// d e/dt from a least-squares line, and its standard error.
    pub drift_rate: f64,
    pub drift_rate_stderr: f64,
    pub verdict: Verdict,
}

impl EnergyStatistics {
    /// Relative errors below this are round-off, whatever their trend.
    pub const NOISE_FLOOR: f64 = 1e-13;

    /// Summarises the energies `h` at times `t` (at least 10 samples for a verdict; fewer are
    /// called bounded when they stay under the noise floor).
    pub fn new(t: &[f64], h: &[f64]) -> Self {
        assert_eq!(t.len(), h.len(), "one energy per time");
        assert!(!t.is_empty(), "an energy series needs at least one sample");
        let initial = h[0];
        let scale = if initial != 0.0 { initial.abs() } else { 1.0 };
        let e: Vec<f64> = h.iter().map(|x| (x - initial) / scale).collect();
        let max_abs = |s: &[f64]| s.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let tenth = (e.len() / 10).max(1);
        let (lo, hi) = e.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        let (drift_rate, drift_rate_stderr) = linear_fit_slope(t, &e);
        let first = max_abs(&e[..tenth]);
        let last = max_abs(&e[e.len() - tenth..]);
        let drifts = last > 2.0 * first && drift_rate.abs() > 3.0 * drift_rate_stderr && last > Self::NOISE_FLOOR;
        EnergyStatistics {
            initial,
            max_error: max_abs(&e),
            band: hi - lo,
            max_error_first_tenth: first,
            max_error_last_tenth: last,
            drift_rate,
            drift_rate_stderr,
            verdict: if drifts {
                Verdict::SecularDrift
            } else {
                Verdict::Bounded
            },
        }
    }
}

/// The error of a conserved quantity J along a run: max |J − J₀|, absolute and relative to |J₀|.
#[derive(Clone, Debug, PartialEq)]
pub struct InvariantStatistics {
    pub initial: f64,
    pub max_abs_error: f64,
    /// max |J − J₀| / |J₀| (equal to the absolute error when J₀ = 0).
    pub max_rel_error: f64,
}

impl InvariantStatistics {
    pub fn new(values: &[f64]) -> Self {
        let initial = values.first().copied().unwrap_or(0.0);
        let max_abs_error = values.iter().fold(0.0_f64, |m, x| m.max((x - initial).abs()));
        let scale = if initial != 0.0 { initial.abs() } else { 1.0 };
        InvariantStatistics {
            initial,
            max_abs_error,
            max_rel_error: max_abs_error / scale,
        }
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

    #[test]
    fn fit_recovers_an_exact_line() {
        let t: Vec<f64> = (0..50).map(|k| k as f64).collect();
        let y: Vec<f64> = t.iter().map(|x| 2.0 - 0.25 * x).collect();
        let (b, sb) = linear_fit_slope(&t, &y);
        assert!((b + 0.25).abs() < 1e-14 && sb < 1e-14);
    }

    #[test]
    fn a_ramp_drifts_and_an_oscillation_is_bounded() {
        let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.1).collect();
        let ramp: Vec<f64> = t.iter().map(|x| 1.0 + 1e-6 * x + 1e-7 * (3.0 * x).sin()).collect();
        let wave: Vec<f64> = t.iter().map(|x| 1.0 + 1e-6 * (3.0 * x).sin()).collect();
        assert_eq!(EnergyStatistics::new(&t, &ramp).verdict, Verdict::SecularDrift);
        assert_eq!(EnergyStatistics::new(&t, &wave).verdict, Verdict::Bounded);
    }
}
