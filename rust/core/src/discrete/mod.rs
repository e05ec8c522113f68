//! Discrete Lagrangians L_d(q₀, q₁, h) ≈ ∫ L(q, q̇, t) dt over [t, t + h], and their discrete
//! Legendre transforms
//!
//! p₀ = −D₁L_d(q₀, q₁),   p₁ = D₂L_d(q₀, q₁)      (Marsden & West, Acta Numerica 2001).
//!
//! A one-step method (q₀, p₀) ↦ (q₁, p₁) defined by these two equations is symplectic, and it
//! conserves p·ξ(q) whenever L_d is invariant under the symmetry ξ. For separable systems the
//! explicit methods of [`crate::integrators`] solve them in closed form (Störmer–Verlet for
//! [`Trapezoidal`], symplectic Euler for [`Rectangle`]); for general Lagrangians
//! [`crate::integrators::Del`] solves them by Newton's method.
//!
//! The end point is passed by its increment, q₁ = q₀ + δq: the discrete velocity δq/h then
//! carries the increment's full precision rather than the round-off of q₁ − q₀ (HLW VIII.5).

use serde::{Deserialize, Serialize};
mod galerkin;
mod midpoint;
mod rectangle;
mod trapezoidal;

pub use galerkin::{Galerkin, Quadrature};
pub use midpoint::Midpoint;
pub use rectangle::Rectangle;
pub use trapezoidal::Trapezoidal;

use crate::model::Lagrangian;
use crate::ModelError;

/// A vector of the scratch space: a `Vec` for any n, or an array `[f64; N]` for a loop whose
/// size is known when it is compiled (the fixed-size DEL step), so that its loops unroll.
pub trait Vector: AsRef<[f64]> + AsMut<[f64]> {}

impl<T: AsRef<[f64]> + AsMut<[f64]>> Vector for T {}

/// Scratch space for the slot derivatives of a discrete Lagrangian, so that Newton iterations
/// allocate nothing.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Workspace<V = Vec<f64>> {
    v: V,
    x: V,
    a: V,
    b: V,
    c: V,
    /// ∂L/∂t at the rule's node from the last evaluation of the gradients, where the model
    /// gives it with them ([`Lagrangian::gradients_and_dl_dt`]); not state, so not kept.
    #[serde(skip)]
    dl_dt: [Option<f64>; 1],
    /// Whether the next evaluation of the gradients takes ∂L/∂t with them
    /// ([`Workspace::keep_dl_dt`]).
    #[serde(skip)]
    with_dl_dt: bool,
}

impl<V> Workspace<V> {
    /// Has the next evaluation of the gradients take ∂L/∂t with them, for the energy balance:
    /// Newton's last evaluation, at the solution; the others take the gradients alone.
    pub(crate) fn keep_dl_dt(&mut self) {
        self.with_dl_dt = true;
    }
}

impl Workspace {
    pub fn new(n: usize) -> Self {
        Workspace {
            v: vec![0.0; n],
            x: vec![0.0; n],
            a: vec![0.0; n],
            b: vec![0.0; n],
            c: vec![0.0; n],
            dl_dt: [None],
            with_dl_dt: false,
        }
    }
}

impl<const N: usize> Default for Workspace<[f64; N]> {
    fn default() -> Self {
        Workspace {
            v: [0.0; N],
            x: [0.0; N],
            a: [0.0; N],
            b: [0.0; N],
            c: [0.0; N],
            dl_dt: [None],
            with_dl_dt: false,
        }
    }
}

impl<V: Vector> Workspace<V> {
    /// v = δq/h and x = q₀ + s·δq.
    #[inline(always)]
    fn set(&mut self, at: &Segment<'_>, s: f64) {
        let (v, x) = (self.v.as_mut(), self.x.as_mut());
        for (((v, x), a), d) in v.iter_mut().zip(x.iter_mut()).zip(at.q0).zip(at.dq) {
            *v = d / at.h;
            *x = a + s * d;
        }
    }
}

/// Where a discrete Lagrangian is evaluated: from q₀ at time t over a step h, with the
/// increments of its control points from q₀ (for the two-point rules just δq = q₁ − q₀; for
/// [`Galerkin`] Q₁ − q₀, …, Q_s − q₀).
#[derive(Clone, Copy, Debug)]
pub struct Segment<'a> {
    pub q0: &'a [f64],
    pub dq: &'a [f64],
    pub t: f64,
    pub h: f64,
}

/// A discrete Lagrangian of a [`Lagrangian`] system, with its slot derivatives, at
/// (q₀, q₁ = q₀ + δq) for the step [t, t + h].
pub trait DiscreteLagrangian {
    /// The quadrature (nodes cᵢ, weights bᵢ) that defines the rule along the straight line:
    /// L_d = h Σᵢ bᵢ L(q₀ + cᵢδq, δq/h, t + cᵢh).
    fn quadrature(&self) -> (&'static [f64], &'static [f64]);

    /// ∂L/∂t at the quadrature's nodes as the last D₁L_d's evaluation left it in `ws`, node by
    /// node (None, or fewer, where it did not): for `Quadrature::time_derivative`. None by
    /// default.
    fn kept_dl_dt<'w, V: Vector>(&self, _ws: &'w Workspace<V>) -> &'w [Option<f64>] {
        &[]
    }

    /// L_d(q₀, q₀ + δq, h).
    fn value<S: Lagrangian + ?Sized>(&self, sys: &S, at: Segment<'_>) -> Result<f64, ModelError>;

    /// Writes D₁L_d(q₀, q₀ + δq, h) into `out`.
    fn d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError>;

    /// Writes D₂L_d(q₀, q₀ + δq, h) into `out`.
    fn d2<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError>;

    /// Writes D₁L_d + D₂L_d, the change of momentum p₁ − p₀ over the step when p₀ = −D₁L_d,
    /// in a form free of the cancellation between the two (the ∂L/∂q̇ terms drop out).
    fn momentum_change<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError>;

    /// [`Self::momentum_change`] right after [`Self::d1`] at the same segment, with what `d1`
    /// left in `ws`: a step solver's last evaluation is D₁L_d at the solution, whose ∂L/∂q the
    /// rules reuse instead of evaluating it again (the same numbers). Default: evaluate anew.
    fn momentum_change_after_d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        self.momentum_change(sys, at, out, ws)
    }

    /// The discrete Legendre transform F⁻L_d: p₀ = −D₁L_d(q₀, q₁, h).
    fn momentum_minus<S: Lagrangian + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        t: f64,
        h: f64,
    ) -> Result<Vec<f64>, ModelError> {
        let mut p = vec![0.0; q0.len()];
        let dq = increment(q0, q1);
        let at = Segment { q0, dq: &dq, t, h };
        self.d1(sys, at, &mut p, &mut Workspace::new(q0.len()))?;
        p.iter_mut().for_each(|x| *x = -*x);
        Ok(p)
    }

    /// The discrete Legendre transform F⁺L_d: p₁ = D₂L_d(q₀, q₁, h).
    fn momentum_plus<S: Lagrangian + ?Sized>(
        &self,
        sys: &S,
        q0: &[f64],
        q1: &[f64],
        t: f64,
        h: f64,
    ) -> Result<Vec<f64>, ModelError> {
        let mut p = vec![0.0; q0.len()];
        let dq = increment(q0, q1);
        let at = Segment { q0, dq: &dq, t, h };
        self.d2(sys, at, &mut p, &mut Workspace::new(q0.len()))?;
        Ok(p)
    }
}

/// δq = q₁ − q₀.
pub fn increment(q0: &[f64], q1: &[f64]) -> Vec<f64> {
    q0.iter().zip(q1).map(|(a, b)| b - a).collect()
}

/// out = α·a + β·b.
#[inline(always)]
fn combine(out: &mut [f64], alpha: f64, a: &[f64], beta: f64, b: &[f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = alpha * x + beta * y;
    }
}
