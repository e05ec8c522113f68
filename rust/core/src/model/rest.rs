//! A model held at rest at a configuration q: the multipliers λ that hold it there (its
//! constraints' reaction at q̇ = 0, [`Reaction`]), the generalized force
//!
//! F(x) = ∂L/∂q(x, 0, t) + Q(x, 0, t) + G(x)ᵀλ,   λ held at q's,
//!
//! whose Jacobian at q is −K̃, K̃ = K − Σᵢλᵢ∇²gᵢ the stiffness on the constraints (their
//! curvature counts: a pendulum's tension is its restoring force), the tangent space ker G(q),
//! and the fastest frequency of the small oscillations there, which bounds a method's step.
//!
//! The fastest frequency is Lanczos's ([`crate::solve::lanczos`]) on the pencil (K̃, M) on the
//! tangent space: K̃v by a forward difference of F along v (one evaluation of ∂L/∂q: its √ε
//! accuracy is far below what a step's limit asks),
//! M⁻¹x = q̇(q, x) − q̇(q, 0) from the inverse Legendre transform (exact for L quadratic in q̇,
//! and O(n) for a constant mass), projected M-orthogonally onto ker G. No matrix of size n × n is
//! formed, so that it costs one force evaluation an iteration whatever n is: a check before a
//! run takes [`Rest::BEFORE_RUN`] iterations at most.

use nalgebra::DMatrix;

use super::constraints::weighted;
use super::{ConstraintSet, HolonomicConstraints, Lagrangian, Reaction};
use crate::solve::difference::forward_step;
use crate::solve::lanczos::{extremes, times_power_of_two};
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::solve::splitmix;
use crate::ModelError;

/// A model at rest at q, with the buffers its force and frequencies take.
pub struct Rest<'a> {
    system: &'a dyn Lagrangian,
    constraints: Option<&'a dyn HolonomicConstraints>,
    q: Vec<f64>,
    t: f64,
    multipliers: Vec<f64>,
    /// G(q), m × n.
    jacobian: DMatrix<f64>,
    force: ForceAtRest,
}

/// G(x)ᵀλ into `out`, G(x) into `g`: the constraints' force at x with the multipliers λ held.
///
/// # Errors
/// The constraints' own.
pub fn reaction_force(
    c: &dyn HolonomicConstraints,
    x: &[f64],
    lambda: &[f64],
    g: &mut DMatrix<f64>,
    out: &mut [f64],
) -> Result<(), ModelError> {
    c.jacobian(x, g)?;
    for (i, o) in out.iter_mut().enumerate() {
        *o = lambda.iter().enumerate().map(|(k, l)| g[(k, i)] * l).sum();
    }
    Ok(())
}

/// The generalized force at rest with the constraints' multipliers held,
/// F(x) = ∂L/∂q(x, 0, t) + Q(x, 0, t) + G(x)ᵀλ, with the buffers it takes (made once, so that a
/// Newton iteration or a Lanczos one allocates nothing for it).
pub struct ForceAtRest {
    zeros: Vec<f64>,
    /// Q(x, 0, t), then G(x)ᵀλ.
    terms: Vec<f64>,
    /// G(x).
    rows: DMatrix<f64>,
}

impl ForceAtRest {
    /// For n coordinates and m constraints.
    pub fn new(n: usize, m: usize) -> Self {
        ForceAtRest {
            zeros: vec![0.0; n],
            terms: vec![0.0; n],
            rows: DMatrix::zeros(m, n),
        }
    }

    /// Writes F(x) of `system` on `constraints` (none: no G(x)ᵀλ) at time t into `out`.
    ///
    /// # Errors
    /// The model's own.
    pub fn evaluate(
        &mut self,
        system: &dyn Lagrangian,
        constraints: Option<&dyn HolonomicConstraints>,
        (x, t): (&[f64], f64),
        lambda: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        system.dl_dq(x, &self.zeros, t, out)?;
        if system.is_forced() {
            system.force(x, &self.zeros, t, &mut self.terms)?;
            out.iter_mut().zip(&self.terms).for_each(|(o, f)| *o += f);
        }
        if let Some(c) = constraints {
            reaction_force(c, x, lambda, &mut self.rows, &mut self.terms)?;
            out.iter_mut().zip(&self.terms).for_each(|(o, f)| *o += f);
        }
        Ok(())
    }
}

/// The fastest frequency of the small oscillations at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fastest {
    /// ω_max = √max(κ_max, −κ_min), κ the eigenvalues of K̃x = κMx on the tangent space: the
    /// largest |λ| of the modes where G = D = 0 (the fastest oscillation, or growth).
    pub omega: f64,
    /// Lanczos iterations, each one evaluation of the force and one of M⁻¹.
    pub iterations: usize,
    /// Whether the estimate met its tolerance (else it is a bound from below).
    pub converged: bool,
}

/// κ_max and κ_min to this relative tolerance: ω_max to half of it.
const TOLERANCE: f64 = 1e-4;

impl<'a> Rest<'a> {
    /// The iterations of a check before a run: an exact answer up to this many degrees of
    /// freedom, else a bound from below. The check is worth at most 1% of a run of 10⁴ steps,
    /// each a force evaluation or more, and an iteration costs one and the vectors' updates; on
    /// the densest top of a spectrum tried (a chain of 100 masses, its highest modes 7e-4
    /// apart) ω_max is then within 5e-4.
    pub const BEFORE_RUN: usize = 32;

    /// The iterations of a diagnosis after a run failed, whose cost no longer matters.
    pub const AFTER_FAILURE: usize = 400;

    /// `system` on `constraints` (if any) at rest at (q, t).
    ///
    /// # Errors
    /// The model's own; C M⁻¹ Cᵀ singular (dependent constraints).
    pub fn new(
        system: &'a dyn Lagrangian,
        constraints: Option<&'a dyn HolonomicConstraints>,
        q: &[f64],
        t: f64,
    ) -> Result<Self, ModelError> {
        let n = q.len();
        let m = constraints.map_or(0, |c| c.count());
        let mut rest = Rest {
            system,
            constraints,
            q: q.to_vec(),
            t,
            multipliers: vec![0.0; m],
            jacobian: DMatrix::zeros(m, n),
            force: ForceAtRest::new(n, m),
        };
        if let Some(c) = constraints {
            c.jacobian(q, &mut rest.jacobian)?;
            // At rest q̇ = 0: p = ∂L/∂q̇(q, 0, t), nonzero with velocity-linear terms.
            let mut p = vec![0.0; n];
            system.dl_dv(q, &vec![0.0; n], t, &mut p)?;
            let mut reaction = Reaction::new(n, m);
            let holonomic = ConstraintSet {
                holonomic: Some(c),
                velocity: None,
            };
            reaction.solve(system, &|q, c, b| holonomic.rows(q, c, b), (q, &p, t))?;
            rest.multipliers = reaction.multipliers;
        }
        Ok(rest)
    }

    /// λ at rest, Lagrange's sign (ṗ = ∂L/∂q + Q + Gᵀλ); empty without constraints.
    pub fn multipliers(&self) -> &[f64] {
        &self.multipliers
    }

    /// Writes F(x) = ∂L/∂q(x, 0, t) + Q(x, 0, t) + G(x)ᵀλ into `out`, λ held at q's.
    fn force(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let at = (x, self.t);
        self.force
            .evaluate(self.system, self.constraints, at, &self.multipliers, out)
    }

    /// An orthonormal basis of the tangent space ker G(q) as columns (n × (n − rank G)): the
    /// identity without constraints.
    pub fn tangent(&self) -> DMatrix<f64> {
        let n = self.q.len();
        if self.jacobian.nrows() == 0 {
            return DMatrix::identity(n, n);
        }
        // The orthogonal projector onto ker G, I − Gᵀ(GGᵀ)⁺G, has eigenvalues 1 (tangent) and 0
        // (normal): a gap of 1, however G is scaled.
        let g = &self.jacobian;
        let gram = g * g.transpose();
        let floor = 1e-12 * gram.amax();
        let pinv = gram
            .pseudo_inverse(floor)
            .unwrap_or_else(|_| DMatrix::zeros(g.nrows(), g.nrows()));
        let projector = DMatrix::identity(n, n) - g.transpose() * pinv * g;
        let eigen = nalgebra::SymmetricEigen::new(projector);
        let columns: Vec<_> = (0..n)
            .filter(|&k| eigen.eigenvalues[k] > 0.5)
            .map(|k| eigen.eigenvectors.column(k).into_owned())
            .collect();
        DMatrix::from_columns(&columns)
    }

    /// The fastest frequency at q ([`Fastest`]), from at most `iterations` of Lanczos on (K̃, M)
    /// on the tangent space.
    ///
    /// # Errors
    /// The model's own; C M⁻¹ Cᵀ singular.
    pub fn fastest(&mut self, iterations: usize) -> Result<Fastest, ModelError> {
        let n = self.q.len();
        let (system, q, t) = (self.system, self.q.clone(), self.t);
        let (zeros, mut rest_velocity) = (vec![0.0; n], vec![0.0; n]);
        system.velocity(&q, &zeros, t, &mut rest_velocity)?;
        let minv = |x: &[f64], out: &mut [f64]| -> Result<(), ModelError> {
            out.fill(0.0);
            system.velocity(&q, x, t, out)?;
            out.iter_mut().zip(&rest_velocity).for_each(|(o, r)| *o -= r);
            Ok(())
        };
        // W = M⁻¹Gᵀ and the LU of S = GW: H r = M⁻¹r − W S⁻¹ G M⁻¹r, the M-orthogonal
        // projection of M⁻¹r onto ker G.
        let m = self.jacobian.nrows();
        let w = weighted(
            &self.jacobian,
            &|_: &[f64], x: &[f64], out: &mut [f64]| minv(x, out),
            &q,
        )?;
        let mut gram = &self.jacobian * &w;
        let mut pivots = vec![0; m];
        if m > 0 && lu_in_place(&mut gram, &mut pivots).is_none() {
            return Err("G M⁻¹ Gᵀ is singular: the constraints are not independent here".into());
        }
        let jacobian = self.jacobian.clone();
        let mut mu = vec![0.0; m];
        let inverse = |r: &[f64], out: &mut [f64]| -> Result<(), ModelError> {
            minv(r, out)?;
            if m > 0 {
                for (k, x) in mu.iter_mut().enumerate() {
                    *x = jacobian.row(k).iter().zip(out.iter()).map(|(g, y)| g * y).sum();
                }
                lu_solve(&gram, &pivots, &mut mu);
                for (i, o) in out.iter_mut().enumerate() {
                    *o -= (0..m).map(|k| w[(i, k)] * mu[k]).sum::<f64>();
                }
            }
            Ok(())
        };
        // K̃v = −[F(q + hv) − F(q)]/h, the move hv of √ε of q's size.
        let size = q.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
        let (mut x, mut moved, mut at_q) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        self.force(&q, &mut at_q)?;
        let stiffness = |v: &[f64], out: &mut [f64]| -> Result<(), ModelError> {
            let largest = v.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
            if largest == 0.0 {
                out.fill(0.0);
                return Ok(());
            }
            let h = forward_step(size) / largest;
            x.iter_mut().zip(&q).zip(v).for_each(|((x, q), v)| *x = q + h * v);
            self.force(&x, &mut moved)?;
            out.iter_mut()
                .zip(moved.iter().zip(at_q.iter()))
                .for_each(|(o, (f, f0))| *o = -(f - f0) / h);
            Ok(())
        };
        let noise = forward_step(1.0);
        // Past the tangent space's dimension a Krylov space has nothing new but the products'
        // noise, which would only blur the Ritz values.
        let dof = n.saturating_sub(m).max(1);
        let found = extremes(&start(n), stiffness, inverse, iterations.min(dof), TOLERANCE, noise)?;
        // κ·2^e, e even: ω = √κ·2^(e/2), representable to ω of 10³⁰⁸ where κ is not.
        let kappa = found.largest.max(-found.smallest);
        let omega = times_power_of_two(kappa.max(0.0).sqrt(), found.exponent / 2);
        if !omega.is_finite() || kappa.is_nan() {
            let reason = "ω_max² at q, the largest eigenvalue κ of K y = κ M y (the stiffness over the mass), is past \
                          the largest float (1.8e308) or not finite; take units of time or mass in which it is smaller";
            return Err(reason.into());
        }
        Ok(Fastest {
            omega,
            iterations: found.iterations,
            // The whole tangent space spanned: T_k's eigenvalues are the pencil's.
            converged: found.converged || found.iterations >= dof,
        })
    }
}

/// The Lanczos start: a fixed covector with every entry nonzero and no pattern a model's
/// modes share (SplitMix64's outputs in [−1, 1] with their magnitude at least ½), so that it
/// has a component along the fastest mode, and the estimate is the same on every run.
fn start(n: usize) -> Vec<f64> {
    splitmix::uniform(n)
        .map(|u| if u < 0.5 { -0.5 - u } else { u })
        .collect()
}
