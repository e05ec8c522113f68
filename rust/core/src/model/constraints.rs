use nalgebra::{DMatrix, DVector};

use crate::error::StepError;
use crate::solve::difference::{self, central_jacobian, Evaluations};
use crate::solve::newton::{Correction, Newton, NewtonOptions, NewtonProblem, Reasons, Rules};
use crate::{Error, ModelError};

/// Holonomic constraints g(q) = 0, m of them on n coordinates, with their Jacobian G = ∂g/∂q.
///
/// With them a mechanical system moves on the manifold g = 0, and its momenta on the hidden
/// constraint G(q)M⁻¹p = 0 (HLW VII.1).
pub trait HolonomicConstraints {
    /// Number of constraints m.
    fn count(&self) -> usize;

    /// Writes g(q) (m entries) into `g`.
    fn residual(&self, q: &[f64], g: &mut [f64]) -> Result<(), ModelError>;

    /// Writes G(q) = ∂g/∂q (m × n) into `jac`. Default: [`differenced_jacobian`].
    fn jacobian(&self, q: &[f64], jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        differenced_jacobian(self, q, jac)
    }
}

/// G(q) by central differences of g, column by column (2n evaluations of g; they allocate
/// scratch), about 1e-10 relative accuracy.
pub fn differenced_jacobian<C: HolonomicConstraints + ?Sized>(
    constraints: &C,
    q: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let m = jac.nrows();
    let (mut plus, mut minus) = (vec![0.0; m], vec![0.0; m]);
    let at = Evaluations {
        plus: &mut plus,
        minus: &mut minus,
    };
    central_jacobian(
        |x, g| constraints.residual(x, g),
        &mut q.to_vec(),
        difference::unit,
        at,
        jac,
    )
}

/// Rigid distances between point bodies in d dimensions (coordinates laid out body by body),
/// or between a body and a fixed anchor: gₖ = ½(|xᵢ − xⱼ|² − lₖ²), Gₖ = (xᵢ − xⱼ) at body i
/// and its negative at body j. Pendulums in Cartesian coordinates and chains are made of these.
#[derive(Clone, Debug, PartialEq)]
pub struct Distances {
    d: usize,
    links: Vec<Link>,
}

/// One rigid distance: from body i to body j, or to a fixed anchor.
#[derive(Clone, Debug, PartialEq)]
pub struct Link {
    pub body: usize,
    pub to: Anchor,
    pub length: f64,
}

/// The other end of a [`Link`].
#[derive(Clone, Debug, PartialEq)]
pub enum Anchor {
    Body(usize),
    Fixed(Vec<f64>),
}

impl Distances {
    /// Links between bodies of `d` coordinates each.
    pub fn new(d: usize, links: Vec<Link>) -> Self {
        Distances { d, links }
    }

    /// The difference xᵢ − (xⱼ or the anchor) along axis a.
    fn separation(&self, link: &Link, q: &[f64], a: usize) -> f64 {
        let x = q[link.body * self.d + a];
        match &link.to {
            Anchor::Body(j) => x - q[j * self.d + a],
            Anchor::Fixed(point) => x - point[a],
        }
    }
}

impl HolonomicConstraints for Distances {
    fn count(&self) -> usize {
        self.links.len()
    }

    fn residual(&self, q: &[f64], g: &mut [f64]) -> Result<(), ModelError> {
        for (g, link) in g.iter_mut().zip(&self.links) {
            let r2: f64 = (0..self.d).map(|a| self.separation(link, q, a).powi(2)).sum();
            *g = 0.5 * (r2 - link.length * link.length);
        }
        Ok(())
    }

    fn jacobian(&self, q: &[f64], jac: &mut DMatrix<f64>) -> Result<(), ModelError> {
        jac.fill(0.0);
        for (k, link) in self.links.iter().enumerate() {
            for a in 0..self.d {
                let s = self.separation(link, q, a);
                jac[(k, link.body * self.d + a)] = s;
                if let Anchor::Body(j) = link.to {
                    jac[(k, j * self.d + a)] = -s;
                }
            }
        }
        Ok(())
    }
}

/// A state (q, p), as [`ConstraintSet::project`](super::ConstraintSet::project) returns it.
pub type PhaseState = (Vec<f64>, Vec<f64>);

/// A separable mechanical system S (H = ½pᵀM⁻¹p + V) on the constraints C: what RATTLE and
/// SHAKE integrate.
#[derive(Clone, Debug)]
pub struct Constrained<S, C> {
    pub system: S,
    pub constraints: C,
}

/// An action x ↦ f(q, x) written into `out`: M(q)⁻¹x, or the inverse Legendre transform.
pub type Action<'a> = &'a dyn Fn(&[f64], &[f64], &mut [f64]) -> Result<(), ModelError>;

/// M(q)⁻¹x = q̇(q, x) − q̇(q, 0) from the inverse Legendre transform `velocity`: exact for L
/// quadratic in q̇, whose q̇ is affine in p. It allocates (set-up and diagnostics).
pub fn inverse_mass<'a>(velocity: Action<'a>) -> impl Fn(&[f64], &[f64], &mut [f64]) -> Result<(), ModelError> + 'a {
    move |q, x, out| {
        let mut rest = vec![0.0; x.len()];
        velocity(q, &vec![0.0; x.len()], &mut rest)?;
        velocity(q, x, out)?;
        out.iter_mut().zip(&rest).for_each(|(o, r)| *o -= r);
        Ok(())
    }
}

/// Refuses, naming `argument`, m constraints on n coordinates whose dense matrices do not fit in
/// the memory available: a step holds G and W = M⁻¹Gᵀ at both of its ends (4mn numbers), the
/// m × m Gram matrix and the Newton Jacobian of the multipliers (2m²).
pub fn check_dense(argument: &'static str, m: usize, n: usize) -> Result<(), Error> {
    let numbers = m
        .saturating_mul(n)
        .saturating_mul(4)
        .saturating_add(m.saturating_mul(m).saturating_mul(2));
    crate::memory::check_allocation(argument, numbers, std::mem::size_of::<f64>())
}

/// G(q) and W = M(q)⁻¹G(q)ᵀ (n × m), allocated (for diagnostics and set-up, not the step loop).
fn jacobians<C: HolonomicConstraints + ?Sized>(
    constraints: &C,
    minv: Action<'_>,
    q: &[f64],
) -> Result<(DMatrix<f64>, DMatrix<f64>), ModelError> {
    let mut jac = DMatrix::zeros(constraints.count(), q.len());
    constraints.jacobian(q, &mut jac)?;
    let w = weighted(&jac, minv, q)?;
    Ok((jac, w))
}

/// W = M(q)⁻¹Gᵀ (n × m) for a constraint matrix G (m × n), allocated.
pub(super) fn weighted(jac: &DMatrix<f64>, minv: Action<'_>, q: &[f64]) -> Result<DMatrix<f64>, ModelError> {
    let (m, n) = jac.shape();
    let mut w = DMatrix::zeros(n, m);
    let mut column = vec![0.0; n];
    for k in 0..m {
        let row: Vec<f64> = jac.row(k).iter().copied().collect();
        minv(q, &row, &mut column)?;
        w.column_mut(k).copy_from_slice(&column);
    }
    Ok(w)
}

/// ‖G‖∞, the largest row sum of |Gᵢⱼ|.
pub(super) fn row_norm(jac: &DMatrix<f64>) -> f64 {
    jac.row_iter()
        .map(|row| row.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// The constraint residuals at one state, with the sizes they are judged against: |g(q)|∞
/// against ‖G(q)‖∞‖q‖∞ and |G(q)q̇|∞ against ‖G(q)‖∞‖q̇‖∞, the first-order change of g and Gq̇
/// when q or q̇ moves by its own size (so also the scale of their rounding errors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residuals {
    pub position: f64,
    pub velocity: f64,
    pub position_size: f64,
    pub velocity_size: f64,
}

/// The nearest consistent state: q on g = 0 by Newton's method along W = M⁻¹Gᵀ (the nearest
/// point in the kinetic metric, to first order), then p ← p − Gᵀμ with (GW)μ = Gq̇(q, p), the
/// M-orthogonal projection onto Gq̇ = 0 (exact when q̇ is affine in p, as for every L quadratic
/// in q̇). `minv` applies M(q)⁻¹, `velocity` is the inverse Legendre transform. Fails if Newton
/// does not converge (no point of the constraints near q) or GW is singular.
pub fn project<C: HolonomicConstraints + ?Sized>(
    constraints: &C,
    minv: Action<'_>,
    velocity: Action<'_>,
    q0: &[f64],
    p0: &[f64],
) -> Result<PhaseState, Error> {
    let model = |e: ModelError| Error::invalid("q0", format!("the constraints failed to evaluate: {e}"));
    let singular = || Error::invalid("q0", "the constraints are not independent here (G M⁻¹ Gᵀ is singular)");
    let m = constraints.count();
    let mut problem = OntoConstraints {
        constraints,
        minv,
        q: DVector::from_column_slice(q0),
        w: DMatrix::zeros(q0.len(), m),
        scale: q0.iter().fold(1.0_f64, |a, x| a.max(x.abs())),
    };
    // The nearest point to round-off: |δq|∞ ≤ 4ε·max(|q₀|∞, 1).
    let options = NewtonOptions {
        tolerance: 4.0 * f64::EPSILON,
        ..NewtonOptions::default()
    };
    let rules = Rules { simplified: false };
    match Newton::new(m).solve(&mut problem, &options, rules) {
        Ok(_) => {}
        Err(StepError::Model(e) | StepError::Interrupted(e)) => return Err(model(e)),
        Err(StepError::Convergence { reason, .. }) if reason == OntoConstraints::<C>::REASONS.singular => {
            return Err(singular())
        }
        Err(_) => {
            return Err(Error::invalid(
                "q0",
                "no point of the constraints near q0 (Newton's projection failed)",
            ))
        }
    }
    let q = problem.q;
    let mut jac = DMatrix::zeros(m, q.len());
    constraints.jacobian(q.as_slice(), &mut jac).map_err(model)?;
    // Finite inputs near the largest floats can still overflow on the way (GM⁻¹Gᵀ, μ).
    if !q.iter().all(|x| x.is_finite()) {
        return Err(Error::invalid(
            "q0",
            "its projection overflows: the positions are too large to project",
        ));
    }
    let p = momentum_projection(&jac, &DVector::zeros(m), minv, velocity, q.as_slice(), p0)?;
    Ok((q.as_slice().to_vec(), p))
}

/// p ← p − Gᵀμ with (GW)μ = Gq̇(q, p) + b, W = M⁻¹Gᵀ: the M-orthogonal projection of the
/// momenta onto G(q)q̇ + b = 0 for the constraint matrix G (m × n) at q and the affine term b
/// (0 but for affine velocity constraints). Errors name `q0` (the constraints not independent,
/// or failing to evaluate) and `p0` (overflow).
pub(super) fn momentum_projection(
    jac: &DMatrix<f64>,
    offset: &DVector<f64>,
    minv: Action<'_>,
    velocity: Action<'_>,
    q: &[f64],
    p0: &[f64],
) -> Result<Vec<f64>, Error> {
    let model = |e: ModelError| Error::invalid("q0", format!("the constraints failed to evaluate: {e}"));
    let singular = || Error::invalid("q0", "the constraints are not independent here (G M⁻¹ Gᵀ is singular)");
    let w = weighted(jac, minv, q).map_err(model)?;
    let mut v = vec![0.0; q.len()];
    velocity(q, p0, &mut v).map_err(model)?;
    let mu = (jac * &w)
        .lu()
        .solve(&(jac * DVector::from_column_slice(&v) + offset))
        .ok_or_else(singular)?;
    let p = DVector::from_column_slice(p0) - jac.transpose() * mu;
    if !p.iter().all(|x| x.is_finite()) {
        return Err(Error::invalid(
            "p0",
            "its projection overflows: the momenta are too large to project",
        ));
    }
    Ok(p.as_slice().to_vec())
}

/// g(q) = 0 by Newton's method along W = M(q)⁻¹G(q)ᵀ: q ← q − Wδ with (GW)δ = g(q). It
/// allocates (set-up, not the step loop).
struct OntoConstraints<'a, C: ?Sized> {
    constraints: &'a C,
    minv: Action<'a>,
    q: DVector<f64>,
    /// W at the last Jacobian.
    w: DMatrix<f64>,
    /// max(|q₀|∞, 1).
    scale: f64,
}

impl<C: HolonomicConstraints + ?Sized> NewtonProblem for OntoConstraints<'_, C> {
    const REASONS: Reasons = Reasons {
        singular: "the constraints are not independent here (G M⁻¹ Gᵀ is singular)",
        non_finite_start: "the constraints are non-finite at q0",
        non_finite: "Newton's projection became non-finite",
        not_converged: "no point of the constraints near q0 (Newton's projection failed)",
        outside: "q0 lies too far from the constraints for Newton's projection: start nearer them",
    };

    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        Ok(self.constraints.residual(self.q.as_slice(), r)?)
    }

    fn jacobian(&mut self, jac: &mut DMatrix<f64>) -> Result<(), StepError> {
        let (g, w) = jacobians(self.constraints, self.minv, self.q.as_slice())?;
        jac.copy_from(&(&g * &w));
        self.w = w;
        Ok(())
    }

    fn correct(&mut self, delta: &[f64]) -> Correction {
        let shift = &self.w * DVector::from_column_slice(delta);
        self.q -= &shift;
        Correction {
            size: shift.amax(),
            scale: self.scale,
        }
    }

    /// g's rounding at q, a few ε of the scale of q.
    fn noise(&self) -> f64 {
        4.0 * f64::EPSILON * self.scale
    }
}
