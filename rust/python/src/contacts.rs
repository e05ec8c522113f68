//! Contacts as Python gives them: each a tuple `(name, restitution, law, kind, payload,
//! friction)`, a native surface (kinds `"crossing"` and `"ellipsoid"`, the payloads of the native
//! events) evaluated without the GIL, or Python's functions φ(q) and ∇φ(q) (kind `"functions"`)
//! called with it; friction None or `(mu_s, mu_k, slip)`, slip None, its rows `(k, flat)`, or
//! `(k, function)`, a Python function of q returning them (k, n).

use std::sync::Arc;

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use varmech::integrators::{Contact, Contacts, Friction, Law, NativeContact, NativeSurface, Slip, SlipRows, Surface};
use varmech::ModelError;

use crate::closure::readers::{call_array, call_scalar, call_vector};

/// `IMPACT_LAWS`, the names of the contacts' laws ([`Law::ALL`]), which Python's contacts check.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("IMPACT_LAWS", PyTuple::new(m.py(), Law::ALL.map(Law::name))?)
}

/// The tuple Python passes: name, restitution, law, kind, payload and friction.
pub type ContactTuple<'py> = (String, f64, String, String, Bound<'py, PyAny>, Option<FrictionTuple>);

/// Friction as Python passes it: μ_s, μ_k and the slip rows, if given.
pub type FrictionTuple = (f64, f64, Option<SlipTuple>);

/// Slip rows as Python passes them: their number and entries, or their number and a function
/// of q that returns them.
#[derive(FromPyObject)]
pub enum SlipTuple {
    Rows(usize, Vec<f64>),
    Field(usize, Py<PyAny>),
}

/// Slip rows J(q) given as a Python function of q returning a (k, n) array.
struct SlipFunction {
    rows: usize,
    function: Py<PyAny>,
}

impl SlipRows for SlipFunction {
    fn count(&self) -> usize {
        self.rows
    }

    fn jacobian(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        Python::attach(|py| {
            let result = self.function.bind(py).call1((PyArray1::from_slice(py, q),));
            call_array(result, "slip", &[self.rows, q.len()], out)
        })
    }
}

/// A surface given as Python functions φ(q) -> float and ∇φ(q) -> array (n,).
struct Functions {
    phi: Py<PyAny>,
    gradient: Py<PyAny>,
}

// Borrowed for a run: the specs outlive it.
impl Surface for &Functions {
    fn phi(&self, q: &[f64]) -> Result<f64, ModelError> {
        Python::attach(|py| call_scalar(self.phi.bind(py).call1((PyArray1::from_slice(py, q),)), "phi"))
    }

    fn gradient(&self, q: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        Python::attach(|py| {
            let result = self.gradient.bind(py).call1((PyArray1::from_slice(py, q),));
            call_vector(result, "gradient", out)
        })
    }
}

/// The native surface of a contact's or an event's payload: `"crossing"` (k, value), the wall
/// q_k ≥ value, or `"ellipsoid"` (coordinates, centre, semi_axes, inside).
pub(crate) fn native_surface(ellipsoid: bool, payload: &Bound<'_, PyAny>) -> PyResult<NativeSurface> {
    Ok(if ellipsoid {
        let (coordinates, centre, semi_axes, inside) = payload.extract()?;
        NativeSurface::Ellipsoid {
            coordinates,
            centre,
            semi_axes,
            inside,
        }
    } else {
        let (coordinate, value) = payload.extract()?;
        NativeSurface::Wall { coordinate, value }
    })
}

/// A contact's surface: native, or Python's functions.
enum Kind {
    Native(NativeSurface),
    Functions(Functions),
}

/// A run's contacts as Python gave them, in order.
pub struct ContactSpecs(Vec<(Kind, f64, Law, Option<Friction>, String)>);

impl ContactSpecs {
    /// The contacts of the tuples; a malformed one is a ValueError naming `contacts`.
    pub fn new(tuples: Vec<ContactTuple<'_>>) -> PyResult<Self> {
        let mut contacts = Vec::with_capacity(tuples.len());
        for (name, restitution, law, kind, payload, friction) in tuples {
            let Some(law) = Law::named(&law) else {
                let names = Law::ALL.map(|law| format!("'{}'", law.name())).join(" or ");
                return Err(PyValueError::new_err(format!(
                    "contacts: {name}: law {names}, got {law:?}"
                )));
            };
            let kind = match kind.as_str() {
                "crossing" | "ellipsoid" => Kind::Native(native_surface(kind == "ellipsoid", &payload)?),
                "functions" => {
                    let (phi, gradient) = payload.extract()?;
                    Kind::Functions(Functions { phi, gradient })
                }
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "contacts: {name}: unknown kind {kind:?}"
                    )))
                }
            };
            let friction = friction.map(|(static_coefficient, kinetic, slip)| Friction {
                static_coefficient,
                kinetic,
                slip: match slip {
                    None => Slip::Tangent,
                    Some(SlipTuple::Rows(rows, jacobian)) => Slip::Rows { rows, jacobian },
                    Some(SlipTuple::Field(rows, function)) => Slip::Field(Arc::new(SlipFunction { rows, function })),
                },
            });
            contacts.push((kind, restitution, law, friction, name));
        }
        Ok(ContactSpecs(contacts))
    }

    /// The core's contacts, their surfaces borrowed from these.
    pub fn contacts(&self) -> Result<Contacts<'_>, varmech::Error> {
        let contacts = self.0.iter().map(|(kind, restitution, law, friction, name)| Contact {
            surface: match kind {
                Kind::Native(native) => Box::new(native.clone()) as Box<dyn Surface>,
                Kind::Functions(functions) => Box::new(functions),
            },
            restitution: *restitution,
            law: *law,
            friction: friction.clone(),
            name: name.clone(),
        });
        Contacts::new(contacts.collect())
    }

    /// The contacts as native ones, for runs without the GIL (ensembles); Python functions
    /// among them are a ValueError naming `contacts` and the contact.
    pub fn into_native(self) -> PyResult<Vec<NativeContact>> {
        self.0
            .into_iter()
            .map(|(kind, restitution, law, friction, name)| match kind {
                _ if friction.as_ref().is_some_and(|f| matches!(f.slip, Slip::Field(_))) => {
                    Err(PyValueError::new_err(format!(
                        "contacts: {name}'s friction has slip rows given by a Python function; the parallel ensemble \
                         takes only constant rows"
                    )))
                }
                Kind::Native(surface) => Ok(NativeContact {
                    surface,
                    restitution,
                    law,
                    friction,
                    name,
                }),
                Kind::Functions(_) => Err(PyValueError::new_err(format!(
                    "contacts: {name} is given by Python functions; the parallel ensemble watches only the native \
                     surfaces (Contact.wall, Contact.ellipsoid)"
                ))),
            })
            .collect()
    }
}
