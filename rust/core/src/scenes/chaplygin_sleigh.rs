use nalgebra::DMatrix;

use super::FreeBody;
use super::{Problem, State};
use crate::model::{Nonholonomic, VelocityConstraints};
use crate::{Error, ModelError};

/// The Chaplygin sleigh: a rigid body of unit mass on a horizontal plane, q = (x, y, θ) of its
/// centre of mass and its heading, with a knife edge (blade) a distance b behind the centre
/// that cannot slip sideways. L = ½(ẋ² + ẏ²) + ½Iθ̇², I about the centre: a [`FreeBody`]
/// with the constraint [`Blade`]. No momentum is conserved: L is invariant under the plane's
/// motions, but the blade's force changes p_x, p_y and p_θ; the energy alone is.
#[derive(Clone, Copy, Debug)]
pub struct ChaplyginSleigh;

/// The blade: the velocity of the point b behind the centre has no sideways component,
/// −ẋsinθ + ẏcosθ − bθ̇ = 0. ∂A/∂q by the trait's differences (as its closure twin).
#[derive(Clone, Debug)]
pub struct Blade {
    distance: f64,
}

impl VelocityConstraints for Blade {
    fn count(&self) -> usize {
        1
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let (s, c) = (q[2].sin(), q[2].cos());
        (a[(0, 0)], a[(0, 1)], a[(0, 2)]) = (-s, c, -self.distance);
        Ok(())
    }
}

impl ChaplyginSleigh {
    /// The sleigh (m = 1, moment of inertia I about the centre, blade b behind it) spinning in
    /// place at θ̇ = ω₀ from the origin, heading along x, to T = 40. With u the forward speed
    /// of the centre, u̇ = bω², ω̇ = −buω/(I + b²); from u₀ = 0, in closed form,
    /// u = U tanh κt, ω = ω₀ sech κt, θ = (ω₀/κ) gd κt (gd the Gudermannian), U = √(2E),
    /// κ = bU/(I + b²), E = ½(I + b²)ω₀²: it relaxes to straight-line motion at speed U. The
    /// reference holds θ and the momenta at T; its x and y (integrals of those) are NaN.
    pub fn problem(inertia: f64, blade: f64, spin: f64) -> Result<Problem<Nonholonomic<FreeBody, Blade>>, Error> {
        super::positive(&[("inertia", inertia), ("blade", blade)])?;
        if !spin.is_finite() {
            return Err(Error::invalid("spin", format!("must be finite, got {spin}")));
        }
        let t_end = 40.0;
        let total = inertia + blade * blade;
        let speed = (total * spin * spin).sqrt();
        let kappa = blade * speed / total;
        let (u, omega, theta) = if kappa > 0.0 {
            let x = kappa * t_end;
            let gd = 2.0 * (0.5 * x).tanh().atan();
            (speed * x.tanh(), spin / x.cosh(), spin / kappa * gd)
        } else {
            (0.0, 0.0, 0.0)
        };
        let (s, c) = theta.sin_cos();
        let reference = State {
            t: t_end,
            q: vec![f64::NAN, f64::NAN, theta],
            p: vec![u * c - blade * omega * s, u * s + blade * omega * c, inertia * omega],
        };
        Ok(Problem {
            system: Nonholonomic {
                system: FreeBody::new(vec![1.0, 1.0, inertia])?,
                constraints: Blade { distance: blade },
            },
            initial: State::start(vec![0.0, 0.0, 0.0], vec![0.0, blade * spin, inertia * spin]),
            t_end,
            reference: Some((
                reference,
                "closed form: u = U tanh κt, ω = ω₀ sech κt, θ = (ω₀/κ) gd κt",
            )),
        })
    }
}
