//! A knife edge (a skate) on an inclined plane, its heading a unit vector (c, s) held to the
//! circle c² + s² = 1, q = (x, y, c, s): holonomic and velocity constraints together
//! (tests/rust/mixed_constraints.rs; the allocation test steps it too).

use nalgebra::DMatrix;
use varmech::model::{HolonomicConstraints, Lagrangian, Mixed, VelocityConstraints};
use varmech::ModelError;

/// L = ½Σ mᵢq̇ᵢ² + f·q: free masses under a constant force.
pub struct Pushed {
    pub mass: Vec<f64>,
    pub force: Vec<f64>,
}

impl Lagrangian for Pushed {
    fn dim(&self) -> usize {
        self.mass.len()
    }

    fn lagrangian(&self, q: &[f64], v: &[f64], _t: f64) -> Result<f64, ModelError> {
        let kinetic: f64 = v.iter().zip(&self.mass).map(|(v, m)| 0.5 * m * v * v).sum();
        Ok(kinetic + q.iter().zip(&self.force).map(|(q, f)| q * f).sum::<f64>())
    }

    fn dl_dq(&self, _q: &[f64], _v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out.copy_from_slice(&self.force);
        Ok(())
    }

    fn dl_dv(&self, _q: &[f64], v: &[f64], _t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        out.iter_mut().zip(v).zip(&self.mass).for_each(|((o, v), m)| *o = m * v);
        Ok(())
    }

    fn velocity(&self, _q: &[f64], p: &[f64], _t: f64, v: &mut [f64]) -> Result<(), ModelError> {
        v.iter_mut().zip(p).zip(&self.mass).for_each(|((v, p), m)| *v = p / m);
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
        system: Pushed {
            mass: vec![1.0, 1.0, INERTIA, INERTIA],
            force: vec![SLOPE, 0.0, 0.0, 0.0],
        },
        holonomic: Holding::Circle(2),
        velocity: KnifeEdge(Heading::Vector(2)),
    };
    (model, vec![0.0, 0.0, 1.0, 0.0], vec![0.0, 0.0, 0.0, INERTIA * OMEGA])
}
