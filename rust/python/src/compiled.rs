//! Compiled models: the symbolic front end's tapes, evaluated in the core with the GIL
//! released.

use std::collections::HashMap;

use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use varmech::integrators::{Dynamics, General};
use varmech::model::compiled::{
    CompiledConstraints, CompiledLagrangian, CompiledModel as Compiled, CompiledSeparable, CompiledVelocityConstraints,
    Function, Tape,
};
use varmech::model::{delayed_slots, Constrained, HolonomicConstraints, Mixed, Nonholonomic, VelocityConstraints};

use crate::closure::readers::check_total;
use crate::convert::slice;
use crate::errors::to_pyerr;
use crate::generator::{self, Generator as Spec};

/// One tape as the binding takes it: rows (code, a, b), constants, output registers.
type Encoded<'py> = (
    PyReadonlyArray2<'py, i64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, i64>,
);

/// A model whose functions are instruction tapes ([`varmech::model::compiled`]), made by
/// `varmech.symbolic`; every evaluation runs in the core.
#[pyclass(frozen, module = "varmech._core")]
pub struct CompiledModel {
    pub model: Compiled,
    /// Whether the tapes run as machine code.
    jit: bool,
}

impl CompiledModel {
    /// Runs `body` with the model as the core's [`Dynamics`].
    pub fn with_integrable<R>(&self, body: impl FnOnce(&dyn Dynamics) -> R) -> R {
        match &self.model {
            Compiled::Separable(s) => body(s),
            Compiled::Lagrangian(l) => body(&General(l)),
            Compiled::ConstrainedSeparable(c) => body(c),
            Compiled::ConstrainedLagrangian(c) => body(&Constrained {
                system: General(&c.system),
                constraints: c.constraints.clone(),
            }),
            Compiled::NonholonomicSeparable(c) => body(c),
            Compiled::NonholonomicLagrangian(c) => body(c),
            Compiled::MixedSeparable(c) => body(c),
            Compiled::MixedLagrangian(c) => body(c),
        }
    }
}

/// The named function of `functions`, decoded as a function of `slots` input slots, and compiled
/// to machine code when `jit` holds.
fn function(
    py: Python<'_>,
    functions: &HashMap<String, Encoded<'_>>,
    name: &'static str,
    slots: usize,
    params: usize,
    jit: bool,
) -> PyResult<Option<Function>> {
    let Some((ops, constants, outputs)) = functions.get(name) else {
        return Ok(None);
    };
    if ops.shape()[1] != 3 {
        return Err(PyValueError::new_err(format!(
            "{name}: ops must have shape (k, 3), got {:?}",
            ops.shape()
        )));
    }
    let flat = ops
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: ops must be a C-contiguous int64 array")))?;
    let rows: Vec<[i64; 3]> = flat.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect();
    let outputs = outputs
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: outputs must be a contiguous int64 array")))?;
    let tape =
        Tape::decode(name, &rows, slice(name, constants)?, outputs, slots, params).map_err(|e| to_pyerr(py, e))?;
    Ok(Some(if jit {
        Function::compiled(tape)
    } else {
        Function::new(tape)
    }))
}

fn required(name: &'static str, f: Option<Function>) -> PyResult<Function> {
    f.ok_or_else(|| PyValueError::new_err(format!("functions: the model needs a {name:?} function")))
}

/// The constructors of [`Compiled`]'s variants over one system type `S`: unconstrained, on
/// holonomic constraints, on velocity constraints, on both.
type Variants<S> = (
    fn(S) -> Compiled,
    fn(Constrained<S, CompiledConstraints>) -> Compiled,
    fn(Nonholonomic<S, CompiledVelocityConstraints>) -> Compiled,
    fn(Mixed<S, CompiledConstraints, CompiledVelocityConstraints>) -> Compiled,
);

const SEPARABLE: Variants<CompiledSeparable> = (
    Compiled::Separable,
    Compiled::ConstrainedSeparable,
    Compiled::NonholonomicSeparable,
    Compiled::MixedSeparable,
);

const LAGRANGIAN: Variants<CompiledLagrangian> = (
    Compiled::Lagrangian,
    Compiled::ConstrainedLagrangian,
    Compiled::NonholonomicLagrangian,
    Compiled::MixedLagrangian,
);

/// `system` on the constraints given, as the variant of `variants` that holds them.
fn on_constraints<S>(
    system: S,
    holonomic: Option<CompiledConstraints>,
    velocity: Option<CompiledVelocityConstraints>,
    (plain, constrained, nonholonomic, mixed): Variants<S>,
) -> Compiled {
    match (holonomic, velocity) {
        (Some(holonomic), Some(velocity)) => mixed(Mixed {
            system,
            holonomic,
            velocity,
        }),
        (Some(constraints), None) => constrained(Constrained { system, constraints }),
        (None, Some(constraints)) => nonholonomic(Nonholonomic { system, constraints }),
        (None, None) => plain(system),
    }
}

#[pymethods]
impl CompiledModel {
    #[new]
    #[pyo3(signature = (kind, dim, functions, parameters, *, constraints=0, velocity_constraints=0, time_dependent=false, forced=false, symmetries=Vec::new(), jit=true, delays=Vec::new()))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        kind: &str,
        dim: usize,
        functions: HashMap<String, Encoded<'_>>,
        parameters: PyReadonlyArray1<'_, f64>,
        constraints: usize,
        velocity_constraints: usize,
        time_dependent: bool,
        forced: bool,
        symmetries: Vec<Spec>,
        jit: bool,
        delays: Vec<f64>,
    ) -> PyResult<Self> {
        generator::generators(symmetries, dim)?;
        let known: &[&str] = match kind {
            "separable" => &[
                "potential",
                "gradient",
                "mass",
                "constraints",
                "constraint_jacobian",
                "velocity_constraints",
                "velocity_constraint_derivative",
            ],
            _ => &[
                "lagrangian",
                "gradients",
                "hessians",
                "force",
                "dl_dt",
                "masses",
                "delayed_force",
                "history",
                "constraints",
                "constraint_jacobian",
                "velocity_constraints",
                "velocity_constraint_derivative",
            ],
        };
        if let Some(name) = functions.keys().find(|name| !known.contains(&name.as_str())) {
            return Err(PyValueError::new_err(format!(
                "functions: {name:?} is not a function of a {kind:?} model (it has {})",
                known.join(", ")
            )));
        }
        let params = slice("parameters", &parameters)?.to_vec();
        let k = params.len();
        let compiled = std::cell::Cell::new(false);
        let f = |name| {
            let function = function(py, &functions, name, 2 * dim + 1, k, jit)?;
            compiled.set(compiled.get() || function.as_ref().is_some_and(Function::is_compiled));
            Ok::<_, PyErr>(function)
        };
        let err = |e| to_pyerr(py, e);
        let force = f("force")?;
        if forced != force.is_some() {
            return Err(PyValueError::new_err(
                "forced: must be true exactly when a \"force\" function is given",
            ));
        }
        // The two functions, named `[value, derivative]`, of `count` constraints; None where `count` is 0.
        let pair = |count: usize, [value, derivative]: [&'static str; 2]| match count {
            0 => Ok(None),
            m => PyResult::Ok(Some((
                m,
                required(value, f(value)?)?,
                required(derivative, f(derivative)?)?,
            ))),
        };
        let constraint_functions = pair(constraints, ["constraints", "constraint_jacobian"])?
            .map(|(m, g, jacobian)| CompiledConstraints::new(m, dim, params.clone(), g, jacobian))
            .transpose()
            .map_err(err)?;
        if constraints > 0 && velocity_constraints > 0 {
            check_total("velocity_constraints", constraints, velocity_constraints, dim)?;
        }
        let rolling = pair(
            velocity_constraints,
            ["velocity_constraints", "velocity_constraint_derivative"],
        )?
        .map(|(m, a, derivative)| CompiledVelocityConstraints::new(m, dim, params.clone(), a, derivative))
        .transpose()
        .map_err(err)?;
        let model = match kind {
            "separable" => {
                if time_dependent || forced || !delays.is_empty() {
                    return Err(PyValueError::new_err(
                        "kind: a separable model depends neither on t nor on a force or a delay",
                    ));
                }
                let s = CompiledSeparable::new(
                    dim,
                    params,
                    required("potential", f("potential")?)?,
                    required("gradient", f("gradient")?)?,
                    required("mass", f("mass")?)?,
                )
                .map_err(err)?;
                on_constraints(s, constraint_functions, rolling, SEPARABLE)
            }
            "lagrangian" => {
                let l = CompiledLagrangian::new(
                    dim,
                    params,
                    required("lagrangian", f("lagrangian")?)?,
                    required("gradients", f("gradients")?)?,
                    required("hessians", f("hessians")?)?,
                    force,
                    (f("dl_dt")?, time_dependent),
                    f("masses")?,
                    (
                        match delays.len() {
                            0 => None,
                            d => {
                                // Its slots: [q, q(t − τ₁) …], [q̇ …], [q̈ …], (1 + d)n each, then t.
                                let slots = delayed_slots(dim, d);
                                let f = function(py, &functions, "delayed_force", slots, k, jit)?;
                                Some((required("delayed_force", f)?, delays))
                            }
                        },
                        // The state before the run, a function of the one slot [s].
                        function(py, &functions, "history", 1, k, jit)?,
                    ),
                )
                .map_err(err)?;
                on_constraints(l, constraint_functions, rolling, LAGRANGIAN)
            }
            other => {
                return Err(PyValueError::new_err(format!(
                    "kind: must be \"separable\" or \"lagrangian\", got {other:?}"
                )));
            }
        };
        Ok(CompiledModel {
            model,
            jit: compiled.get(),
        })
    }

    #[getter]
    pub fn dim(&self) -> usize {
        self.with_integrable(|sys| sys.dim())
    }

    /// Number of holonomic constraints (0 for unconstrained models).
    #[getter]
    fn constraints(&self) -> usize {
        match &self.model {
            Compiled::ConstrainedSeparable(c) => c.constraints.count(),
            Compiled::ConstrainedLagrangian(c) => c.constraints.count(),
            Compiled::MixedSeparable(c) => c.holonomic.count(),
            Compiled::MixedLagrangian(c) => c.holonomic.count(),
            _ => 0,
        }
    }

    /// Number of velocity constraints A(q)q̇ = 0 (0 for holonomic or unconstrained models).
    #[getter]
    fn velocity_constraints(&self) -> usize {
        match &self.model {
            Compiled::NonholonomicSeparable(c) => c.constraints.count(),
            Compiled::NonholonomicLagrangian(c) => c.constraints.count(),
            Compiled::MixedSeparable(c) => c.velocity.count(),
            Compiled::MixedLagrangian(c) => c.velocity.count(),
            _ => 0,
        }
    }

    /// The parameter vector.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.model.parameters())
    }

    /// Whether the tapes run as machine code (else the interpreter runs them).
    #[getter]
    fn jit(&self) -> bool {
        self.jit
    }

    /// The same model with another parameter vector; the tapes are shared.
    fn with_parameters(&self, py: Python<'_>, values: PyReadonlyArray1<'_, f64>) -> PyResult<Self> {
        let model = self
            .model
            .with_parameters(slice("values", &values)?)
            .map_err(|e| to_pyerr(py, e))?;
        Ok(CompiledModel { model, jit: self.jit })
    }

    fn __repr__(&self) -> String {
        format!("CompiledModel(dim={})", self.dim())
    }
}

/// The names of the tape's ops by code.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CompiledModel>()?;
    m.add("TAPE_OPS", Tape::OPS.to_vec())?;
    Ok(())
}
