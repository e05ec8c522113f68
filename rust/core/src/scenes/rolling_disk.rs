use nalgebra::DMatrix;

use super::FreeBody;
use super::{Problem, State};
use crate::model::{Generator, Nonholonomic, VelocityConstraints};
use crate::{Error, ModelError};

/// A thin uniform disk of unit mass and radius R rolling upright without slipping on a
/// horizontal plane (a coin on a table), q = (x, y, θ, φ): its contact point (x, y), its heading
/// θ and its rolling angle φ. L = ½(ẋ² + ẏ²) + ½Iθ̇² + ½Jφ̇² with I = R²/4 about a diameter
/// and J = R²/2 about the axle (the height of its centre is constant: no potential), a
/// [`FreeBody`] with the constraints [`Rolling`].
///
/// Conserved: E, p_θ and p_φ. The constraint forces Aᵀλ have no θ component, and their φ
/// component keeps Jφ̇ constant (Jφ̈ = −mR²φ̈), so p_θ = Iθ̇ and p_φ = Jφ̇ are conserved
/// ([`RollingDisk::symmetries`]). x and y are cyclic in L too, but p_x and p_y are not
/// conserved: the momentum turns with the disk.
#[derive(Clone, Copy, Debug)]
pub struct RollingDisk;

/// The disk's rolling: ẋ = Rφ̇cosθ, ẏ = Rφ̇sinθ, A(q) = [[1, 0, 0, −Rcosθ], [0, 1, 0, −Rsinθ]].
/// ∂A/∂q by the trait's differences, as its closure twin takes them, so that the two runs
/// agree to the bit.
#[derive(Clone, Debug)]
pub struct Rolling {
    radius: f64,
}

impl VelocityConstraints for Rolling {
    fn count(&self) -> usize {
        2
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let (s, c) = (q[2].sin(), q[2].cos());
        a.fill(0.0);
        (a[(0, 0)], a[(0, 3)]) = (1.0, -self.radius * c);
        (a[(1, 1)], a[(1, 3)]) = (1.0, -self.radius * s);
        Ok(())
    }
}

impl RollingDisk {
    /// θ and φ, whose momenta the disk conserves.
    pub fn symmetries() -> Vec<Generator> {
        vec![Generator::Cyclic { index: 2 }, Generator::Cyclic { index: 3 }]
    }

    /// The disk of radius R turning at θ̇ = `turn` and rolling at φ̇ = `roll`, from the origin
    /// with heading θ₀ = 0.3, to T = 100. Exact: θ̇ and φ̇ constant, the contact point on the
    /// circle of radius Rφ̇/θ̇, (x, y) = (Rφ̇/θ̇)(sinθ − sinθ₀, cosθ₀ − cosθ), the reference.
    pub fn problem(radius: f64, turn: f64, roll: f64) -> Result<Problem<Nonholonomic<FreeBody, Rolling>>, Error> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::invalid(
                "radius",
                format!("must be finite and positive, got {radius}"),
            ));
        }
        if !(turn.is_finite() && turn != 0.0) {
            return Err(Error::invalid(
                "turn",
                format!("must be finite and non-zero, got {turn}"),
            ));
        }
        if !roll.is_finite() {
            return Err(Error::invalid("roll", format!("must be finite, got {roll}")));
        }
        let r2 = radius * radius;
        let inertia = [1.0, 1.0, 0.25 * r2, 0.5 * r2];
        let (theta0, t_end) = (0.3_f64, 100.0);
        let speed = radius * roll;
        let p0 = vec![
            speed * theta0.cos(),
            speed * theta0.sin(),
            inertia[2] * turn,
            inertia[3] * roll,
        ];
        let theta = theta0 + turn * t_end;
        let circle = speed / turn;
        let reference = State {
            t: t_end,
            q: vec![
                circle * (theta.sin() - theta0.sin()),
                circle * (theta0.cos() - theta.cos()),
                theta,
                roll * t_end,
            ],
            p: vec![speed * theta.cos(), speed * theta.sin(), p0[2], p0[3]],
        };
        Ok(Problem {
            system: Nonholonomic {
                system: FreeBody::new(inertia.to_vec())?,
                constraints: Rolling { radius },
            },
            initial: State::start(vec![0.0, 0.0, theta0, 0.0], p0),
            t_end,
            reference: Some((reference, "exact: θ̇, φ̇ constant, the contact point on a circle")),
        })
    }

    /// E = ½(R²φ̇² + Iθ̇² + Jφ̇²) of the disk of radius R turning at θ̇ and rolling at φ̇.
    pub fn energy(radius: f64, turn: f64, roll: f64) -> f64 {
        let r2 = radius * radius;
        0.5 * (r2 * roll * roll + 0.25 * r2 * turn * turn + 0.5 * r2 * roll * roll)
    }
}
