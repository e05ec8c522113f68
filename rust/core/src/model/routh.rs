use std::cell::RefCell;

use nalgebra::{DMatrix, DVector};

use super::{Hessians, Lagrangian};
use crate::error::StepError;
use crate::solve::difference::{self, central_jacobian, Evaluations};
use crate::solve::lu::{lu_in_place, lu_solve};
use crate::solve::newton::{model_error, norm, Correction, Newton, NewtonOptions, NewtonProblem, Reasons, Rules};
use crate::{Error, ModelError};

/// The Newton iteration for ċ: to a relative correction of 1e-15 (or the noise floor of a
/// differenced ∂²L/∂ċ²), at most 50 iterations.
const NEWTON: NewtonOptions = NewtonOptions {
    tolerance: 1e-15,
    max_iterations: 50,
};

/// The Routhian of a Lagrangian with cyclic coordinates, a [`Lagrangian`] on the remaining
/// (shape) coordinates x (Routh's "ignoration of coordinates"; Marsden, Ratiu & Scheurle,
/// J. Math. Phys. 41 (2000) 3379).
///
/// With q = (x, c), ∂L/∂c = 0 and the conserved momenta μ = ∂L/∂ċ, the Routhian is
///
/// R(x, ẋ, t; μ) = L(x, ẋ, ċ, t) − μ·ċ,   ċ solving ∂L/∂ċ(x, ẋ, ċ, t) = μ,
///
/// the MRS sign convention (Landau–Lifshitz and Goldstein use μ·ċ − L, whose equations differ
/// by that sign): x(t) solves the Euler–Lagrange equations of L exactly when it solves those of
/// R. Since ∂R/∂ċ = ∂L/∂ċ − μ = 0, the first derivatives of R are those of L at the solved ċ:
/// ∂R/∂x = ∂L/∂x and ∂R/∂ẋ = ∂L/∂ẋ, and R's energy ∂R/∂ẋ·ẋ − R is the energy of L.
///
/// For L = ½q̇ᵀM(q)q̇ − V(q) the solve is linear, ċ = M_cc⁻¹(μ − M_cx ẋ), and
///
/// R = ½ẋᵀ(M_xx − M_xc M_cc⁻¹ M_cx)ẋ + μᵀM_cc⁻¹M_cx ẋ − (V + ½μᵀM_cc⁻¹μ):
///
/// a kinetic term, a gyroscopic term linear in ẋ, and the amended potential V_μ. Newton's
/// method with the exact ∂²L/∂ċ² (from [`Lagrangian::hessians`]) finds that ċ in one step;
/// for a general L it iterates, from ċ = 0 (never from the last solution, so that what R
/// evaluates depends on its arguments alone).
///
/// The scratch sits in a `RefCell`, so a `Routhian` serves one thread.
pub struct Routhian<'a, L: ?Sized> {
    full: &'a L,
    cyclic: Vec<usize>,
    shape: Vec<usize>,
    momenta: Vec<f64>,
    scratch: RefCell<Scratch>,
    newton: RefCell<Newton>,
}

/// One point at which ∂L/∂ċ is evaluated, with its quadrature weight.
struct Node<'x> {
    x: &'x [f64],
    xdot: &'x [f64],
    t: f64,
    weight: f64,
}

struct Scratch {
    /// The full state (x, c; ẋ, ċ); c holds its reference value, which L does not see.
    q: Vec<f64>,
    v: Vec<f64>,
    /// The last cyclic velocity solved for (each solve starts from 0).
    cdot: Vec<f64>,
    /// The point (x, ẋ, t) of the last one-node solve, while `cdot` holds its solution: the
    /// integrators ask for ∂R/∂x and ∂R/∂ẋ at the same point in turn.
    solved: Option<f64>,
    solved_x: Vec<f64>,
    solved_xdot: Vec<f64>,
    full: Vec<f64>,
    /// p for the inverse Legendre transform.
    p: Vec<f64>,
    /// The differences of ∂L/∂ċ, and one node's ∂²L/∂ċ² from them.
    plus: Vec<f64>,
    minus: Vec<f64>,
    node_k: DMatrix<f64>,
    /// K = ∂²L/∂ċ² and its LU factors, for the Schur complements.
    k: DMatrix<f64>,
    pivots: Vec<usize>,
    hessians: Hessians,
    /// K⁻¹B_qᵀ and K⁻¹B_vᵀ, for the Schur complements of the Hessians.
    kinv_b: DMatrix<f64>,
    column: DVector<f64>,
}

impl<'a, L: Lagrangian + ?Sized> Routhian<'a, L> {
    /// The Routhian of `full` with the coordinates `cyclic` ignored at momenta `momenta`.
    /// `reference` gives values for the cyclic coordinates (L does not depend on them; they
    /// only complete the configuration handed to L). Refuses forced models, whose forces would
    /// change μ, and indices that repeat or leave no shape coordinate.
    pub fn new(full: &'a L, cyclic: &[usize], momenta: &[f64], reference: &[f64]) -> Result<Self, Error> {
        let n = full.dim();
        let m = cyclic.len();
        if m == 0 || m >= n || cyclic.iter().any(|&i| i >= n) {
            return Err(Error::invalid(
                "cyclic",
                format!(
                    "need between 1 and {} distinct indices below {n}, got {cyclic:?}",
                    n.max(1) - 1
                ),
            ));
        }
        let mut sorted = cyclic.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        if sorted.len() != m {
            return Err(Error::invalid("cyclic", format!("indices repeat: {cyclic:?}")));
        }
        if momenta.len() != m || momenta.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid(
                "momenta",
                format!("need {m} finite values, one per cyclic coordinate, got {momenta:?}"),
            ));
        }
        if reference.len() != m || reference.iter().any(|x| !x.is_finite()) {
            return Err(Error::invalid("reference", format!("need {m} finite values")));
        }
        if full.is_forced() {
            return Err(Error::invalid(
                "model",
                "forces act on it, so the cyclic momenta are not conserved and Routh reduction does not apply",
            ));
        }
        let shape: Vec<usize> = (0..n).filter(|i| !cyclic.contains(i)).collect();
        let r = shape.len();
        let mut q = vec![0.0; n];
        cyclic.iter().zip(reference).for_each(|(&i, &c)| q[i] = c);
        let scratch = Scratch {
            q,
            v: vec![0.0; n],
            cdot: vec![0.0; m],
            solved: None,
            solved_x: vec![0.0; r],
            solved_xdot: vec![0.0; r],
            full: vec![0.0; n],
            p: vec![0.0; n],
            plus: vec![0.0; m],
            minus: vec![0.0; m],
            node_k: DMatrix::zeros(m, m),
            k: DMatrix::zeros(m, m),
            pivots: vec![0; m],
            hessians: Hessians::zeros(n),
            kinv_b: DMatrix::zeros(m, 2 * r),
            column: DVector::zeros(m),
        };
        Ok(Routhian {
            full,
            cyclic: cyclic.to_vec(),
            shape,
            momenta: momenta.to_vec(),
            scratch: RefCell::new(scratch),
            newton: RefCell::new(Newton::new(m)),
        })
    }

    /// The ignored coordinates c.
    pub fn cyclic(&self) -> &[usize] {
        &self.cyclic
    }

    /// The remaining coordinates x, in order.
    pub fn shape(&self) -> &[usize] {
        &self.shape
    }

    /// The conserved momenta μ of the ignored coordinates.
    pub fn momenta(&self) -> &[f64] {
        &self.momenta
    }

    /// Writes ċ(x, ẋ, t) with ∂L/∂ċ = μ into `out`.
    pub fn cyclic_velocity(&self, x: &[f64], xdot: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        let s = &mut *self.scratch.borrow_mut();
        self.solve_at(s, x, xdot, t)?;
        out.copy_from_slice(&s.cdot);
        Ok(())
    }

    /// The amended potential V_μ(x, t) = −R(x, 0, t), which is V + ½μᵀM_cc⁻¹μ for a
    /// mechanical system. Its critical points are the relative equilibria: states at rest in x
    /// whose ignored coordinates turn uniformly.
    pub fn amended_potential(&self, x: &[f64], t: f64) -> Result<f64, ModelError> {
        let zero = vec![0.0; x.len()];
        let s = &mut *self.scratch.borrow_mut();
        self.solve_at(s, x, &zero, t)?;
        Ok(-self.value(s, t)?)
    }

    /// The cyclic increments Δc of a trajectory of R, one row per step between consecutive
    /// states (t, x, p_x): the reconstruction of the ignored coordinates.
    ///
    /// - `rule = Some((nodes, weights))`, the quadrature of a two-point discrete Lagrangian
    ///   L_d = h Σᵢ bᵢ L(q₀ + cᵢΔq, Δq/h): Δc = hċ with ċ solving the discrete momentum
    ///   equation Σᵢ bᵢ ∂L/∂ċ(x₀ + cᵢΔx, Δx/h, ċ) = μ (the reconstruction of discrete Routh
    ///   reduction, J_d(q_k, q_{k+1}) = μ; Jalnapurkar, Leok, Marsden & West 2006). For the
    ///   midpoint rule this is exactly the increment of the unreduced DEL integration.
    /// - `rule = None`: Δc = ∫ċ dt by 3-point Gauss–Legendre quadrature along the cubic
    ///   Hermite interpolant of x with the end velocities ẋ = ∂R/∂ẋ⁻¹(p_x): local error
    ///   O(h⁵), for reconstructions of order 4 from a trajectory of any order.
    pub fn cyclic_increments(
        &self,
        t: &[f64],
        x: &[f64],
        p: &[f64],
        rule: Option<(&[f64], &[f64])>,
    ) -> Result<Vec<f64>, ModelError> {
        let (r, m) = (self.shape.len(), self.cyclic.len());
        let steps = t.len().saturating_sub(1);
        let mut out = vec![0.0; steps * m];
        let (mut xdot0, mut xdot1) = (vec![0.0; r], vec![0.0; r]);
        let (mut xs, mut xdots) = (vec![vec![0.0; r]; 3], vec![vec![0.0; r]; 3]);
        let cdot = &mut vec![0.0; m];
        if steps > 0 && rule.is_none() {
            self.velocity(&x[..r], &p[..r], t[0], &mut xdot1)?;
        }
        for k in 0..steps {
            let h = t[k + 1] - t[k];
            let (x0, x1) = (&x[k * r..(k + 1) * r], &x[(k + 1) * r..(k + 2) * r]);
            let (nodes, weights): (&[f64], &[f64]) = match rule {
                Some(rule) => {
                    for (i, &c) in rule.0.iter().enumerate() {
                        for j in 0..r {
                            xs[i][j] = x0[j] + c * (x1[j] - x0[j]);
                            xdots[i][j] = (x1[j] - x0[j]) / h;
                        }
                    }
                    rule
                }
                None => {
                    std::mem::swap(&mut xdot0, &mut xdot1);
                    self.velocity(x1, &p[(k + 1) * r..(k + 2) * r], t[k + 1], &mut xdot1)?;
                    let ends = Ends {
                        h,
                        x0,
                        v0: &xdot0,
                        x1,
                        v1: &xdot1,
                    };
                    for (i, &c) in GAUSS3.0.iter().enumerate() {
                        ends.hermite(c, &mut xs[i], &mut xdots[i]);
                    }
                    (&GAUSS3.0, &GAUSS3.1)
                }
            };
            let row = &mut out[k * m..(k + 1) * m];
            if rule.is_some() {
                let nodes: Vec<Node> = (0..nodes.len())
                    .map(|i| Node {
                        x: &xs[i],
                        xdot: &xdots[i],
                        t: t[k] + nodes[i] * h,
                        weight: weights[i],
                    })
                    .collect();
                let s = &mut *self.scratch.borrow_mut();
                self.solve(s, &nodes)?;
                row.iter_mut().zip(&s.cdot).for_each(|(d, c)| *d = h * c);
            } else {
                for i in 0..3 {
                    self.cyclic_velocity(&xs[i], &xdots[i], t[k] + nodes[i] * h, cdot)?;
                    row.iter_mut()
                        .zip(cdot.iter())
                        .for_each(|(d, c)| *d += h * weights[i] * c);
                }
            }
        }
        Ok(out)
    }

    /// Solves Σᵢ wᵢ ∂L/∂ċ(xᵢ, ẋᵢ, ċ, tᵢ) = μ for ċ by Newton's method from ċ = 0,
    /// leaving the full state of the last node in the scratch; a one-node solve at the point
    /// of the last one is remembered.
    fn solve(&self, s: &mut Scratch, nodes: &[Node]) -> Result<(), ModelError> {
        if let [node] = nodes {
            if s.solved == Some(node.t) && s.solved_x == node.x && s.solved_xdot == node.xdot {
                self.embed(s, node.x, node.xdot);
                return Ok(());
            }
        }
        s.solved = None;
        // From ċ = 0, never from the last solution: the result is then a function of the
        // point alone, so an evaluation elsewhere (an energy check, a save) cannot move it.
        s.cdot.fill(0.0);
        self.newton(s, nodes)?;
        if let [node] = nodes {
            s.solved = Some(node.t);
            s.solved_x.copy_from_slice(node.x);
            s.solved_xdot.copy_from_slice(node.xdot);
        }
        Ok(())
    }

    /// [`Routhian::solve`] at the one point (x, ẋ, t).
    fn solve_at(&self, s: &mut Scratch, x: &[f64], xdot: &[f64], t: f64) -> Result<(), ModelError> {
        self.solve(
            s,
            &[Node {
                x,
                xdot,
                t,
                weight: 1.0,
            }],
        )
    }

    /// A first derivative of R: the shape entries of `derivative` (∂L/∂q or ∂L/∂q̇) of L at the
    /// solved ċ, since ∂R/∂ċ = 0.
    fn shape_derivative(
        &self,
        x: &[f64],
        xdot: &[f64],
        t: f64,
        out: &mut [f64],
        derivative: impl Fn(&L, &[f64], &[f64], f64, &mut [f64]) -> Result<(), ModelError>,
    ) -> Result<(), ModelError> {
        let s = &mut *self.scratch.borrow_mut();
        self.solve_at(s, x, xdot, t)?;
        derivative(self.full, &s.q, &s.v, t, &mut s.full)?;
        self.gather(s, out);
        Ok(())
    }

    /// [`Routhian::solve`] without the memo.
    fn newton(&self, s: &mut Scratch, nodes: &[Node]) -> Result<(), ModelError> {
        let rules = Rules { simplified: false };
        let mut problem = CyclicVelocities { routh: self, s, nodes };
        self.newton
            .borrow_mut()
            .solve(&mut problem, &NEWTON, rules)
            .map_err(model_error)?;
        Ok(())
    }

    /// Writes (x, ẋ) and the current ċ into the full state.
    fn embed(&self, s: &mut Scratch, x: &[f64], xdot: &[f64]) {
        for (k, &i) in self.shape.iter().enumerate() {
            s.q[i] = x[k];
            s.v[i] = xdot[k];
        }
        for (k, &i) in self.cyclic.iter().enumerate() {
            s.v[i] = s.cdot[k];
        }
    }

    /// R = L − μ·ċ at the solved state.
    fn value(&self, s: &Scratch, t: f64) -> Result<f64, ModelError> {
        let work: f64 = self.momenta.iter().zip(&s.cdot).map(|(a, b)| a * b).sum();
        Ok(self.full.lagrangian(&s.q, &s.v, t)? - work)
    }

    /// Gathers the shape entries of the full vector in the scratch.
    fn gather(&self, s: &Scratch, out: &mut [f64]) {
        self.shape.iter().zip(out.iter_mut()).for_each(|(&i, o)| *o = s.full[i]);
    }
}

/// The 3-point Gauss–Legendre rule on [0, 1] (order 6).
const GAUSS3: ([f64; 3], [f64; 3]) = (
    [0.112_701_665_379_258_31, 0.5, 0.887_298_334_620_741_7],
    [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0],
);

/// The ends (x₀, ẋ₀) and (x₁, ẋ₁) of a step of length h.
struct Ends<'a> {
    h: f64,
    x0: &'a [f64],
    v0: &'a [f64],
    x1: &'a [f64],
    v1: &'a [f64],
}

impl Ends<'_> {
    /// The cubic Hermite interpolant through the ends, at s = 0 and s = 1: x(s) and its time
    /// derivative.
    fn hermite(&self, s: f64, x: &mut [f64], v: &mut [f64]) {
        let Ends { h, x0, v0, x1, v1 } = *self;
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (
            2.0 * s3 - 3.0 * s2 + 1.0,
            s3 - 2.0 * s2 + s,
            -2.0 * s3 + 3.0 * s2,
            s3 - s2,
        );
        let (d00, d10, d01, d11) = (
            6.0 * s2 - 6.0 * s,
            3.0 * s2 - 4.0 * s + 1.0,
            -6.0 * s2 + 6.0 * s,
            3.0 * s2 - 2.0 * s,
        );
        for j in 0..x.len() {
            x[j] = h00 * x0[j] + h10 * h * v0[j] + h01 * x1[j] + h11 * h * v1[j];
            v[j] = (d00 * x0[j] + d01 * x1[j]) / h + d10 * v0[j] + d11 * v1[j];
        }
    }
}

/// Σᵢ wᵢ ∂L/∂ċ(xᵢ, ẋᵢ, ċ, tᵢ) − μ = 0 for ċ (the scratch's `cdot`), from ċ = 0.
struct CyclicVelocities<'p, 'a, L: ?Sized> {
    routh: &'p Routhian<'a, L>,
    s: &'p mut Scratch,
    nodes: &'p [Node<'p>],
}

impl<L: Lagrangian + ?Sized> NewtonProblem for CyclicVelocities<'_, '_, L> {
    const REASONS: Reasons = Reasons {
        singular: "∂²L/∂ċ² is singular: the cyclic velocities are not determined by their momenta",
        non_finite_start: "∂L/∂ċ is non-finite at the last cyclic velocities",
        non_finite: "the cyclic velocities became non-finite",
        not_converged: "the cyclic velocities did not converge: ∂L/∂ċ = μ has no nearby solution",
        outside: "∂L/∂ċ = μ has no solution near the last cyclic velocities: L is not convex in ċ on the way, \
                  or μ lies beyond what ∂L/∂ċ reaches",
    };

    /// Leaves the full state of the last node in the scratch.
    fn residual(&mut self, r: &mut [f64]) -> Result<(), StepError> {
        let (routh, s) = (self.routh, &mut *self.s);
        routh.momenta.iter().zip(r.iter_mut()).for_each(|(mu, r)| *r = -mu);
        for node in self.nodes {
            routh.embed(s, node.x, node.xdot);
            routh.full.dl_dv(&s.q, &s.v, node.t, &mut s.full)?;
            for (j, &c) in routh.cyclic.iter().enumerate() {
                r[j] += node.weight * s.full[c];
            }
        }
        Ok(())
    }

    /// K = Σᵢ wᵢ ∂²L/∂ċ²(nodeᵢ), exact when L supplies its Hessians, else by central
    /// differences of ∂L/∂ċ.
    fn jacobian(&mut self, k: &mut DMatrix<f64>) -> Result<(), StepError> {
        let (routh, s) = (self.routh, &mut *self.s);
        k.fill(0.0);
        for node in self.nodes {
            routh.embed(s, node.x, node.xdot);
            if routh.full.hessians(&s.q, &s.v, node.t, &mut s.hessians)? {
                for (j, &a) in routh.cyclic.iter().enumerate() {
                    for (l, &b) in routh.cyclic.iter().enumerate() {
                        k[(j, l)] += node.weight * s.hessians.vv[(a, b)];
                    }
                }
                continue;
            }
            let Scratch {
                q,
                v,
                cdot,
                full,
                plus,
                minus,
                node_k,
                ..
            } = s;
            let dl_dcdot = |c: &[f64], out: &mut [f64]| {
                routh.cyclic.iter().zip(c).for_each(|(&i, c)| v[i] = *c);
                routh.full.dl_dv(q, v, node.t, full)?;
                routh.cyclic.iter().zip(out.iter_mut()).for_each(|(&i, o)| *o = full[i]);
                Ok::<(), ModelError>(())
            };
            central_jacobian(dl_dcdot, cdot, difference::unit, Evaluations { plus, minus }, node_k)?;
            k.iter_mut().zip(node_k.iter()).for_each(|(k, d)| *k += node.weight * d);
        }
        Ok(())
    }

    fn correct(&mut self, delta: &[f64]) -> Correction {
        Correction::relative(&mut self.s.cdot, delta)
    }

    /// ‖F‖∞ ≤ 4ε‖μ‖∞: the momenta to round-off.
    fn solved(&self, residual: f64) -> bool {
        let scale = self.routh.momenta.iter().fold(f64::MIN_POSITIVE, |a, b| a.max(b.abs()));
        residual <= 4.0 * f64::EPSILON * scale
    }

    /// The rounding of μ.
    fn noise(&self) -> f64 {
        4.0 * f64::EPSILON * norm(&self.routh.momenta)
    }
}

impl<L: Lagrangian + ?Sized> Lagrangian for Routhian<'_, L> {
    fn dim(&self) -> usize {
        self.shape.len()
    }

    /// R = L − μ·ċ.
    fn lagrangian(&self, x: &[f64], xdot: &[f64], t: f64) -> Result<f64, ModelError> {
        let s = &mut *self.scratch.borrow_mut();
        self.solve_at(s, x, xdot, t)?;
        self.value(s, t)
    }

    /// ∂R/∂x = ∂L/∂x at the solved ċ.
    fn dl_dq(&self, x: &[f64], xdot: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.shape_derivative(x, xdot, t, out, L::dl_dq)
    }

    /// ∂R/∂ẋ = ∂L/∂ẋ at the solved ċ.
    fn dl_dv(&self, x: &[f64], xdot: &[f64], t: f64, out: &mut [f64]) -> Result<(), ModelError> {
        self.shape_derivative(x, xdot, t, out, L::dl_dv)
    }

    /// The Hessians of R are Schur complements of those of L: with K = ∂²L/∂ċ² and the
    /// couplings B_q = ∂²L/∂x∂ċ, B_v = ∂²L/∂ẋ∂ċ (since dċ = −K⁻¹(B_qᵀdx + B_vᵀdẋ)),
    /// R_xx = L_xx − B_qK⁻¹B_qᵀ, R_xẋ = L_xẋ − B_qK⁻¹B_vᵀ, R_ẋẋ = L_ẋẋ − B_vK⁻¹B_vᵀ.
    fn hessians(&self, x: &[f64], xdot: &[f64], t: f64, out: &mut Hessians) -> Result<bool, ModelError> {
        let s = &mut *self.scratch.borrow_mut();
        self.solve_at(s, x, xdot, t)?;
        if !self.full.hessians(&s.q, &s.v, t, &mut s.hessians)? {
            return Ok(false);
        }
        let Scratch {
            hessians: hl,
            k,
            pivots,
            kinv_b,
            column,
            ..
        } = s;
        for (j, &a) in self.cyclic.iter().enumerate() {
            for (l, &b) in self.cyclic.iter().enumerate() {
                k[(j, l)] = hl.vv[(a, b)];
            }
        }
        if lu_in_place(k, pivots).is_none() {
            return Err("∂²L/∂ċ² is singular: the cyclic velocities are not determined by their momenta".into());
        }
        let r = self.shape.len();
        for (col, &i) in self.shape.iter().enumerate() {
            for (block, h) in [&hl.qv, &hl.vv].into_iter().enumerate() {
                for (j, &c) in self.cyclic.iter().enumerate() {
                    column[j] = h[(i, c)];
                }
                lu_solve(k, pivots, column.as_mut_slice());
                kinv_b.column_mut(block * r + col).copy_from(column);
            }
        }
        for (a, &i) in self.shape.iter().enumerate() {
            for (b, &j) in self.shape.iter().enumerate() {
                let (mut qq, mut qv, mut vv) = (hl.qq[(i, j)], hl.qv[(i, j)], hl.vv[(i, j)]);
                for (l, &c) in self.cyclic.iter().enumerate() {
                    qq -= hl.qv[(i, c)] * kinv_b[(l, b)];
                    qv -= hl.qv[(i, c)] * kinv_b[(l, r + b)];
                    vv -= hl.vv[(i, c)] * kinv_b[(l, r + b)];
                }
                out.qq[(a, b)] = qq;
                out.qv[(a, b)] = qv;
                out.vv[(a, b)] = vv;
            }
        }
        Ok(true)
    }

    fn is_time_dependent(&self) -> bool {
        self.full.is_time_dependent()
    }

    /// ẋ from p_x: the full inverse Legendre transform at p = (p_x, μ).
    fn velocity(&self, x: &[f64], p: &[f64], t: f64, xdot: &mut [f64]) -> Result<(), ModelError> {
        let s = &mut *self.scratch.borrow_mut();
        for (k, &i) in self.shape.iter().enumerate() {
            s.q[i] = x[k];
            s.p[i] = p[k];
        }
        for (k, &i) in self.cyclic.iter().enumerate() {
            s.p[i] = self.momenta[k];
        }
        // From q̇ = 0, as the solve of ċ: ẋ depends on (x, p) alone.
        s.v.fill(0.0);
        let Scratch { q, v, p, .. } = &mut *s;
        self.full.velocity(q, p, t, v)?;
        self.shape.iter().zip(xdot.iter_mut()).for_each(|(&i, o)| *o = s.v[i]);
        self.cyclic
            .iter()
            .zip(s.cdot.iter_mut())
            .for_each(|(&i, c)| *c = s.v[i]);
        s.solved = None;
        Ok(())
    }
}
