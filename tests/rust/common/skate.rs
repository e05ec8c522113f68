//! A knife edge (a skate) on an inclined plane, its heading a unit vector (c, s) held to the
//! circle c² + s² = 1, q = (x, y, c, s): holonomic and velocity constraints together
//! (tests/rust/mixed_constraints.rs; the allocation test steps it too).

use nalgebra::DMatrix;
use varmech::model::{HolonomicConstraints, Mass, MechanicalSystem, Mixed, VelocityConstraints};
use varmech::ModelError;

/// L = ½q̇ᵀ diag(m) q̇ + f·q: free masses under a constant force, V = −f·q.
pub struct Pushed {
    pub mass: Mass,
    pub force: Vec<f64>,
}

impl Pushed {
    pub fn new(mass: Vec<f64>, force: Vec<f64>) -> Self {
        Pushed {
            mass: Mass::diagonal(mass).expect("positive masses"),
            force,
        }
    }
}

impl MechanicalSystem for Pushed {
    fn dim(&self) -> usize {
        self.force.len()
    }

    fn mass(&self) -> &Mass {
        &self.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(-q.iter().zip(&self.force).map(|(q, f)| q * f).sum::<f64>())
    }

    fn gradient(&self, _q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad.iter_mut().zip(&self.force).for_each(|(g, f)| *g = -f);
        Ok(())
    }
}

/// Where the knife edge's heading is: an angle φ at `at`, or a unit vector (c, s) at `at`,
/// `at + 1`.
#[derive(Clone, Copy)]
pub enum Heading {
    Angle(usize),
    Vector(usize),
}

/// No sideways slip, s ẋ − c ẏ = 0 with (c, s) the heading.
pub struct KnifeEdge(pub Heading);

impl KnifeEdge {
    fn heading(&self, q: &[f64]) -> (f64, f64) {
        match self.0 {
            Heading::Angle(i) => (q[i].cos(), q[i].sin()),
            Heading::Vector(i) => (q[i], q[i + 1]),
        }
    }
}

impl VelocityConstraints for KnifeEdge {
    fn count(&self) -> usize {
        1
    }

    fn matrix(&self, q: &[f64], a: &mut DMatrix<f64>) -> Result<(), ModelError> {
        let (c, s) = self.heading(q);
        a.fill(0.0);
        (a[(0, 0)], a[(0, 1)]) = (s, -c);
        Ok(())
    }
}

/// The heading's circle ½(c² + s² − 1) = 0 at (`at`, `at + 1`), or the plane z = 0 at `at`.
pub enum Holding {
    Circle(usize),
    Plane(usize),
}

impl HolonomicConstraints for Holding {
    fn count(&self) -> usize {
        1
    }

    fn residual(&self, q: &[f64], g: &mut [f64]) -> Result<(), ModelError> {
        g[0] = match *self {
            Holding::Circle(i) => 0.5 * (q[i] * q[i] + q[i + 1] * q[i + 1] - 1.0),
            Holding::Plane(i) => q[i],
        };
        Ok(())
    }

    fn jacobian(&self, q: &[f64], jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        jac.fill(0.0);
        match *self {
            Holding::Circle(i) => (jac[(0, i)], jac[(0, i + 1)]) = (q[i], q[i + 1]),
            Holding::Plane(i) => jac[(0, i)] = 1.0,
        }
        Ok(())
    }
}

pub const SLOPE: f64 = 1.0;
pub const INERTIA: f64 = 0.5;
pub const OMEGA: f64 = 1.3;

/// The skate with its heading on the circle, and its initial state (heading down the slope,
/// turning at ω, at rest otherwise).
pub fn skate() -> (Mixed<Pushed, Holding, KnifeEdge>, Vec<f64>, Vec<f64>) {
    let model = Mixed {
        system: Pushed::new(vec![1.0, 1.0, INERTIA, INERTIA], vec![SLOPE, 0.0, 0.0, 0.0]),
        holonomic: Holding::Circle(2),
        velocity: KnifeEdge(Heading::Vector(2)),
    };
    (model, vec![0.0, 0.0, 1.0, 0.0], vec![0.0, 0.0, 0.0, INERTIA * OMEGA])
}
