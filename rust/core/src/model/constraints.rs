use nalgebra::{DMatrix, DVector};

use super::{finite_difference, MechanicalSystem};
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

/// G(q) by central differences of g, row by row (2n evaluations of g per row; they allocate
/// scratch), about 1e-10 relative accuracy.
pub fn differenced_jacobian<C: HolonomicConstraints + ?Sized>(
    constraints: &C,
    q: &[f64],
    jac: &mut DMatrix<f64>,
) -> Result<(), ModelError> {
    let (m, n) = jac.shape();
    let (mut work, mut row) = (vec![0.0; n], vec![0.0; n]);
    let mut g = vec![0.0; m];
    for i in 0..m {
        finite_difference::central_gradient(
            |x| {
                constraints.residual(x, &mut g)?;
                Ok(g[i])
            },
            q,
            &mut work,
            &mut row,
        )?;
        jac.row_mut(i).copy_from_slice(&row);
    }
    Ok(())
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

/// A state (q, p), as [`Constrained::project`] returns it.
pub type PhaseState = (Vec<f64>, Vec<f64>);

/// A separable mechanical system S (H = ½pᵀM⁻¹p + V) on the constraints C: what RATTLE and
/// SHAKE integrate.
#[derive(Clone, Debug)]
pub struct Constrained<S, C> {
    pub system: S,
    pub constraints: C,
}

impl<S: MechanicalSystem, C: HolonomicConstraints> Constrained<S, C> {
    /// G(q) and M⁻¹G(q)ᵀ, allocated (for diagnostics and set-up, not the step loop).
    fn jacobians(&self, q: &[f64]) -> Result<(DMatrix<f64>, DMatrix<f64>), ModelError> {
        let (m, n) = (self.constraints.count(), q.len());
        let mut jac = DMatrix::zeros(m, n);
        self.constraints.jacobian(q, &mut jac)?;
        let mut minv_t = DMatrix::zeros(n, m);
        let mut column = vec![0.0; n];
        for k in 0..m {
            let row: Vec<f64> = jac.row(k).iter().copied().collect();
            self.system.mass().velocity(&row, &mut column);
            minv_t.column_mut(k).copy_from_slice(&column);
        }
        Ok((jac, minv_t))
    }

    /// The constraint residuals (|g(q)|∞, |G(q)M⁻¹p|∞) at one state.
    pub fn residuals(&self, q: &[f64], p: &[f64]) -> Result<(f64, f64), ModelError> {
        let mut g = vec![0.0; self.constraints.count()];
        self.constraints.residual(q, &mut g)?;
        let (_, minv_t) = self.jacobians(q)?;
        let hidden = minv_t.transpose() * DVector::from_column_slice(p);
        Ok((g.iter().fold(0.0, |a, x| a.max(x.abs())), hidden.amax()))
    }

    /// The nearest consistent state: q on g = 0 by Newton's method along M⁻¹Gᵀ (the nearest
    /// point in the kinetic metric, to first order), then p projected onto G(q)M⁻¹p = 0
    /// M-orthogonally, p ← p − Gᵀ(GM⁻¹Gᵀ)⁻¹GM⁻¹p. Fails if Newton does not converge (no point
    /// of the constraints near q) or GM⁻¹Gᵀ is singular.
    pub fn project(&self, q0: &[f64], p0: &[f64]) -> Result<PhaseState, Error> {
        let model = |e: ModelError| Error::invalid("q0", format!("the constraints failed to evaluate: {e}"));
        let m = self.constraints.count();
        let mut q = DVector::from_column_slice(q0);
        let mut g = vec![0.0; m];
        let scale = q0.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
        let mut converged = false;
        for _ in 0..50 {
            self.constraints.residual(q.as_slice(), &mut g).map_err(model)?;
            let (jac, minv_t) = self.jacobians(q.as_slice()).map_err(model)?;
            let schur = (&jac * &minv_t).lu();
            let step = schur.solve(&DVector::from_column_slice(&g)).ok_or_else(|| {
                Error::invalid("q0", "the constraints are not independent here (G M⁻¹ Gᵀ is singular)")
            })?;
            let delta = &minv_t * step;
            q -= &delta;
            if !q.iter().all(|x| x.is_finite()) {
                break;
            }
            if delta.amax() <= 4.0 * f64::EPSILON * scale {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(Error::invalid(
                "q0",
                "no point of the constraints near q0 (Newton's projection failed)",
            ));
        }
        let (jac, minv_t) = self.jacobians(q.as_slice()).map_err(model)?;
        let p = DVector::from_column_slice(p0);
        let mu = (&jac * &minv_t)
            .lu()
            .solve(&(minv_t.transpose() * &p))
            .ok_or_else(|| Error::invalid("q0", "the constraints are not independent here (G M⁻¹ Gᵀ is singular)"))?;
        let p = p - jac.transpose() * mu;
        Ok((q.as_slice().to_vec(), p.as_slice().to_vec()))
    }
}
