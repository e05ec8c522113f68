use std::f64::consts::PI;

use nalgebra::DMatrix;

use super::{Problem, State};
use crate::model::{Generator, Lagrangian, Nonholonomic, VelocityConstraints};
use crate::{Error, ModelError};

/// A homogeneous ball of unit mass and radius a (I = 2a²/5) rolling without slipping on a
/// rough plane, q = (x, y, φ, θ, ψ): its centre in the plane and its ZXZ Euler angles, whose
/// space-frame angular velocity is
///
/// ω = (θ̇cosφ + ψ̇sinθsinφ, θ̇sinφ − ψ̇sinθcosφ, φ̇ + ψ̇cosθ),
///
/// so that L = ½(ẋ² + ẏ²) + ½I(φ̇² + θ̇² + ψ̇² + 2φ̇ψ̇cosθ) + g sinα x on a plane inclined at
/// α with x down the slope (g sinα = 0 on a level table). The Euler angles are singular at
/// θ = 0, π; the scenes start the body's third axis where the motion keeps it away.
#[derive(Clone, Debug)]
pub struct RollingSphere {
    inertia: f64,
    /// g sinα, the gravity along the slope.
    slope: f64,
}

/// The ball's contact with its plane: no slip relative to the plane's own velocity there,
/// ẋ − aω_y = −Ωy and ẏ + aω_x = Ωx on a table turning at Ω about the origin (Ω = 0 for a
/// fixed plane): A(q)q̇ + b(q) = 0 with b = (Ωy, −Ωx), affine for Ω ≠ 0. ∂A/∂q and ∂b/∂q by
/// the trait's differences, as its closure twin takes them, so that the two agree to the bit.
#[derive(Clone, Debug)]
pub struct SphereContact {
    radius: f64,
    /// Ω, the table's rate.
    rate: f64,
}

impl SphereContact {
    /// Ω, the table's rate (0 for a fixed plane).
    pub fn rate(&self) -> f64 {
        self.rate
    }
}

impl VelocityConstraints for SphereContact {
    fn count(&self) -> usize {
        2
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let (sp, cp, st) = (q[2].sin(), q[2].cos(), q[3].sin());
        let r = self.radius;
        a.fill(0.0);
        (a[(0, 0)], a[(0, 3)], a[(0, 4)]) = (1.0, -r * sp, r * (st * cp));
        (a[(1, 1)], a[(1, 3)], a[(1, 4)]) = (1.0, r * cp, r * (st * sp));
        Ok(())
    }

    fn is_affine(&self) -> bool {
        self.rate != 0.0
    }

    fn offset(&self, q: &[f64], b: &mut [f64]) -> Result<(), ModelError> {
        (b[0], b[1]) = (self.rate * q[1], -(self.rate * q[0]));
        Ok(())
    }
}

impl Lagrangian for RollingSphere {
    fn dim(&self) -> usize {
        5
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let spin = v[2] * v[2] + v[3] * v[3] + v[4] * v[4] + 2.0 * v[2] * v[4] * q[3].cos();
        Ok(0.5 * (v[0] * v[0] + v[1] * v[1]) + 0.5 * self.inertia * spin + self.slope * q[0])
    }

    fn dl_dq(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out.fill(0.0);
        out[0] = self.slope;
        out[3] = -(self.inertia * v[2] * v[4] * q[3].sin());
        Ok(())
    }

    fn dl_dv(&self, q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let (i, c) = (self.inertia, q[3].cos());
        out.copy_from_slice(&[v[0], v[1], i * (v[2] + v[4] * c), i * v[3], i * (v[4] + v[2] * c)]);
        Ok(())
    }
}

/// The momenta the ball conserves: p_φ = Iω_z (index 2), its spin about the plane's normal
/// (the contact force's torque lies in the plane, and A has no φ column), to round-off by the
/// discrete method too. On the incline the exact motion also keeps p_y = ẏ (the friction has
/// no component across the slope, Byerly), but the discrete one only to O(h²) (1.3e-4 at
/// h = 0.1 over T = 1), so it is not declared; p_x, p_θ and p_ψ are not conserved, nor p_y on
/// the turntable, though L depends on neither x nor y.
pub fn sphere_symmetries(_contact: &SphereContact) -> Vec<Generator> {
    vec![Generator::Cyclic { index: 2 }]
}

impl RollingSphere {
    /// The ball on the rough plane inclined at α (0 ≤ α < π/2) under gravity g, from the
    /// origin with centre velocity (vx, vy) and `spin` ω_z about the normal, to T = 1. Exact
    /// (Byerly; reference/impulses_and_rolling.md): the centre moves with constant
    /// acceleration (5/7)g sinα down the slope and uniformly across it, on a parabola; the
    /// reference holds the centre and p_x, p_y, p_φ at T (the other angles and momenta NaN).
    pub fn incline(
        alpha: f64,
        g: f64,
        radius: f64,
        velocity: [f64; 2],
        spin: f64,
    ) -> Result<Problem<Nonholonomic<Self, SphereContact>>, Error> {
        if !(alpha.is_finite() && (0.0..0.5 * PI).contains(&alpha)) {
            return Err(Error::invalid("alpha", format!("must be in [0, π/2), got {alpha}")));
        }
        super::finite(&[("g", g), ("vx0", velocity[0]), ("vy0", velocity[1]), ("spin", spin)])?;
        let (sphere, contact) = Self::ball(radius, g * alpha.sin(), 0.0)?;
        let [vx, vy] = velocity;
        let omega = [-vy / radius, vx / radius, spin];
        let (q0, p0) = sphere.start([0.0, 0.0], velocity, omega, 0.0)?;
        let (t_end, acceleration) = (1.0, 5.0 / 7.0 * sphere.slope);
        let nan = f64::NAN;
        let reference = State {
            t: t_end,
            q: vec![
                vx * t_end + 0.5 * acceleration * t_end * t_end,
                vy * t_end,
                nan,
                nan,
                nan,
            ],
            p: vec![vx + acceleration * t_end, vy, sphere.inertia * spin, nan, nan],
        };
        Ok(sphere.problem(
            contact,
            (q0, p0),
            (reference, "Byerly: (5/7)g sin α down the slope, a parabola"),
        ))
    }

    /// The ball on a level table turning at Ω > 0 about the origin, from the centre position
    /// `centre` with velocity `velocity` and `spin` ω_z about the normal, to T = 14π/Ω, two
    /// orbits: its centre's velocity turns at ν = (2/7)Ω, so that the centre runs round a circle
    /// of radius |v|/ν about c = r + (−ẏ, ẋ)/ν, back to its start at T, the reference (the
    /// angles and their momenta NaN, but p_φ = Iω_z).
    pub fn turntable(
        rate: f64,
        radius: f64,
        centre: [f64; 2],
        velocity: [f64; 2],
        spin: f64,
    ) -> Result<Problem<Nonholonomic<Self, SphereContact>>, Error> {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(Error::invalid(
                "omega",
                format!("must be finite and positive, got {rate}"),
            ));
        }
        super::finite(&[
            ("x0", centre[0]),
            ("y0", centre[1]),
            ("vx0", velocity[0]),
            ("vy0", velocity[1]),
            ("spin", spin),
        ])?;
        let (sphere, contact) = Self::ball(radius, 0.0, rate)?;
        let ([x, y], [vx, vy]) = (centre, velocity);
        let omega = [(rate * x - vy) / radius, (vx + rate * y) / radius, spin];
        let (q0, p0) = sphere.start(centre, velocity, omega, 2.0 / 7.0 * rate)?;
        let t_end = 14.0 * PI / rate;
        let nan = f64::NAN;
        let reference = State {
            t: t_end,
            q: vec![x, y, nan, nan, nan],
            p: vec![vx, vy, sphere.inertia * spin, nan, nan],
        };
        Ok(sphere.problem(
            contact,
            (q0, p0),
            (reference, "exact: the centre turns at 2Ω/7 on a circle, back at 14π/Ω"),
        ))
    }

    /// J = E − Ω(x p_y − y p_x), the ball's Jacobi integral on the table turning at Ω:
    /// dE/dt = Ω(xF_y − yF_x) = Ω d/dt(x ẏ − y ẋ) for the contact force F (unit mass), so
    /// that J is conserved while E is not.
    pub fn jacobi_integral(&self, rate: f64, q: &[f64], p: &[f64]) -> Result<f64, ModelError> {
        Ok(self.energy(q, p, 0.0)? - rate * (q[0] * p[1] - q[1] * p[0]))
    }

    /// The problem of the ball on `contact` from (q₀, p₀) to the time of its `reference`.
    fn problem(
        self,
        contact: SphereContact,
        (q, p): (Vec<f64>, Vec<f64>),
        reference: (State, &'static str),
    ) -> Problem<Nonholonomic<Self, SphereContact>> {
        Problem {
            system: Nonholonomic {
                system: self,
                constraints: contact,
            },
            initial: State::start(q, p),
            t_end: reference.0.t,
            reference: Some(reference),
        }
    }

    /// The ball of radius a > 0 (I = 2a²/5) with gravity g sinα along x, on a table turning at Ω.
    fn ball(radius: f64, slope: f64, rate: f64) -> Result<(Self, SphereContact), Error> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::invalid(
                "radius",
                format!("must be finite and positive, got {radius}"),
            ));
        }
        let sphere = RollingSphere {
            inertia: 0.4 * radius * radius,
            slope,
        };
        Ok((sphere, SphereContact { radius, rate }))
    }

    /// (q₀, p₀) with the centre at `centre` moving at `velocity`, turning at ω (space frame),
    /// the body's third axis along ω − νẑ: the axis the body turns about in the frame that
    /// turns with its centre's velocity at ν, where it stays (exactly so on an orbit about the
    /// table's centre), so that θ stays away from the Euler angles' singularities.
    fn start(
        &self,
        centre: [f64; 2],
        velocity: [f64; 2],
        omega: [f64; 3],
        nu: f64,
    ) -> Result<(Vec<f64>, Vec<f64>), Error> {
        let axis = [omega[0], omega[1], omega[2] - nu];
        let norm = axis.iter().map(|x| x * x).sum::<f64>().sqrt();
        let (phi, theta) = if norm > 0.0 {
            (axis[0].atan2(-axis[1]), (axis[2] / norm).clamp(-1.0, 1.0).acos())
        } else {
            (PI, 0.5 * PI)
        };
        let (sp, cp, st, ct) = (phi.sin(), phi.cos(), theta.sin(), theta.cos());
        let theta_dot = omega[0] * cp + omega[1] * sp;
        let psi_dot = (omega[0] * sp - omega[1] * cp) / st;
        let phi_dot = omega[2] - psi_dot * ct;
        let q0 = vec![centre[0], centre[1], phi, theta, 0.0];
        let mut p0 = vec![0.0; 5];
        let v0 = [velocity[0], velocity[1], phi_dot, theta_dot, psi_dot];
        self.dl_dv(&q0, &v0, 0.0, &mut p0)
            .map_err(|e| Error::invalid("vx0", e.to_string()))?;
        Ok((q0, p0))
    }
}
