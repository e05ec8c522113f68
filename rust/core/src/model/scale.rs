//! The size a conserved quantity's error is judged against.

use serde::{Deserialize, Serialize};

/// η = 2⁻¹⁰⁷⁴, the least subnormal number: the spacing of the values below the normal range.
const SUBNORMAL_SPACING: f64 = f64::from_bits(1);

/// Running sizes of a conserved quantity J along a run: its scale, the mean of a size
/// sampled at each saved state (the kinetic energy |T| for the energy, Σ|pᵢξᵢ| for a Noether
/// momentum), and the largest size of the terms J is computed from (|T| + |V| for the energy),
/// which sets J's rounding error.
///
/// An error is *round-off* up to [`Scale::ROUND_OFF`] · (ε · max(terms) + η) · √(1 + steps), a
/// small multiple of the terms' rounding error grown as a random walk over the steps (Brouwer's
/// law for compensated summation); η, the spacing of the subnormal numbers, is the rounding of
/// values that have underflowed (a motion decayed to 1e-310 rounds at η, not at ε of its size:
/// Higham, *Accuracy and Stability of Numerical Algorithms*, §2.1), and *fails* at
/// [`Scale::FAILURE`] × the scale, where J is
/// wrong by its own size. The mean kinetic energy is the energy's scale because it is the size
/// of the motion: |H₀| is no scale when V's zero is arbitrary (H₀ = 0 for a pendulum released
/// at its pivot's height), and max |V| is none for orbits that dive deep into a potential well
/// (Kepler at e = 0.9 has max |V| = 20|H₀|, where an error of |H₀| unbinds the orbit).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scale {
    sum: f64,
    sum_terms: f64,
    samples: u64,
    max_terms: f64,
}

impl Scale {
    /// An error this large relative to the scale fails the run; the default
    /// `max_energy_error` of a run (beyond which an error stops a run beyond the method's
    /// stability limit, and one within it where it grows).
    pub const FAILURE: f64 = 1.0;
    /// Round-off is within this many ε of the terms' size, times √(1 + steps).
    pub const ROUND_OFF: f64 = 10.0;
    /// Rounding that is biased (an implicit method's solve leaves its residual with one sign)
    /// grows the error by at most this many ε of the terms' size a step: slower growth is not
    /// a method's drift.
    pub const BIASED_ROUND_OFF: f64 = 4.0;

    /// Adds a sample: the quantity's size there and the size of its terms.
    pub fn push(&mut self, size: f64, terms: f64) {
        self.sum += size.abs();
        self.sum_terms += terms.abs();
        self.samples += 1;
        self.max_terms = self.max_terms.max(terms.abs());
    }

    /// The mean size over the samples, or the mean size of the terms when the size is zero
    /// throughout (a system at rest has no kinetic energy to measure against).
    pub fn scale(&self) -> f64 {
        let n = self.samples.max(1) as f64;
        if self.sum > 0.0 {
            self.sum / n
        } else {
            self.sum_terms / n
        }
    }

    /// The round-off level after `steps` steps.
    pub fn round_off(&self, steps: u64) -> f64 {
        Self::ROUND_OFF * self.rounding() * (1.0 + steps as f64).sqrt()
    }

    /// The most biased rounding can add over `steps` steps.
    pub fn biased_round_off(&self, steps: u64) -> f64 {
        Self::BIASED_ROUND_OFF * self.rounding() * steps as f64
    }

    /// One rounding of the terms: ε of their size, and η where they have underflowed.
    fn rounding(&self) -> f64 {
        f64::EPSILON * self.max_terms + SUBNORMAL_SPACING
    }

    /// Whether `error` fails after `steps` steps: not finite, or beyond both round-off and
    /// `tolerance` × the scale (`tolerance` is [`Scale::FAILURE`] for the verdicts).
    pub fn fails(&self, error: f64, steps: u64, tolerance: f64) -> bool {
        self.fails_against(error, self.scale(), steps, tolerance)
    }

    /// [`Scale::fails`] against another `scale` (the verdicts' scale less the mean error).
    pub fn fails_against(&self, error: f64, scale: f64, steps: u64, tolerance: f64) -> bool {
        !error.is_finite() || (error.abs() >= tolerance * scale && error.abs() > self.round_off(steps))
    }
}
