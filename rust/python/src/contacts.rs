//! Contacts as Python gives them: each a tuple `(name, restitution, law, kind, payload,
//! friction)`, a native surface (kinds `"crossing"` and `"ellipsoid"`, the payloads of the native
//! events) evaluated without the GIL, or Python's functions φ(q) and ∇φ(q) (kind `"functions"`)
//! called with it; friction None or `(mu_s, mu_k, slip)`, slip None or its rows (k, flat).

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::{Contact, Contacts, Friction, Law, NativeContact, NativeSurface, Slip, Surface};
use varmech::ModelError;

use crate::closure::readers::{call_scalar, call_vector};

/// The tuple Python passes: name, restitution, law, kind, payload and friction.
pub type ContactTuple<'py> = (String, f64, String, String, Bound<'py, PyAny>, Option<FrictionTuple>);

/// Friction as Python passes it: μ_s, μ_k and the slip rows (their number and entries), if given.
pub type FrictionTuple = (f64, f64, Option<(usize, Vec<f64>)>);

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
            let law = match law.as_str() {
                "reflect" => Law::Reflect,
                "variational" => Law::Variational,
                _ => {
                    let message = format!("contacts: {name}: law 'variational' or 'reflect', got {law:?}");
                    return Err(PyValueError::new_err(message));
                }
            };
            let kind = match kind.as_str() {
                "crossing" => {
                    let (coordinate, value) = payload.extract()?;
                    Kind::Native(NativeSurface::Wall { coordinate, value })
                }
                "ellipsoid" => {
                    let (coordinates, centre, semi_axes, inside) = payload.extract()?;
                    Kind::Native(NativeSurface::Ellipsoid {
                        coordinates,
                        centre,
                        semi_axes,
                        inside,
                    })
                }
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
                slip: slip.map_or(Slip::Tangent, |(rows, jacobian)| Slip::Rows { rows, jacobian }),
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
