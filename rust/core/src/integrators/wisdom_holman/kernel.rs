//! The Wisdom–Holman kernel's operators on the Jacobi variables: the Kepler drift K(t), the
//! interaction kick I(t) and the modified kick of Wisdom, Holman & Touma (1996).

use super::{interaction_accelerations, kepler_drift, Jacobi};
use serde::{Deserialize, Serialize};

/// The kernel between two drifts: K(h/2) · kick · K(h/2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Kernel {
    /// The kick I(h) of Wisdom & Holman (1991): error O(εh²) (O(ε²h²) once corrected).
    Standard,
    /// The "lazy implementer's" modified kick of Wisdom, Holman & Touma (1996, §10; Rein,
    /// Tamayo & Brown 2019's WHCKL): the kick of the modified interaction
    /// H̃_I = H_I − (h²/24)Σᵢ|∂H_I/∂x′ᵢ|²/m′ᵢ, whose force is taken at displaced positions,
    /// a′(x′ + (h²/12)a′(x′)), which it equals to O(h⁴ε³). It removes the ε²h² term of the
    /// corrected error, at two force evaluations a step.
    LazyModifiedKick,
}

impl Kernel {
    /// Evaluations of the interaction forces a step.
    pub fn force_evaluations(self) -> u64 {
        match self {
            Kernel::Standard => 1,
            Kernel::LazyModifiedKick => 2,
        }
    }
}

/// The kick's work buffers: body-by-body positions and the accelerations.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct Work {
    pub(super) inertial: Vec<[f64; 3]>,
    pub(super) acc: Vec<[f64; 3]>,
    /// The modified kick's displaced Jacobi positions.
    pub(super) displaced: Vec<[f64; 3]>,
}

impl Work {
    pub(super) fn new(bodies: usize) -> Self {
        let zeros = || vec![[0.0; 3]; bodies];
        Work {
            inertial: zeros(),
            acc: zeros(),
            displaced: zeros(),
        }
    }
}

/// Jacobi positions and velocities with their compensated-summation carries.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(super) struct Variables {
    pub(super) x: Vec<[f64; 3]>,
    pub(super) v: Vec<[f64; 3]>,
    pub(super) ex: Vec<[f64; 3]>,
    pub(super) ev: Vec<[f64; 3]>,
}

impl Variables {
    pub(super) fn new(bodies: usize) -> Self {
        let zeros = || vec![[0.0; 3]; bodies];
        Variables {
            x: zeros(),
            v: zeros(),
            ex: zeros(),
            ev: zeros(),
        }
    }

    pub(super) fn copy_from(&mut self, other: &Variables) {
        self.x.copy_from_slice(&other.x);
        self.v.copy_from_slice(&other.v);
        self.ex.copy_from_slice(&other.ex);
        self.ev.copy_from_slice(&other.ev);
    }

    pub(super) fn is_finite(&self) -> bool {
        self.x.iter().chain(&self.v).flatten().all(|c| c.is_finite())
    }

    /// The Kepler drift K(dt) of every Jacobi coordinate, and the centre of mass's straight line.
    pub(super) fn drift(&mut self, jacobi: &Jacobi, dt: f64, compensated: bool) {
        let bodies = self
            .x
            .iter_mut()
            .zip(&mut self.v)
            .zip(self.ex.iter_mut().zip(&mut self.ev));
        for (((x, v), (ex, ev)), &mu) in bodies.zip(jacobi.mu()).skip(1) {
            let (dx, dv) = kepler_drift(*x, *v, mu, dt);
            add(x, ex, dx, compensated);
            add(v, ev, dv, compensated);
        }
        let v0 = self.v[0];
        add(&mut self.x[0], &mut self.ex[0], v0.map(|c| c * dt), compensated);
    }

    /// The interaction kick I(dt): v′ᵢ += dt·a′ᵢ(x′), i ≥ 1.
    pub(super) fn kick(&mut self, jacobi: &Jacobi, dt: f64, compensated: bool, work: &mut Work) {
        interaction_accelerations(jacobi, &self.x, &mut work.inertial, &mut work.acc);
        self.add_kick(dt, compensated, work);
    }

    /// The kernel's kick over the step h: I(h), or the modified kick (see [`Kernel`]).
    pub(super) fn kernel_kick(&mut self, kernel: Kernel, jacobi: &Jacobi, h: f64, compensated: bool, work: &mut Work) {
        match kernel {
            Kernel::Standard => self.kick(jacobi, h, compensated, work),
            Kernel::LazyModifiedKick => {
                interaction_accelerations(jacobi, &self.x, &mut work.inertial, &mut work.acc);
                let c = h * h / 12.0;
                work.displaced[0] = self.x[0];
                for i in 1..self.x.len() {
                    work.displaced[i] = std::array::from_fn(|k| self.x[i][k] + c * work.acc[i][k]);
                }
                interaction_accelerations(jacobi, &work.displaced, &mut work.inertial, &mut work.acc);
                self.add_kick(h, compensated, work);
            }
        }
    }

    /// v′ᵢ += dt·a′ᵢ, i ≥ 1, the accelerations in `work`.
    fn add_kick(&mut self, dt: f64, compensated: bool, work: &Work) {
        for i in 1..self.v.len() {
            add(
                &mut self.v[i],
                &mut self.ev[i],
                work.acc[i].map(|c| c * dt),
                compensated,
            );
        }
    }
}

/// x += δ, with Kahan's carry e when `compensated` (HLW VIII.5, Algorithm 5.1).
#[inline(always)]
fn add(x: &mut [f64; 3], e: &mut [f64; 3], d: [f64; 3], compensated: bool) {
    if compensated {
        for k in 0..3 {
            let sum = e[k] + d[k];
            let next = x[k] + sum;
            e[k] = sum + (x[k] - next);
            x[k] = next;
        }
    } else {
        for k in 0..3 {
            x[k] += d[k];
        }
    }
}
