use super::{Problem, State};
use crate::model::{Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// The mathematical pendulum in its angle q from the downward vertical, H = p²/2 − cos q
/// (g/l = 1, unit mass and length; HLW I.1).
#[derive(Clone, Debug)]
pub struct Pendulum {
    mass: Mass,
}

unit_mass!(Pendulum);

impl Pendulum {
    /// The exact flow from the bottom, (q, p) = (0, p₀) with |p₀| < 2 (libration):
    /// q(t) = 2 arcsin(k sn(t | k²)), p(t) = 2k cn(t | k²) with k = p₀/2.
    pub fn exact_from_bottom(p0: f64, t: f64) -> Result<(f64, f64), Error> {
        if p0.is_nan() || p0.abs() >= 2.0 {
            return Err(Error::invalid(
                "p0",
                format!("the closed form holds for librations, |p0| < 2, got {p0}"),
            ));
        }
        let k = 0.5 * p0;
        let (sn, cn) = jacobi_sn_cn(t, k * k);
        Ok((2.0 * (k * sn).asin(), 2.0 * k * cn))
    }

    /// HLW's protocol: (q, p) = (0, 1) to t = 2π, against the GNI test codes' reference.
    pub fn problem() -> Problem<Self> {
        let t = 2.0 * std::f64::consts::PI;
        Problem {
            system: Self::new(),
            initial: State::start(vec![0.0], vec![1.0]),
            t_end: t,
            reference: Some((
                State {
                    t,
                    q: vec![-0.443944662290259],
                    p: vec![0.897846803312944],
                },
                "Hairer, Lubich & Wanner, GNI I.1; GNI test codes",
            )),
        }
    }
}

impl MechanicalSystem for Pendulum {
    fn dim(&self) -> usize {
        1
    }
    fn mass(&self) -> &Mass {
        &self.mass
    }
    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(-q[0].cos())
    }
    #[inline]
    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad[0] = q[0].sin();
        Ok(())
    }
}

/// Jacobi's sn(u | m) and cn(u | m) for 0 ≤ m < 1 by the arithmetic–geometric mean
/// (Abramowitz & Stegun 16.4.14): aₙ₊₁ = (aₙ + bₙ)/2, bₙ₊₁ = √(aₙbₙ), cₙ₊₁ = (aₙ − bₙ)/2 from
/// (1, √(1−m), √m); φ_N = 2ᴺa_N u; φₙ₋₁ = [φₙ + arcsin((cₙ/aₙ) sin φₙ)]/2; sn = sin φ₀,
/// cn = cos φ₀.
fn jacobi_sn_cn(u: f64, m: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0_f64, (1.0 - m).sqrt());
    let mut ratios = [0.0_f64; 16];
    let mut n = 0;
    while n < ratios.len() {
        let c = 0.5 * (a - b);
        let next = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = next;
        ratios[n] = c / a;
        n += 1;
        if c.abs() <= f64::EPSILON * a {
            break;
        }
    }
    let mut phi = (1u64 << n) as f64 * a * u;
    for r in ratios[..n].iter().rev() {
        phi = 0.5 * (phi + (r * phi.sin()).asin());
    }
    phi.sin_cos()
}
