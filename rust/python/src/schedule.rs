//! A run's schedule as Python gives it: impulses, each a tuple `(t, kind, payload)`, and the
//! sample times `t_eval`. Kinds: `"generalized"` (the components as numbers), `"function"`
//! (Python's P(q)), `"point"` (Python's x(q), its Jacobian or None, and the impulse vector).

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::{Blow, Generalized, Impulse, PointFunction, Schedule, Struck};
use varmech::ModelError;

use crate::closure::readers::{call_array, call_vector};

/// The tuple Python passes: the time, the kind and its payload.
pub type ImpulseTuple<'py> = (f64, String, Bound<'py, PyAny>);

/// A blow as Python gave it.
pub enum Kind {
    Generalized(Generalized),
    Function(Py<PyAny>),
    Point {
        point: Py<PyAny>,
        jacobian: Option<Py<PyAny>>,
        impulse: Vec<f64>,
    },
}

impl Kind {
    /// The blow of `kind` with its payload; an unknown kind is None.
    pub fn new(kind: &str, payload: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
        Ok(Some(match kind {
            "generalized" => Kind::Generalized(Generalized(payload.extract()?)),
            "function" => Kind::Function(payload.extract()?),
            "point" => {
                let (point, jacobian, impulse) = payload.extract()?;
                Kind::Point {
                    point,
                    jacobian,
                    impulse,
                }
            }
            _ => return Ok(None),
        }))
    }

    /// The core's blow, borrowing Python's functions.
    pub fn blow(&self) -> Box<dyn Blow + '_> {
        match self {
            Kind::Generalized(native) => Box::new(native.clone()),
            Kind::Function(f) => Box::new(Function(f)),
            Kind::Point {
                point,
                jacobian,
                impulse,
            } => {
                let d = impulse.len();
                Box::new(Struck {
                    point: point_function(point, "point", move |_| vec![d]),
                    jacobian: jacobian
                        .as_ref()
                        .map(|j| point_function(j, "jacobian", move |n| vec![d, n])),
                    impulse: impulse.clone(),
                })
            }
        }
    }

    /// The argument a misfit of the blow names: its components, or its impulse vector.
    pub fn argument(&self) -> &'static str {
        match self {
            Kind::Point { .. } => "impulse",
            _ => "generalized",
        }
    }
}

/// Components of impulse given as Python's function P(q) -> array (n,).
struct Function<'a>(&'a Py<PyAny>);

impl Blow for Function<'_> {
    fn components(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        Python::attach(|py| {
            call_vector(
                self.0.bind(py).call1((PyArray1::from_slice(py, q),)),
                "generalized",
                out,
            )
        })
    }
}

/// Python's function of q as the core's [`PointFunction`], its result read in `shape`.
fn point_function<'a>(
    f: &'a Py<PyAny>,
    call: &'static str,
    shape: impl Fn(usize) -> Vec<usize> + 'a,
) -> PointFunction<'a> {
    Box::new(move |q: &[f64], out: &mut [f64]| {
        Python::attach(|py| {
            let result = f.bind(py).call1((PyArray1::from_slice(py, q),));
            call_array(result, call, &shape(q.len()), out)
        })
    })
}

/// A run's impulses and samples as Python gave them.
#[derive(Default)]
pub struct ScheduleSpecs {
    impulses: Vec<(f64, Kind)>,
    samples: Vec<f64>,
}

impl ScheduleSpecs {
    /// The schedule of the tuples and the samples; a malformed tuple is a ValueError naming
    /// `impulses`.
    pub fn new(tuples: Vec<ImpulseTuple<'_>>, samples: Vec<f64>) -> PyResult<Self> {
        let mut impulses = Vec::with_capacity(tuples.len());
        for (i, (t, kind, payload)) in tuples.into_iter().enumerate() {
            let Some(kind) = Kind::new(&kind, &payload)? else {
                let message = format!("impulses[{i}]: unknown kind {kind:?}");
                return Err(PyValueError::new_err(message));
            };
            impulses.push((t, kind));
        }
        Ok(ScheduleSpecs { impulses, samples })
    }

    /// The impulses as native ones, for runs without the GIL (ensembles); one given by Python
    /// functions is a ValueError naming `impulses`.
    pub fn into_native(self) -> PyResult<Vec<(f64, Generalized)>> {
        (self.impulses.into_iter().enumerate())
            .map(|(i, (t, kind))| match kind {
                Kind::Generalized(blow) => Ok((t, blow)),
                _ => Err(PyValueError::new_err(format!(
                    "impulses: impulses[{i}] is given by Python functions; the parallel ensemble applies only \
                     impulses whose components are numbers (Impulse(generalized=[...]))"
                ))),
            })
            .collect()
    }

    /// Whether there is nothing to schedule.
    pub fn is_empty(&self) -> bool {
        self.impulses.is_empty() && self.samples.is_empty()
    }

    /// The core's schedule, its blows borrowed from these.
    pub fn schedule(&self) -> Result<Schedule<'_>, varmech::Error> {
        let impulses = (self.impulses.iter()).map(|(t, kind)| Impulse {
            t: *t,
            blow: kind.blow(),
        });
        Schedule::new(impulses.collect(), self.samples.clone())
    }
}
