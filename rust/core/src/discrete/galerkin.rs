use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::Segment;
use crate::model::{Hessians, Lagrangian};
use crate::solve::sized;
use crate::ModelError;

/// L_d = h Σᵢ bᵢ L(q(cᵢh), q̇(cᵢh), t + cᵢh) along the polynomial q(τh) = Σⱼ ℓⱼ(τ)Qⱼ of degree
/// s through the control points Q₀ = q₀, Q₁, …, Q_s = q₁ at τ = j/s. A step's equations are
/// ∂L_d/∂Qⱼ for the slots j = 1, …, s−1 and then 0, its unknowns the increments Q₁ − q₀, …,
/// Q_s − q₀. Degree 1 gives the two-point rules (midpoint: c = ½; trapezoid: c = 0, 1).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Quadrature {
    s: usize,
    nodes: Vec<f64>,
    weights: Vec<f64>,
    /// ℓⱼ(cᵢ) and ℓⱼ'(cᵢ), row i, column j = 0..=s.
    basis: Vec<Vec<f64>>,
    slopes: Vec<Vec<f64>>,
    /// sign det K, K = (Σᵢ bᵢℓⱼ'(cᵢ)ℓₖ'(cᵢ)) over the slots j and the unknowns k: the
    /// Jacobian of the equations tends to (1/h)·K ⊗ ∂²L/∂q̇² as h → 0.
    k_sign: f64,
    pos: Vec<f64>,
    vel: Vec<f64>,
    hessians: Hessians,
}

impl Quadrature {
    /// The rule (nodes cᵢ, weights bᵢ) along the polynomial of degree s, for n coordinates.
    pub(crate) fn new(s: usize, nodes: &[f64], weights: &[f64], n: usize) -> Self {
        let d: Vec<f64> = (0..=s).map(|j| j as f64 / s as f64).collect();
        let ell = |j: usize, x: f64| {
            (0..=s)
                .filter(|&m| m != j)
                .map(|m| (x - d[m]) / (d[j] - d[m]))
                .product::<f64>()
        };
        let slope = |j: usize, x: f64| {
            (0..=s)
                .filter(|&k| k != j)
                .map(|k| {
                    (0..=s)
                        .filter(|&m| m != j && m != k)
                        .map(|m| (x - d[m]) / (d[j] - d[m]))
                        .product::<f64>()
                        / (d[j] - d[k])
                })
                .sum::<f64>()
        };
        let basis = nodes.iter().map(|&c| (0..=s).map(|j| ell(j, c)).collect()).collect();
        let slopes: Vec<Vec<f64>> = nodes.iter().map(|&c| (0..=s).map(|j| slope(j, c)).collect()).collect();
        let slot = |r: usize| if r + 1 < s { r + 1 } else { 0 };
        let k = DMatrix::from_fn(s, s, |r, c| {
            (0..nodes.len())
                .map(|i| weights[i] * slopes[i][slot(r)] * slopes[i][c + 1])
                .sum::<f64>()
        });
        Quadrature {
            s,
            nodes: nodes.to_vec(),
            weights: weights.to_vec(),
            basis,
            slopes,
            k_sign: k.determinant().signum(),
            pos: vec![0.0; n],
            vel: vec![0.0; n],
            hessians: Hessians::zeros(n),
        }
    }

    /// The degree s: the number of unknown control points.
    pub(crate) fn degree(&self) -> usize {
        self.s
    }

    /// The slot of the r-th block of equations: Q₁, …, Q_{s−1}, then Q₀.
    #[inline(always)]
    fn slot(&self, r: usize) -> usize {
        if r + 1 < self.s {
            r + 1
        } else {
            0
        }
    }

    /// `pos` = q(cᵢh) and `vel` = q̇(cᵢh) for the control increments `at.dq`.
    #[inline(always)]
    fn node_state(&mut self, i: usize, at: &Segment<'_>) {
        let n = at.q0.len();
        for a in 0..n {
            let (mut pos, mut vel) = (0.0, 0.0);
            for j in 1..=self.s {
                let xj = at.dq[(j - 1) * n + a];
                pos += self.basis[i][j] * xj;
                vel += self.slopes[i][j] * xj;
            }
            self.pos[a] = at.q0[a] + pos;
            self.vel[a] = vel / at.h;
        }
    }

    /// ∂L_d/∂t = h Σᵢ bᵢ ∂L/∂t(q(cᵢh), q̇(cᵢh), t + cᵢh) over the step at `at`: what L's
    /// dependence on t takes from the energy, E₁ − E₀ = W − ∂L_d/∂t to the method's order (W
    /// the forces' work); 0 for an L that does not depend on t. ∂L/∂t at node i is `kept[i]`
    /// where the gradients' last evaluation there gave it
    /// ([`Lagrangian::gradients_and_dl_dt`]), else [`Lagrangian::dl_dt`] evaluated.
    pub(crate) fn time_derivative<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        at: Segment<'_>,
        kept: &[Option<f64>],
    ) -> Result<f64, ModelError> {
        if !sys.is_time_dependent() {
            return Ok(0.0);
        }
        let mut sum = 0.0;
        // Over the nodes: as many as the degree for Gauss's rules, two for the trapezoid's.
        for i in 0..self.nodes.len() {
            let dl_dt = match kept.get(i) {
                Some(&Some(dl_dt)) => dl_dt,
                _ => self.evaluated_dl_dt(sys, &at, i)?,
            };
            sum += self.weights[i] * dl_dt;
        }
        Ok(at.h * sum)
    }

    /// ∂L/∂t at node i, evaluated: out of line, so that the kept values' loop (a compiled
    /// model's every step) carries none of its frame.
    #[cold]
    #[inline(never)]
    fn evaluated_dl_dt<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        at: &Segment<'_>,
        i: usize,
    ) -> Result<f64, ModelError> {
        self.node_state(i, at);
        sys.dl_dt(&self.pos, &self.vel, at.t + self.nodes[i] * at.h)
    }

    /// The sign of det ∂F/∂x as h → 0: sign(det K)ⁿ·sign(det ∂²L/∂q̇²)ˢ.
    pub(crate) fn continuum_sign(&self, n: usize, hessian_sign: f64) -> f64 {
        self.k_sign.powi(n as i32) * hessian_sign.powi(self.s as i32)
    }

    /// Writes ∂F/∂x into `jac` from the model's exact second derivatives at the nodes,
    ///
    /// ∂F_r/∂Qₖ = Σᵢ bᵢ[hℓⱼℓₖ L_qq + ℓⱼℓₖ' L_qq̇ + ℓⱼ'ℓₖ L_q̇q + ℓⱼ'ℓₖ' L_q̇q̇/h](cᵢ), j = slot(r),
    ///
    /// and returns true; false when the model supplies none.
    pub(crate) fn jacobian<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        at: Segment<'_>,
        jac: &mut DMatrix<f64>,
    ) -> Result<bool, ModelError> {
        let stride = jac.nrows();
        self.jacobian_into(sys, at, jac.as_mut_slice(), stride)
    }

    /// [`Quadrature::jacobian`] into the column-major `jac` of column stride `stride`: a
    /// matrix's storage or an array's, whose size the inlined loops then know.
    #[inline(always)]
    pub(crate) fn jacobian_into<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        at: Segment<'_>,
        jac: &mut [f64],
        stride: usize,
    ) -> Result<bool, ModelError> {
        let (n, t, h) = (at.q0.len(), at.t, at.h);
        jac.fill(0.0);
        for i in 0..self.nodes.len() {
            self.node_state(i, &at);
            if !sys.hessians(&self.pos, &self.vel, t + self.nodes[i] * h, &mut self.hessians)? {
                return Ok(false);
            }
            let (b, hs) = (self.weights[i], &self.hessians);
            for r in 0..self.s {
                let j = self.slot(r);
                let (lj, dj) = (self.basis[i][j], self.slopes[i][j]);
                for c in 0..self.s {
                    let (lk, dk) = (self.basis[i][c + 1], self.slopes[i][c + 1]);
                    let weights = [b * h * lj * lk, b * lj * dk, b * dj * lk, b * dj * dk / h];
                    let jac = &mut jac[c * n * stride + r * n..];
                    sized!(add_block(jac, stride, weights, hs; n));
                }
            }
        }
        Ok(true)
    }
}

/// Adds the n×n block qq·L_qq + qv·L_qq̇ + vq·L_q̇q + vv·L_q̇q̇ to the column-major `jac` of column
/// stride `stride`, from its first entry.
#[inline(always)]
fn add_block(jac: &mut [f64], stride: usize, [qq, qv, vq, vv]: [f64; 4], hs: &Hessians, n: usize) {
    let (hqq, hqv, hvv) = (hs.qq.as_slice(), hs.qv.as_slice(), hs.vv.as_slice());
    for e in 0..n {
        for a in 0..n {
            jac[e * stride + a] +=
                qq * hqq[e * n + a] + qv * hqv[e * n + a] + vq * hqv[a * n + e] + vv * hvv[e * n + a];
        }
    }
}

/// The Galerkin discrete Lagrangian of degree s with s-point Gauss–Legendre quadrature
/// (Marsden & West 2001, §2.6; order 2s): q(τh) = Σⱼ ℓⱼ(τ)Qⱼ through the control points
/// Q₀ = q₀, Q₁, …, Q_s = q₁ at τ = j/s, and L_d = h Σᵢ bᵢ L(q(cᵢh), q̇(cᵢh), t + cᵢh), made
/// stationary in the interior points. Its slot derivatives are
///
/// ∂L_d/∂Qⱼ = Σᵢ bᵢ[hℓⱼ(cᵢ)∂L/∂q + ℓⱼ'(cᵢ)∂L/∂q̇],
///
/// and since Σⱼ ℓⱼ = 1, Σⱼ ℓⱼ' = 0, their sum is hΣᵢ bᵢ ∂L/∂q(cᵢ). A force f adds to ∂L/∂q at
/// every node (forced DEL equations), and its work over the step is hΣᵢ bᵢ f(cᵢ)·q̇(cᵢ).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Galerkin {
    pub(crate) quadrature: Quadrature,
    lq: Vec<Vec<f64>>,
    lv: Vec<Vec<f64>>,
    /// ∂L/∂t at each node where the model gives it with the gradients; not state.
    #[serde(skip)]
    dl_dt: Vec<Option<f64>>,
    f: Vec<f64>,
}

impl Galerkin {
    /// Degree s = 2 (order 4) or 3 (order 6).
    pub fn new(s: usize, n: usize) -> Self {
        let (nodes, weights) = match s {
            2 => {
                let d = 3f64.sqrt() / 6.0;
                (vec![0.5 - d, 0.5 + d], vec![0.5, 0.5])
            }
            3 => {
                let d = 15f64.sqrt() / 10.0;
                (vec![0.5 - d, 0.5, 0.5 + d], vec![5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0])
            }
            _ => panic!("Galerkin integrators of degree 2 and 3 only"),
        };
        Galerkin {
            quadrature: Quadrature::new(s, &nodes, &weights, n),
            lq: vec![vec![0.0; n]; s],
            lv: vec![vec![0.0; n]; s],
            dl_dt: vec![None; s],
            f: vec![0.0; n],
        }
    }

    /// ∂L/∂q + f and ∂L/∂q̇ at every quadrature node, for the control increments `at.dq`
    /// (Q₀ = q₀), with ∂L/∂t where `with_dl_dt` asks (at the solution, for the energy balance)
    /// and the model gives it with them; returns the forces' work over
    /// the step, h Σᵢ bᵢ f(cᵢ)·q̇(cᵢ). A force f enters
    /// where ∂L/∂q does: the discrete Lagrange–d'Alembert principle adds the virtual work
    /// h Σᵢ bᵢ f(cᵢ)·δq(cᵢh) to δL_d, and δq(cᵢh) = Σⱼ ℓⱼ(cᵢ)δQⱼ.
    pub(crate) fn derivatives<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        at: Segment<'_>,
        with_dl_dt: bool,
    ) -> Result<f64, ModelError> {
        let quad = &mut self.quadrature;
        // A scheme read from a checkpoint has none kept.
        self.dl_dt.resize(quad.s, None);
        let mut work = 0.0;
        for i in 0..quad.s {
            quad.node_state(i, &at);
            let ti = at.t + quad.nodes[i] * at.h;
            let (lq, lv) = (&mut self.lq[i], &mut self.lv[i]);
            self.dl_dt[i] = if with_dl_dt {
                sys.gradients_and_dl_dt(&quad.pos, &quad.vel, ti, lq, lv)?
            } else {
                sys.gradients(&quad.pos, &quad.vel, ti, lq, lv)?;
                None
            };
            if sys.is_forced() {
                sys.force(&quad.pos, &quad.vel, ti, &mut self.f)?;
                let mut power = 0.0;
                for ((lq, f), v) in self.lq[i].iter_mut().zip(&self.f).zip(&quad.vel) {
                    *lq += f;
                    power += f * v;
                }
                work += at.h * quad.weights[i] * power;
            }
        }
        Ok(work)
    }

    /// The energy put in over the step whose [`Galerkin::derivatives`] were the last taken, at
    /// `at`, their work `work` less ∂L_d/∂t ([`Quadrature::time_derivative`], from ∂L/∂t kept
    /// there).
    pub(crate) fn energy_put_in<S: Lagrangian + ?Sized>(
        &mut self,
        sys: &S,
        at: Segment<'_>,
        work: f64,
    ) -> Result<f64, ModelError> {
        Ok(work - self.quadrature.time_derivative(sys, at, &self.dl_dt)?)
    }

    /// How much the slots amplify the rounding of the derivatives of L they sum:
    /// maxⱼ Σᵢ |bᵢ|(h|ℓⱼ(cᵢ)| + |ℓⱼ'(cᵢ)|), at least 1 (Σᵢ bᵢℓₛ'(cᵢ) = 1).
    pub(crate) fn noise_gain(&self, h: f64) -> f64 {
        let quad = &self.quadrature;
        (0..=quad.s).fold(1.0_f64, |gain, j| {
            let slot = (0..quad.s)
                .map(|i| quad.weights[i].abs() * (h.abs() * quad.basis[i][j].abs() + quad.slopes[i][j].abs()))
                .sum::<f64>();
            gain.max(slot)
        })
    }

    /// out = ∂L_d/∂Qⱼ = Σᵢ bᵢ[hℓⱼ(cᵢ)∂L/∂q + ℓⱼ'(cᵢ)∂L/∂q̇] from the last
    /// [`Galerkin::derivatives`].
    pub(crate) fn slot(&self, j: usize, h: f64, out: &mut [f64]) {
        let quad = &self.quadrature;
        out.fill(0.0);
        for i in 0..quad.s {
            let (a, b) = (
                quad.weights[i] * h * quad.basis[i][j],
                quad.weights[i] * quad.slopes[i][j],
            );
            for ((o, lq), lv) in out.iter_mut().zip(&self.lq[i]).zip(&self.lv[i]) {
                *o += a * lq + b * lv;
            }
        }
    }

    /// The discrete energy E_d = −∂L_d/∂h of the step through the control increments `at.dq`
    /// that make L_d stationary in the interior points, which may then be held as h varies:
    /// E_d = Σᵢ bᵢ E(q(cᵢh), q̇(cᵢh)), E = q̇·∂L/∂q̇ − L, for an autonomous L.
    pub(crate) fn energy<S: Lagrangian + ?Sized>(&mut self, sys: &S, at: Segment<'_>) -> Result<f64, ModelError> {
        let quad = &mut self.quadrature;
        let mut energy = 0.0;
        for i in 0..quad.s {
            quad.node_state(i, &at);
            let ti = at.t + quad.nodes[i] * at.h;
            sys.dl_dv(&quad.pos, &quad.vel, ti, &mut self.lv[i])?;
            let momentum: f64 = self.lv[i].iter().zip(&quad.vel).map(|(p, v)| p * v).sum();
            energy += quad.weights[i] * (momentum - sys.lagrangian(&quad.pos, &quad.vel, ti)?);
        }
        Ok(energy)
    }

    /// out = Σⱼ ∂L_d/∂Qⱼ = hΣᵢ bᵢ ∂L/∂q(cᵢ) from the last [`Galerkin::derivatives`].
    pub(crate) fn slot_sum(&self, h: f64, out: &mut [f64]) {
        out.fill(0.0);
        for (lq, b) in self.lq.iter().zip(&self.quadrature.weights) {
            out.iter_mut().zip(lq).for_each(|(d, lq)| *d += h * b * lq);
        }
    }
}
