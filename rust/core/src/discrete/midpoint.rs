use super::{combine, DiscreteLagrangian, Segment, Vector, Workspace};
use crate::model::Lagrangian;
use crate::ModelError;
use serde::{Deserialize, Serialize};

/// The midpoint rule, L_d = h·L(q₀ + δq/2, δq/h, t + h/2).
///
/// D₁L_d = (h/2)∂L/∂q − ∂L/∂q̇ and D₂L_d = (h/2)∂L/∂q + ∂L/∂q̇, both at the midpoint: its
/// variational integrator is the implicit midpoint rule, symmetric and of order 2, and free of
/// the parasitic modes of the trapezoidal rule on velocity-linear Lagrangians.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct Midpoint;

impl Midpoint {
    /// ∂L/∂q into ws.a and ∂L/∂q̇ into ws.b, at the midpoint (∂L/∂t into ws.dl_dt where asked,
    /// [`Workspace::keep_dl_dt`], and the model gives it with them).
    #[inline(always)]
    fn derivatives<S: Lagrangian + ?Sized, V: Vector>(
        sys: &S,
        at: &Segment<'_>,
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        ws.set(at, 0.5);
        let (x, v, t) = (ws.x.as_ref(), ws.v.as_ref(), at.t + 0.5 * at.h);
        ws.dl_dt[0] = if std::mem::take(&mut ws.with_dl_dt) {
            sys.gradients_and_dl_dt(x, v, t, ws.a.as_mut(), ws.b.as_mut())?
        } else {
            sys.gradients(x, v, t, ws.a.as_mut(), ws.b.as_mut())?;
            None
        };
        Ok(())
    }
}

impl DiscreteLagrangian for Midpoint {
    fn quadrature(&self) -> (&'static [f64], &'static [f64]) {
        (&[0.5], &[1.0])
    }

    fn kept_dl_dt<'w, V: Vector>(&self, ws: &'w Workspace<V>) -> &'w [Option<f64>] {
        &ws.dl_dt
    }

    fn value<S: Lagrangian + ?Sized>(&self, sys: &S, at: Segment<'_>) -> Result<f64, ModelError> {
        let mut ws = Workspace::new(at.q0.len());
        ws.set(&at, 0.5);
        Ok(at.h * sys.lagrangian(ws.x.as_ref(), ws.v.as_ref(), at.t + 0.5 * at.h)?)
    }

    #[inline(always)]
    fn d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        Self::derivatives(sys, &at, ws)?;
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
        Self::derivatives(sys, &at, ws)?;
        combine(out, 0.5 * at.h, ws.a.as_ref(), 1.0, ws.b.as_ref());
        Ok(())
    }

    /// h·∂L/∂q at the midpoint.
    fn momentum_change<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        ws.set(&at, 0.5);
        sys.dl_dq(ws.x.as_ref(), ws.v.as_ref(), at.t + 0.5 * at.h, out)?;
        out.iter_mut().for_each(|x| *x *= at.h);
        Ok(())
    }

    /// h·∂L/∂q from D₁L_d's evaluation (ws.a).
    fn momentum_change_after_d1<S: Lagrangian + ?Sized, V: Vector>(
        &self,
        _sys: &S,
        at: Segment<'_>,
        out: &mut [f64],
        ws: &mut Workspace<V>,
    ) -> Result<(), ModelError> {
        out.iter_mut().zip(ws.a.as_ref()).for_each(|(o, a)| *o = a * at.h);
        Ok(())
    }
}
