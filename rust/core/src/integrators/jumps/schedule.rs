//! What a run does at given times: impulses (Byerly 1916, ch. III: a blow changes the momenta by
//! its components of impulse, Δp = P(q), and the positions not at all) and samples (the states
//! at requested times, `t_eval`). A step that holds such a time is split there: the method's
//! partial step to it from the step's start (or from the last jump before it), so that each
//! state has the method's own error, of its order.

use nalgebra::DMatrix;

use crate::solve::difference::{central_jacobian, unit, Evaluations};
use crate::{Error, ModelError};

/// A blow's components of impulse P_r = I · ∂x/∂qᵣ at the configuration q.
///
/// The binding implements it with Python callables, whose exceptions come back as the
/// [`ModelError`] unchanged.
pub trait Blow {
    /// Writes P(q) into `out` (n entries).
    fn components(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError>;

    /// Why the blow cannot act on n coordinates, if it cannot. By default it can.
    fn misfit(&self, _n: usize) -> Option<String> {
        None
    }
}

/// Components of impulse given as numbers, the same at every q.
#[derive(Clone, Debug, PartialEq)]
pub struct Generalized(pub Vec<f64>);

impl Blow for Generalized {
    fn components(&self, _q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        out.copy_from_slice(&self.0);
        Ok(())
    }

    fn misfit(&self, n: usize) -> Option<String> {
        let m = self.0.len();
        if m != n {
            return Some(format!("{m} components of impulse for {n} coordinates"));
        }
        (!self.0.iter().all(|x| x.is_finite())).then(|| "the components of impulse must be finite".into())
    }
}

/// A function of q writing its values into a slice: a point x(q) (d values) or its Jacobian
/// ∂x/∂q (d × n, row by row).
pub type PointFunction<'f> = Box<dyn Fn(&[f64], &mut [f64]) -> Result<(), ModelError> + 'f>;

/// An impulse vector I applied at the point x(q): P = (∂x/∂q)ᵀ I, with the Jacobian given or,
/// without it, by central differences of x ([`central_jacobian`], error O(ε^(2/3))).
pub struct Struck<'f> {
    pub point: PointFunction<'f>,
    pub jacobian: Option<PointFunction<'f>>,
    pub impulse: Vec<f64>,
}

impl Blow for Struck<'_> {
    fn components(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        let (d, n) = (self.impulse.len(), q.len());
        if let Some(jacobian) = &self.jacobian {
            let mut jac = vec![0.0; d * n];
            jacobian(q, &mut jac)?;
            for (i, o) in out.iter_mut().enumerate() {
                *o = (0..d).map(|k| jac[k * n + i] * self.impulse[k]).sum();
            }
            return Ok(());
        }
        let mut jac = DMatrix::zeros(d, n);
        let (mut plus, mut minus) = (vec![0.0; d], vec![0.0; d]);
        let at = Evaluations {
            plus: &mut plus,
            minus: &mut minus,
        };
        central_jacobian(|y, x| (self.point)(y, x), &mut q.to_vec(), unit, at, &mut jac)?;
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..d).map(|k| jac[(k, i)] * self.impulse[k]).sum();
        }
        Ok(())
    }

    fn misfit(&self, _n: usize) -> Option<String> {
        (self.impulse.is_empty() || !self.impulse.iter().all(|x| x.is_finite()))
            .then(|| "the impulse vector must be non-empty and finite".into())
    }
}

/// A blow at time `t`.
pub struct Impulse<'f> {
    pub t: f64,
    pub blow: Box<dyn Blow + 'f>,
}

/// The impulses and the samples of a run, each in order of time. A run acts on those in
/// (t_start, t_end] of its span, and a new run on those at its t0 too; a run resumed from a
/// checkpoint at t is given them all again and takes those after t.
#[derive(Default)]
pub struct Schedule<'f> {
    impulses: Vec<Impulse<'f>>,
    samples: Vec<f64>,
}

impl<'f> Schedule<'f> {
    /// The schedule of `impulses` (sorted by time here, stably) and `samples`. Refuses,
    /// naming `impulses`, a time that is not finite, and naming `t_eval`, samples not finite
    /// or not in increasing order.
    pub fn new(mut impulses: Vec<Impulse<'f>>, samples: Vec<f64>) -> Result<Self, Error> {
        if let Some(i) = impulses.iter().position(|b| !b.t.is_finite()) {
            return Err(Error::invalid(
                "impulses",
                format!("impulses[{i}]: its time must be finite"),
            ));
        }
        if !samples.iter().all(|t| t.is_finite()) {
            return Err(Error::invalid("t_eval", "must be finite"));
        }
        if samples.windows(2).any(|w| w[1] < w[0]) {
            return Err(Error::invalid("t_eval", "must be sorted in increasing order"));
        }
        impulses.sort_by(|a, b| a.t.total_cmp(&b.t));
        Ok(Schedule { impulses, samples })
    }

    /// The impulses, in order of time.
    pub fn impulses(&self) -> &[Impulse<'f>] {
        &self.impulses
    }

    /// The sample times, in increasing order.
    pub fn samples(&self) -> &[f64] {
        &self.samples
    }

    /// Whether there are samples: the run then saves the states at them, and those alone.
    pub fn sampling(&self) -> bool {
        !self.samples.is_empty()
    }

    /// Whether every blow acts on n coordinates.
    pub(in crate::integrators) fn fit(&self, n: usize) -> Result<(), Error> {
        for (i, b) in self.impulses.iter().enumerate() {
            if let Some(reason) = b.blow.misfit(n) {
                return Err(Error::invalid("impulses", format!("impulses[{i}]: {reason}")));
            }
        }
        Ok(())
    }
}
