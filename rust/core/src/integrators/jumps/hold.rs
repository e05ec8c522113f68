//! Contacts held closed: a unilateral constraint φ(q) ≥ 0 kept as the equality φ(q) = 0 while
//! its multiplier pushes (λ ≥ 0), the motion of a body resting, sliding or rolling on a surface.
//!
//! The held step is RATTLE (Andersen 1983; HLW VII.1.4) on the closed surfaces Φ = (φₖ),
//!
//! p½ = p₀ + (τ/2)∂L/∂q(q₀) + ∇Φ(q₀)ᵀc,   q₁ = q₀ + τq̇(q₀, p½),   Φ(q₁) = 0,
//! p₁ = p½ + (τ/2)∂L/∂q(q₁) + ∇Φ(q₁)ᵀμ,   ∇Φ(q₁)q̇(q₁, p₁) = 0,
//!
//! composed with the fractions γ of the run's method where it is Verlet or a composition of it
//! (yoshida4, …): symplectic on the contact manifold at the method's order. The held state's
//! multipliers λ are those of [`crate::model::Reaction`] (the state's own), on the closed
//! surfaces; a contact is released where its λ crosses 0.

use nalgebra::DMatrix;

use super::Contact;
use crate::integrators::{Composition, Method};
use crate::model::Lagrangian;
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::ModelError;

/// Newton iterations of the position constraint at most: it starts O(τ²) off and converges
/// quadratically, so a step that needs more is far too large for the surface's curvature.
const ITERATIONS: usize = 30;

/// The held step of one method on a run's contacts, with every buffer it needs (made once: a
/// step allocates nothing).
#[derive(Debug)]
pub(super) struct Hold {
    gamma: Vec<f64>,
    /// The state a step advances, in place.
    pub(super) q: Vec<f64>,
    pub(super) p: Vec<f64>,
    v: Vec<f64>,
    w: Vec<f64>,
    zeros: Vec<f64>,
    force: Vec<f64>,
    start: Vec<f64>,
    /// ∇φₖ and M⁻¹∇φₖ of the closed contacts, k-th row at k·n.
    normals: Vec<f64>,
    inverse: Vec<f64>,
    /// The m × m systems and their pivots, the (m−1)-th for m closed contacts.
    systems: Vec<(DMatrix<f64>, Vec<usize>)>,
    c: Vec<f64>,
    r: Vec<f64>,
    gradient: Vec<f64>,
    /// The time t at which `force`, `normals` and `inverse` hold ∂L/∂q and the normals of the
    /// contacts `cached_for` at `q` (the end of the last step, where the run checks λ and the
    /// next step starts), if they do.
    cached: Option<f64>,
    cached_for: Vec<usize>,
}

impl Hold {
    /// The held step of `method` on n coordinates and up to `contacts` closed at once; None
    /// where the method is not Verlet or a composition of it.
    pub(super) fn new(method: Method, n: usize, contacts: usize) -> Option<Hold> {
        let gamma = Composition::of(method)?.gamma().to_vec();
        let v = || vec![0.0; n];
        Some(Hold {
            gamma,
            q: v(),
            p: v(),
            v: v(),
            w: v(),
            zeros: v(),
            force: v(),
            start: v(),
            normals: vec![0.0; n * contacts],
            inverse: vec![0.0; n * contacts],
            systems: (1..=contacts).map(|m| (DMatrix::zeros(m, m), vec![0; m])).collect(),
            c: vec![0.0; contacts],
            r: vec![0.0; contacts],
            gradient: v(),
            cached: None,
            cached_for: Vec::with_capacity(contacts),
        })
    }

    /// The methods that hold a contact, as an error names them.
    pub(super) fn methods() -> &'static str {
        "verlet and its compositions (yoshida4, suzuki4, mclachlan4, yoshida6, kahan_li6, kahan_li8, …)"
    }

    /// The held step of size τ from (t, q, p) on the `closed` contacts (indices into
    /// `contacts`): its end in `q` and `p`.
    ///
    /// # Errors
    /// The model's or a surface's own error; the position constraint not solved (a step too
    /// large for the surface's curvature, or surfaces that are not independent there).
    pub(super) fn step(
        &mut self,
        model: &dyn Lagrangian,
        (contacts, closed): (&[Contact<'_>], &[usize]),
        (t, tau): (f64, f64),
        (q, p): (&[f64], &[f64]),
    ) -> Result<(), ModelError> {
        // The last step's end, where the next starts: its force and normals are kept.
        let mut warm = self.at(q, t, closed);
        if !warm {
            self.q.copy_from_slice(q);
            model.dl_dq(&self.q, &self.zeros, t, &mut self.force)?;
        }
        self.p.copy_from_slice(p);
        self.cached = None;
        let mut time = t;
        for k in 0..self.gamma.len() {
            let s = self.gamma[k] * tau;
            self.substep(model, (contacts, closed), (time, s), warm)?;
            time += s;
            warm = true;
        }
        self.cache(t + tau, closed);
        Ok(())
    }

    /// Whether `force`, `normals` and `inverse` are those of the `closed` contacts at (q, t): the
    /// last step ended there.
    fn at(&self, q: &[f64], t: f64, closed: &[usize]) -> bool {
        self.cached == Some(t) && self.q == q && self.cached_for == closed
    }

    /// `force`, `normals` and `inverse` marked as those of the `closed` contacts at (q, t).
    fn cache(&mut self, t: f64, closed: &[usize]) {
        self.cached = Some(t);
        self.cached_for.clear();
        self.cached_for.extend_from_slice(closed);
    }

    /// One RATTLE step of size s from (q, p) at t, with ∂L/∂q(q) in `force` (and the
    /// normals at q in `normals` and `inverse` if `warm`), left at its end.
    fn substep(
        &mut self,
        model: &dyn Lagrangian,
        (contacts, closed): (&[Contact<'_>], &[usize]),
        (t, s): (f64, f64),
        warm: bool,
    ) -> Result<(), ModelError> {
        let (n, m) = (self.q.len(), closed.len());
        for (x, f) in self.p.iter_mut().zip(&self.force) {
            *x += 0.5 * s * f;
        }
        if !warm {
            self.normals_at(model, (contacts, closed), t)?;
        }
        // q₁(c) = q₀ + s(q̇(q₀, p½) + Σ cₖ M⁻¹∇φₖ(q₀)): Newton on Φ(q₁(c)) = 0.
        model.velocity(&self.q, &self.p, t, &mut self.v)?;
        self.start.copy_from_slice(&self.q);
        self.c[..m].fill(0.0);
        let scale = self.start.iter().fold(1.0_f64, |a, x| a.max(x.abs()));
        let mut converged = false;
        for _ in 0..ITERATIONS {
            for i in 0..n {
                let shift: f64 = (0..m).map(|k| self.c[k] * self.inverse[k * n + i]).sum();
                self.q[i] = self.start[i] + s * (self.v[i] + shift);
            }
            let (system, pivots) = &mut self.systems[m - 1];
            for (a, &j) in closed.iter().enumerate() {
                let contact = &contacts[j];
                contact.surface.gradient(&self.q, &mut self.gradient)?;
                for b in 0..m {
                    let w = &self.inverse[b * n..(b + 1) * n];
                    system[(a, b)] = s * self.gradient.iter().zip(w).map(|(g, w)| g * w).sum::<f64>();
                }
                self.r[a] = -contact.surface.phi(&self.q)?;
            }
            if lu_in_place(system, pivots).is_none() {
                return Err("the held contacts' surfaces are not independent here".into());
            }
            lu_solve(system, pivots, &mut self.r[..m]);
            let mut change = 0.0_f64;
            for i in 0..n {
                let shift: f64 = (0..m).map(|k| self.r[k] * self.inverse[k * n + i]).sum();
                change = change.max((s * shift).abs());
            }
            for k in 0..m {
                self.c[k] += self.r[k];
            }
            if change <= 4.0 * f64::EPSILON * scale {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(format!(
                "the held contacts' position constraint did not converge in {ITERATIONS} Newton iterations (a step \
                 too large for the surface's curvature)"
            )
            .into());
        }
        for i in 0..n {
            let shift: f64 = (0..m).map(|k| self.c[k] * self.inverse[k * n + i]).sum();
            self.q[i] = self.start[i] + s * (self.v[i] + shift);
            self.p[i] += (0..m).map(|k| self.c[k] * self.normals[k * n + i]).sum::<f64>();
        }
        model.dl_dq(&self.q, &self.zeros, t + s, &mut self.force)?;
        for (x, f) in self.p.iter_mut().zip(&self.force) {
            *x += 0.5 * s * f;
        }
        self.project(model, (contacts, closed), t + s)
    }

    /// p made tangent to the closed contacts at q: p + ∇Φᵀμ with ∇Φ q̇(q, p + ∇Φᵀμ) = 0.
    pub(super) fn project(
        &mut self,
        model: &dyn Lagrangian,
        (contacts, closed): (&[Contact<'_>], &[usize]),
        t: f64,
    ) -> Result<(), ModelError> {
        let (n, m) = (self.q.len(), closed.len());
        self.cached = None;
        self.normals_at(model, (contacts, closed), t)?;
        model.velocity(&self.q, &self.p, t, &mut self.v)?;
        let (system, pivots) = &mut self.systems[m - 1];
        for a in 0..m {
            let normal = &self.normals[a * n..(a + 1) * n];
            for b in 0..m {
                let w = &self.inverse[b * n..(b + 1) * n];
                system[(a, b)] = normal.iter().zip(w).map(|(g, w)| g * w).sum();
            }
            self.c[a] = -normal.iter().zip(&self.v).map(|(g, v)| g * v).sum::<f64>();
        }
        if lu_in_place(system, pivots).is_none() {
            return Err("the held contacts' surfaces are not independent here".into());
        }
        lu_solve(system, pivots, &mut self.c[..m]);
        for i in 0..n {
            self.p[i] += (0..m).map(|k| self.c[k] * self.normals[k * n + i]).sum::<f64>();
        }
        Ok(())
    }

    /// ∇φₖ(q) and M⁻¹∇φₖ = q̇(q, ∇φₖ) of the closed contacts, at q (q̇ linear in p: the
    /// kick–drift methods' models have T = ½pᵀM⁻¹p).
    fn normals_at(
        &mut self,
        model: &dyn Lagrangian,
        (contacts, closed): (&[Contact<'_>], &[usize]),
        t: f64,
    ) -> Result<(), ModelError> {
        let n = self.q.len();
        for (a, &j) in closed.iter().enumerate() {
            let normal = &mut self.normals[a * n..(a + 1) * n];
            contacts[j].surface.gradient(&self.q, normal)?;
            model.velocity(&self.q, normal, t, &mut self.inverse[a * n..(a + 1) * n])?;
        }
        Ok(())
    }

    /// λ of the `closed` contacts at (q, p, t): the k-th into `out[k]`. For the models a held
    /// step integrates (H = ½pᵀM⁻¹p + V(q), M constant, no forces) [`Reaction::solve`]'s
    /// equations read (∇Φ M⁻¹∇Φᵀ)λ = −(∇²φₖ[q̇, q̇] + ∇φₖ·M⁻¹∂L/∂q), and the curvature term is
    /// a central difference of ∇φₖ·q̇ along q̇, exact for quadrics: two gradients a contact
    /// instead of the general difference's four evaluations of the whole motion.
    pub(super) fn multipliers(
        &mut self,
        model: &dyn Lagrangian,
        (contacts, closed): (&[Contact<'_>], &[usize]),
        (q, p, t): (&[f64], &[f64], f64),
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let (n, m) = (q.len(), closed.len());
        if !self.at(q, t, closed) {
            self.q.copy_from_slice(q);
            self.normals_at(model, (contacts, closed), t)?;
            model.dl_dq(q, &self.zeros, t, &mut self.force)?;
            self.cache(t, closed);
        }
        model.velocity(q, p, t, &mut self.v)?;
        model.velocity(q, &self.force, t, &mut self.w)?;
        let amax = |x: &[f64]| x.iter().fold(0.0_f64, |a, y| a.max(y.abs()));
        let speed = amax(&self.v);
        // The difference's step: truncation (s²) and rounding (ε/s) both near ε^(2/3).
        let s = f64::EPSILON.cbrt() * amax(q).max(1.0) / speed;
        let (system, pivots) = &mut self.systems[m - 1];
        for (a, &j) in closed.iter().enumerate() {
            let normal = &self.normals[a * n..(a + 1) * n];
            let mut curvature = 0.0;
            if speed > 0.0 {
                for sign in [1.0, -1.0] {
                    for (x, (qi, vi)) in self.start.iter_mut().zip(q.iter().zip(&self.v)) {
                        *x = qi + sign * s * vi;
                    }
                    contacts[j].surface.gradient(&self.start, &mut self.gradient)?;
                    curvature += sign * self.gradient.iter().zip(&self.v).map(|(g, v)| g * v).sum::<f64>();
                }
                curvature /= 2.0 * s;
            }
            out[a] = -(curvature + normal.iter().zip(&self.w).map(|(g, x)| g * x).sum::<f64>());
            for b in 0..m {
                let w = &self.inverse[b * n..(b + 1) * n];
                system[(a, b)] = normal.iter().zip(w).map(|(g, w)| g * w).sum();
            }
        }
        if lu_in_place(system, pivots).is_none() {
            return Err("the held contacts' surfaces are not independent here".into());
        }
        lu_solve(system, pivots, &mut out[..m]);
        Ok(())
    }
}
