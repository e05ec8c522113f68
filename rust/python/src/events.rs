//! Events as Python gives them: each a spec tuple `(name, direction, terminal, kind, payload)`,
//! the built-in kinds turned into the core's [`NativeEvent`]s (evaluated without the GIL), a
//! Python function called per evaluation with the GIL.

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::{Dynamics, EventFunctions, EventSpec, NativeEvent};
use varmech::ModelError;

use crate::contacts::native_surface;
use crate::errors::{boxed, to_pyerr};

/// One event function: built in, or a Python g(t, q, p) or g(t, q, v) (`velocities`).
enum Function {
    Native(NativeEvent),
    Python { function: Py<PyAny>, velocities: bool },
}

/// A run's event functions, with the velocity buffer of the (t, q, v) ones.
pub struct Events {
    functions: Vec<Function>,
    v: Vec<f64>,
}

/// The spec tuple Python passes: name, direction, terminal count (0: never), kind and payload.
pub type EventTuple<'py> = (String, i8, usize, String, Bound<'py, PyAny>);

impl Events {
    /// The functions and specs of the spec tuples, for a model of n coordinates. Kinds: `"p"`,
    /// `"v"` (payload the function), `"crossing"` ((k, value)), `"ellipsoid"` ((coordinates,
    /// centre, semi_axes, inside)), `"energy_error"` (bound), `"multiplier"` (row),
    /// `"escape"`, `"encounter"` ((radius, groups)). A malformed one is a ValueError naming
    /// `events`.
    pub fn new(py: Python<'_>, tuples: Vec<EventTuple<'_>>, n: usize) -> PyResult<(Self, Vec<EventSpec>)> {
        let mut functions = Vec::with_capacity(tuples.len());
        let mut specs = Vec::with_capacity(tuples.len());
        for (name, direction, terminal, kind, payload) in tuples {
            let function = match kind.as_str() {
                "p" | "v" => Function::Python {
                    function: payload.unbind(),
                    velocities: kind == "v",
                },
                // The crossing of a contact's surface: g = φ.
                "crossing" | "ellipsoid" => Function::Native(native_surface(kind == "ellipsoid", &payload)?.into()),
                "energy_error" => {
                    // (bound, E₀) for a resumed run; bound alone, E₀ taken at the start.
                    let (bound, initial) = payload
                        .extract::<(f64, f64)>()
                        .or_else(|_| payload.extract::<f64>().map(|bound| (bound, f64::NAN)))?;
                    Function::Native(NativeEvent::EnergyError { bound, initial })
                }
                "multiplier" => Function::Native(NativeEvent::Multiplier {
                    row: payload.extract()?,
                    reaction: None,
                }),
                "escape" | "encounter" => {
                    let (radius, groups) = payload.extract()?;
                    Function::Native(if kind == "escape" {
                        NativeEvent::Escape { radius, groups }
                    } else {
                        NativeEvent::Encounter { radius, groups }
                    })
                }
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "events: unknown kind {kind:?} of {name}"
                    )))
                }
            };
            if let Function::Native(native) = &function {
                native.check(&name, n).map_err(|e| to_pyerr(py, e))?;
            }
            functions.push(function);
            specs.push(EventSpec {
                name,
                direction,
                terminal,
            });
        }
        Ok((
            Events {
                functions,
                v: vec![0.0; n],
            },
            specs,
        ))
    }
}

impl Events {
    /// The functions as the core's native events, for runs without the GIL (ensembles); a
    /// Python function among them is a ValueError naming `events` and it.
    pub fn into_native(self, specs: &[EventSpec]) -> PyResult<Vec<NativeEvent>> {
        self.functions
            .into_iter()
            .zip(specs)
            .map(|(f, spec)| match f {
                Function::Native(native) => Ok(native),
                Function::Python { .. } => Err(PyValueError::new_err(format!(
                    "events: {} is a Python function; the parallel ensemble watches only the built-in events",
                    spec.name
                ))),
            })
            .collect()
    }
}

impl EventFunctions for Events {
    fn len(&self) -> usize {
        self.functions.len()
    }

    fn start(&mut self, model: &dyn Dynamics, t: f64, q: &[f64], p: &[f64]) -> Result<(), ModelError> {
        self.functions.iter_mut().try_for_each(|f| match f {
            Function::Native(native) => native.start(model, t, q, p),
            Function::Python { .. } => Ok(()),
        })
    }

    fn evaluate(
        &mut self,
        model: &dyn Dynamics,
        t: f64,
        q: &[f64],
        p: &[f64],
        g: &mut [f64],
    ) -> Result<(), ModelError> {
        let v = &mut self.v;
        for (f, g) in self.functions.iter_mut().zip(g) {
            *g = match f {
                Function::Native(native) => native.value(model, t, q, p)?,
                Function::Python { function, velocities } => {
                    let x = if *velocities {
                        model.as_lagrangian().velocity(q, p, t, v)?;
                        &*v
                    } else {
                        p
                    };
                    Python::attach(|py| {
                        let args = (t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, x));
                        function.call1(py, args)?.extract::<f64>(py)
                    })
                    .map_err(boxed)?
                }
            };
        }
        Ok(())
    }
}
