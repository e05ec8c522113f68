use std::convert::Infallible;

use super::{Problem, State};
use crate::model::{Generator, Hessians, Lagrangian};
use crate::solve::bracket::bisect;
use crate::{Error, ModelError};

/// The heavy symmetric top about a fixed point, in Euler angles q = (θ, φ, ψ): the nutation θ
/// of its figure axis from the UPWARD vertical, the precession φ about the vertical and the
/// spin ψ about the figure axis,
///
/// L = ½I₁(θ̇² + sin²θ φ̇²) + ½I₃(ψ̇ + φ̇ cos θ)² − Mgl cos θ,
///
/// with I₁ the moment of inertia about an axis through the fixed point perpendicular to the
/// figure axis, I₃ the one about the figure axis, and Mgl the weight times the distance of the
/// centre of mass from the fixed point (Goldstein, Classical Mechanics, 3rd ed., § 5.7).
///
/// Its mass matrix depends on θ, so it is a general Lagrangian. φ and ψ are cyclic: their
/// momenta p_φ = I₁ sin²θ φ̇ + p_ψ cos θ and p_ψ = I₃ω₃, with ω₃ = ψ̇ + φ̇ cos θ the spin, are
/// conserved (by the variational integrators, to round-off). The coordinates are singular at
/// sin θ = 0 (the figure axis vertical), where φ and ψ are not separately defined.
#[derive(Clone, Debug)]
pub struct HeavyTop {
    i1: f64,
    i3: f64,
    mgl: f64,
}

impl HeavyTop {
    /// I₁ and I₃ must be finite and positive, Mgl finite (Mgl < 0 puts the centre of mass below
    /// the fixed point).
    pub fn new(i1: f64, i3: f64, mgl: f64) -> Result<Self, Error> {
        super::positive(&[("i1", i1), ("i3", i3)])?;
        if !mgl.is_finite() {
            return Err(Error::invalid("mgl", format!("must be finite, got {mgl}")));
        }
        Ok(HeavyTop { i1, i3, mgl })
    }

    /// The cyclic precession and spin angles, whose momenta p_φ and p_ψ are conserved.
    pub fn symmetries(&self) -> Vec<Generator> {
        vec![Generator::Cyclic { index: 1 }, Generator::Cyclic { index: 2 }]
    }

    /// The two precession rates φ̇ (slow, fast) of steady precession at the fixed nutation angle
    /// θ (from the upward vertical) with the spin ω₃ = ψ̇ + φ̇ cos θ, or `None` when there is no
    /// real one (or sin θ = 0, where the Euler angles are singular).
    ///
    /// The θ equation of motion is I₁θ̈ = ∂L/∂θ = sin θ (I₁φ̇² cos θ − I₃ω₃φ̇ + Mgl). At
    /// θ̇ = θ̈ = 0 and sin θ ≠ 0 it requires
    ///
    /// Mgl = φ̇(I₃ω₃ − I₁φ̇ cos θ), i.e. I₁cos θ φ̇² − I₃ω₃φ̇ + Mgl = 0
    ///
    /// (Goldstein (5.76); measured from the downward vertical, θ → π − θ flips the sign of
    /// Mgl). Its roots are φ̇ = [I₃ω₃ ± √(I₃²ω₃² − 4I₁Mgl cos θ)] / (2I₁ cos θ), computed
    /// without cancellation as slow = Mgl/Q and fast = Q/(I₁ cos θ) with
    /// Q = ½(I₃ω₃ + sgn(I₃ω₃)√(I₃²ω₃² − 4I₁Mgl cos θ)); |slow| ≤ |fast|. For a fast top the
    /// slow rate tends to Mgl/(I₃ω₃) and the fast one to I₃ω₃/(I₁ cos θ). At θ = π/2 the
    /// equation is linear: the fast root is at infinity and returned as ±∞. The spin ψ̇ of the
    /// steady motion is ω₃ − φ̇ cos θ.
    pub fn steady_precession(&self, theta: f64, omega3: f64) -> Option<(f64, f64)> {
        let (s, c) = theta.sin_cos();
        if s == 0.0 || !theta.is_finite() || !omega3.is_finite() {
            return None;
        }
        let (a, b) = (self.i1 * c, self.i3 * omega3); // a φ̇² − b φ̇ + Mgl = 0
        let discriminant = b * b - 4.0 * a * self.mgl;
        if discriminant < 0.0 {
            return None;
        }
        let q = 0.5 * (b + discriminant.sqrt().copysign(b));
        if q == 0.0 {
            // b = 0 and a·Mgl = 0: a φ̇² = 0 (a double root at 0, or every φ̇ when a = 0 too).
            return Some((0.0, 0.0));
        }
        Some((self.mgl / q, q / a))
    }

    /// The turning points (θ_min, θ_max) of the nutation with the conserved momenta p_φ, p_ψ
    /// and energy E, or `None` when no θ is reachable with them.
    ///
    /// With u = cos θ, E = ½I₁θ̇² + (p_φ − p_ψu)²/(2I₁(1 − u²)) + p_ψ²/(2I₃) + Mglu gives
    ///
    /// u̇² = f(u) = (1 − u²)(α − βu) − (b − au)²,
    ///
    /// α = (2E − p_ψ²/I₃)/I₁, β = 2Mgl/I₁, a = p_ψ/I₁, b = p_φ/I₁
    ///
    /// (Goldstein (5.63)–(5.65)). The motion keeps f(u) ≥ 0, and f(±1) = −(b ∓ a)² ≤ 0, so it
    /// lies between the two roots of the cubic f in [−1, 1] around its maximum there: u_max at
    /// θ_min and u_min at θ_max. They are found by locating the maximum of f on [−1, 1] (a root
    /// of the quadratic f′, or an end) and bisecting f on each side of it to adjacent floating-
    /// point numbers. In steady precession the two coincide (to about √ε, as a double root).
    pub fn turning_points(&self, p_phi: f64, p_psi: f64, energy: f64) -> Option<(f64, f64)> {
        if !(p_phi.is_finite() && p_psi.is_finite() && energy.is_finite()) {
            return None;
        }
        let alpha = (2.0 * energy - p_psi * p_psi / self.i3) / self.i1;
        let beta = 2.0 * self.mgl / self.i1;
        let (a, b) = (p_psi / self.i1, p_phi / self.i1);
        let f = |u: f64| (1.0 - u) * (1.0 + u) * (alpha - beta * u) - (b - a * u).powi(2);
        // f(u) = βu³ − (α + a²)u² + (2ab − β)u + α − b², so f′(u) = 3βu² − 2(α + a²)u + 2ab − β.
        let (c2, c1, c0) = (3.0 * beta, -2.0 * (alpha + a * a), 2.0 * a * b - beta);
        let mut candidates = vec![-1.0, 1.0];
        if c2 != 0.0 {
            let d = c1 * c1 - 4.0 * c2 * c0;
            if d >= 0.0 {
                let q = -0.5 * (c1 + d.sqrt().copysign(c1));
                if q != 0.0 {
                    candidates.extend([q / c2, c0 / q]);
                } else {
                    candidates.push(0.0);
                }
            }
        } else if c1 != 0.0 {
            candidates.push(-c0 / c1);
        }
        let top = candidates
            .into_iter()
            .filter(|u| (-1.0..=1.0).contains(u))
            .map(|u| (u, f(u)))
            .fold(
                (f64::NAN, f64::NEG_INFINITY),
                |best, x| if x.1 > best.1 { x } else { best },
            );
        let (u_top, f_top) = top;
        if f_top < 0.0 || f_top.is_nan() {
            return None;
        }
        // Bisection between a point where f < 0 (or an end) and one where f ≥ 0, until the two
        // are adjacent; returns the point where f ≥ 0 (inside the motion).
        let boundary = |outside: f64, inside: f64| {
            if f(outside) >= 0.0 {
                return outside;
            }
            let holds = |u: f64| Ok::<_, Infallible>(f(u) >= 0.0);
            let Ok((inside, _)) = bisect(holds, (inside, outside), usize::MAX, |_, _| true);
            inside
        };
        let (u_min, u_max) = (boundary(-1.0, u_top), boundary(1.0, u_top));
        Some((u_max.acos(), u_min.acos()))
    }

    /// A fast top (I₁ = 1, I₃ = 1/2, Mgl = 1) released at θ₀ = 0.3 with θ̇₀ = φ̇₀ = 0 and the
    /// spin ψ̇₀ = ω₃ = 5, to T = 50. p_ψ² = 6.25 exceeds 4I₁Mgl = 4, so a sleeping top with this
    /// spin would be stable. Released without precession, it falls and nutates in cusps between
    /// θ_min = θ₀ = 0.3 and θ_max = 0.47947487… (from [`HeavyTop::turning_points`]), 13 times
    /// by T = 50, while it precesses. No reference state: the analytic check is the
    /// nutation band, and the momenta p_φ = p_ψ cos θ₀ and p_ψ = 2.5 are conserved.
    pub fn problem() -> Problem<Self> {
        let system = Self::new(1.0, 0.5, 1.0).expect("valid parameters");
        let q0 = vec![0.3, 0.0, 0.0];
        let mut p0 = vec![0.0; 3];
        system.dl_dv(&q0, &[0.0, 0.0, 5.0], 0.0, &mut p0).expect("exact");
        Problem {
            initial: State::start(q0, p0),
            t_end: 50.0,
            reference: None,
            system,
        }
    }
}

impl Lagrangian for HeavyTop {
    fn dim(&self) -> usize {
        3
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let (s, c) = q[0].sin_cos();
        let spin = v[2] + v[1] * c;
        Ok(0.5 * self.i1 * (v[0] * v[0] + s * s * v[1] * v[1]) + 0.5 * self.i3 * spin * spin - self.mgl * c)
    }

    /// ∂L/∂θ = sin θ (I₁φ̇² cos θ − I₃ω₃φ̇ + Mgl), ∂L/∂φ = ∂L/∂ψ = 0.
    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let (s, c) = q[0].sin_cos();
        let spin = v[2] + v[1] * c;
        out[0] = s * (self.i1 * v[1] * v[1] * c - self.i3 * spin * v[1] + self.mgl);
        out[1] = 0.0;
        out[2] = 0.0;
        Ok(())
    }

    /// p_θ = I₁θ̇, p_φ = I₁ sin²θ φ̇ + I₃ω₃ cos θ, p_ψ = I₃ω₃.
    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let (s, c) = q[0].sin_cos();
        let p_psi = self.i3 * (v[2] + v[1] * c);
        out[0] = self.i1 * v[0];
        out[1] = self.i1 * s * s * v[1] + p_psi * c;
        out[2] = p_psi;
        Ok(())
    }

    /// With s = sin θ, c = cos θ, ω₃ = ψ̇ + φ̇c: L_qq has the one entry
    /// ∂²L/∂θ² = I₁φ̇² cos 2θ + I₃φ̇²s² − I₃ω₃φ̇c + Mgl c; L_qq̇ has the one row
    /// ∂²L/∂θ∂q̇ = (0, 2I₁scφ̇ − I₃s(ω₃ + φ̇c), −I₃sφ̇); and L_q̇q̇ = [[I₁, 0, 0],
    /// [0, I₁s² + I₃c², I₃c], [0, I₃c, I₃]].
    fn hessians(&self, q: &[f64], v: &[f64], _t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let (s, c) = q[0].sin_cos();
        let spin = v[2] + v[1] * c;
        let (i1, i3) = (self.i1, self.i3);
        out.qq.fill(0.0);
        out.qq[(0, 0)] =
            i1 * v[1] * v[1] * (c * c - s * s) + i3 * v[1] * v[1] * s * s - i3 * spin * v[1] * c + self.mgl * c;
        out.qv.fill(0.0);
        out.qv[(0, 1)] = 2.0 * i1 * s * c * v[1] - i3 * s * (spin + v[1] * c);
        out.qv[(0, 2)] = -i3 * s * v[1];
        out.vv.fill(0.0);
        out.vv[(0, 0)] = i1;
        out.vv[(1, 1)] = i1 * s * s + i3 * c * c;
        out.vv[(1, 2)] = i3 * c;
        out.vv[(2, 1)] = i3 * c;
        out.vv[(2, 2)] = i3;
        Ok(true)
    }

    /// The inverse Legendre transform in closed form: θ̇ = p_θ/I₁, ω₃ = p_ψ/I₃,
    /// φ̇ = (p_φ − p_ψ cos θ)/(I₁ sin²θ), ψ̇ = ω₃ − φ̇ cos θ.
    fn velocity(&self, q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        let (s, c) = q[0].sin_cos();
        if s == 0.0 {
            return Err("the Euler angles are singular at sin θ = 0 (the figure axis vertical)".into());
        }
        let phi_dot = (p[1] - p[2] * c) / (self.i1 * s * s);
        v[0] = p[0] / self.i1;
        v[1] = phi_dot;
        v[2] = p[2] / self.i3 - phi_dot * c;
        Ok(())
    }
}
