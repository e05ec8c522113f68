use super::{combine, DiscreteLagrangian, Segment, Vector, Workspace};
use crate::model::Lagrangian;
use crate::ModelError;
use serde::{Deserialize, Serialize};

/// The trapezoidal rule, L_d = (h/2)[L(q₀, v, t) + L(q₁, v, t + h)] with v = δq/h.
///
/// D₁L_d = (h/2)∂L/∂q(q₀) − ½[∂L/∂q̇(q₀) + ∂L/∂q̇(q₁)] and
/// D₂L_d = (h/2)∂L/∂q(q₁) + ½[∂L/∂q̇(q₀) + ∂L/∂q̇(q₁)]. For L = ½vᵀMv − V these are
/// p₀ = Mv + (h/2)∇V(q₀) and p₁ = Mv − (h/2)∇V(q₁): solved for (q₁, p₁), Störmer–Verlet.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct Trapezoidal;

impl Trapezoidal {
    /// ∂L/∂q at q₀ (`at_end` false) or q₁ into ws.a, and ½[∂L/∂q̇(q₀) + ∂L/∂q̇(q₁)] into ws.b.
    fn derivatives<S: Lagrangian + ?Sized, V: Vector>(
        sys: &S,
        at: &Segment<'_>,
        at_end: bool,
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        let Segment { q0, t, h, .. } = *at;
        ws.set(at, 1.0);
        if at_end {
            sys.dl_dq(ws.x.as_ref(), ws.v.as_ref(), t + h, ws.a.as_mut())?;
        } else {
            sys.dl_dq(q0, ws.v.as_ref(), t, ws.a.as_mut())?;
        }
        sys.dl_dv(q0, ws.v.as_ref(), t, ws.b.as_mut())?;
        sys.dl_dv(ws.x.as_ref(), ws.v.as_ref(), t + h, ws.c.as_mut())?;
        for (b, c) in ws.b.as_mut().iter_mut().zip(ws.c.as_ref()) {
            *b = 0.5 * (*b + c);
        }
        Ok(())
    }
}

impl DiscreteLagrangian for Trapezoidal {
    fn quadrature(&self) -> (&'static [f64], &'static [f64]) {
        (&[0.0, 1.0], &[0.5, 0.5])
    }

    fn value<S: Lagrangian + ?Sized>(&self, sys: &S, at: Segment<'_>) -> Result<f64, ModelError> {
        let Segment { q0, t, h, .. } = at;
        let mut ws = Workspace::new(q0.len());
        ws.set(&at, 1.0);
        Ok(0.5 * h * (sys.lagrangian(q0, ws.v.as_ref(), t)? + sys.lagrangian(ws.x.as_ref(), ws.v.as_ref(), t + h)?))
    }

    fn d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        Self::derivatives(sys, &at, false, ws)?;
        combine(out, 0.5 * at.h, ws.a.as_ref(), -1.0, ws.b.as_ref());
        Ok(())
    }

    fn d2<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        Self::derivatives(sys, &at, true, ws)?;
        combine(out, 0.5 * at.h, ws.a.as_ref(), 1.0, ws.b.as_ref());
        Ok(())
    }

    /// (h/2)[∂L/∂q(q₀) + ∂L/∂q(q₁)].
    fn momentum_change<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        let Segment { q0, t, h, .. } = at;
        ws.set(&at, 1.0);
        sys.dl_dq(q0, ws.v.as_ref(), t, ws.a.as_mut())?;
        sys.dl_dq(ws.x.as_ref(), ws.v.as_ref(), t + h, ws.b.as_mut())?;
        combine(out, 0.5 * h, ws.a.as_ref(), 0.5 * h, ws.b.as_ref());
        Ok(())
    }

    /// (h/2)[∂L/∂q(q₀) + ∂L/∂q(q₁)], ∂L/∂q(q₀) from D₁L_d's evaluation (ws.a).
    fn momentum_change_after_d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        let Segment { t, h, .. } = at;
        sys.dl_dq(ws.x.as_ref(), ws.v.as_ref(), t + h, ws.b.as_mut())?;
        combine(out, 0.5 * h, ws.a.as_ref(), 0.5 * h, ws.b.as_ref());
        Ok(())
    }
}
