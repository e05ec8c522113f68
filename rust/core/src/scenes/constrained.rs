use super::{Problem, State};
use crate::model::{check_dense, Anchor, Constrained, Distances, Generator, Link, Mass, MechanicalSystem};
use crate::{Error, ModelError};

/// Point masses in d dimensions under uniform gravity along the last axis,
/// V = g Σᵢ mᵢ xᵢ,d; coordinates body by body.
#[derive(Clone, Debug)]
pub struct PointMasses {
    d: usize,
    masses: Vec<f64>,
    g: f64,
    mass: Mass,
}

impl PointMasses {
    pub fn new(d: usize, masses: Vec<f64>, g: f64) -> Result<Self, Error> {
        if !g.is_finite() {
            return Err(Error::invalid("g", "must be finite"));
        }
        let mass = Mass::diagonal(masses.iter().flat_map(|&m| std::iter::repeat_n(m, d)).collect())?;
        Ok(PointMasses { d, masses, g, mass })
    }
}

impl MechanicalSystem for PointMasses {
    fn dim(&self) -> usize {
        self.d * self.masses.len()
    }

    fn mass(&self) -> &Mass {
        &self.mass
    }

    fn potential(&self, q: &[f64]) -> Result<f64, ModelError> {
        Ok(self.g
            * self
                .masses
                .iter()
                .enumerate()
                .map(|(i, m)| m * q[i * self.d + self.d - 1])
                .sum::<f64>())
    }

    fn gradient(&self, q: &[f64], grad: &mut [f64]) -> Result<(), ModelError> {
        grad[..q.len()].fill(0.0);
        for (i, m) in self.masses.iter().enumerate() {
            grad[i * self.d + self.d - 1] = self.g * m;
        }
        Ok(())
    }

    /// Rotations about the vertical, in three dimensions.
    fn symmetries(&self) -> Vec<Generator> {
        if self.d == 3 {
            vec![Generator::Rotation {
                axis: 2,
                spatial_dim: 3,
            }]
        } else {
            Vec::new()
        }
    }
}

/// A mechanical system in Cartesian coordinates on rigid links.
pub type LinkedMasses = Constrained<PointMasses, Distances>;

/// A chain of `links` unit masses on unit links hanging from the origin in d dimensions, with
/// g = 1, at rest with every link at `angle` from the downward vertical (in the first plane).
fn chain(d: usize, links: usize, angle: f64) -> Result<(LinkedMasses, Vec<f64>), Error> {
    if links == 0 {
        return Err(Error::invalid("links", "must be at least 1"));
    }
    check_dense("links", links, d.saturating_mul(links))?;
    let system = PointMasses::new(d, vec![1.0; links], 1.0)?;
    let constraints = Distances::new(
        d,
        (0..links)
            .map(|i| Link {
                body: i,
                to: if i == 0 {
                    Anchor::Fixed(vec![0.0; d])
                } else {
                    Anchor::Body(i - 1)
                },
                length: 1.0,
            })
            .collect(),
    );
    let mut q = vec![0.0; d * links];
    for i in 0..links {
        q[i * d] = (i + 1) as f64 * angle.sin();
        q[i * d + d - 1] = -((i + 1) as f64) * angle.cos();
    }
    Ok((Constrained { system, constraints }, q))
}

/// The planar pendulum in Cartesian coordinates (x, y) on x² + y² = 1, m = l = g = 1,
/// U = gy, released from rest 2 rad from the downward vertical (reference/scenes.json,
/// `constrained_pendulum_cartesian`; HLW VII). Its exact solution is the pendulum's.
pub fn cartesian_pendulum() -> Problem<LinkedMasses> {
    let (system, q0) = chain(2, 1, 2.0).expect("valid parameters");
    Problem {
        system,
        initial: State::start(q0, vec![0.0; 2]),
        t_end: 1e4,
        reference: None,
    }
}

/// The spherical pendulum in Cartesian coordinates (x, y, z) on |x| = 1, m = l = g = 1, from
/// θ = 1, θ̇ = 0, φ̇ = 1.2 to T = 50, against the (θ, φ) reference of reference/scenes.json.
/// L_z is conserved.
pub fn cartesian_spherical_pendulum() -> Problem<LinkedMasses> {
    let (system, _) = chain(3, 1, 1.0).expect("valid parameters");
    let at = |theta: f64, phi: f64| {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        vec![st * cp, st * sp, -ct]
    };
    let q0 = at(1.0, 0.0);
    let p0 = vec![0.0, 1.0f64.sin() * 1.2, 0.0];
    Problem {
        system,
        initial: State::start(q0, p0),
        t_end: 50.0,
        reference: Some((
            State {
                t: 50.0,
                q: at(0.962577918129, 65.170838533326),
                p: vec![f64::NAN; 3],
            },
            "reference/scenes.json (spherical pendulum; positions from the angles at T = 50)",
        )),
    }
}

/// A planar chain of `links` unit masses on unit links from the origin, g = 1, released from
/// rest straight at 1 rad from the downward vertical.
pub fn planar_chain(links: usize) -> Result<Problem<LinkedMasses>, Error> {
    let (system, q0) = chain(2, links, 1.0)?;
    Ok(Problem {
        system,
        initial: State {
            t: 0.0,
            p: vec![0.0; q0.len()],
            q: q0,
        },
        t_end: 100.0,
        reference: None,
    })
}
