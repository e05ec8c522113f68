use super::{combine, DiscreteLagrangian, Segment, Vector, Workspace};
use crate::model::Lagrangian;
use crate::ModelError;

/// The left rectangle rule, L_d = h·L(q₀, δq/h, t).
///
/// D₁L_d = h∂L/∂q(q₀) − ∂L/∂q̇(q₀) and D₂L_d = ∂L/∂q̇(q₀). For L = ½vᵀMv − V these give
/// symplectic Euler, p₁ = p₀ − h∇V(q₀), q₁ = q₀ + hM⁻¹p₁.
#[derive(Clone, Copy, Debug, Default)]
pub struct Rectangle;

impl DiscreteLagrangian for Rectangle {
    fn quadrature(&self) -> (&'static [f64], &'static [f64]) {
        (&[0.0], &[1.0])
    }

    fn value<S: Lagrangian + ?Sized>(&self, sys: &S, at: Segment<'_>) -> Result<f64, ModelError> {
        let Segment { q0, t, h, .. } = at;
        let mut ws = Workspace::new(q0.len());
        ws.set(&at, 0.0);
        Ok(h * sys.lagrangian(q0, ws.v.as_ref(), t)?)
    }

    fn d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        let Segment { q0, t, h, .. } = at;
        ws.set(&at, 0.0);
        sys.gradients(q0, ws.v.as_ref(), t, ws.a.as_mut(), ws.b.as_mut())?;
        combine(out, h, ws.a.as_ref(), -1.0, ws.b.as_ref());
        Ok(())
    }

    fn d2<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        let Segment { q0, t, .. } = at;
        ws.set(&at, 0.0);
        sys.dl_dv(q0, ws.v.as_ref(), t, out)
    }

    /// h·∂L/∂q(q₀).
    fn momentum_change<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        let Segment { q0, t, h, .. } = at;
        ws.set(&at, 0.0);
        sys.dl_dq(q0, ws.v.as_ref(), t, out)?;
        out.iter_mut().for_each(|x| *x *= h);
        Ok(())
    }
}
