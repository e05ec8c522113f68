//! Diagnostics of saved states: the energy function, first derivatives of L, Noether momenta,
//! and statistics of conserved quantities.

use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use varmech::diagnostics::{self, LyapunovOptions, Series, Stretching, Verdict};
use varmech::integrators::Method;
use varmech::model::{self, EnergyTerms, Scale};
use varmech::ModelError;

use crate::bind::{bind_model, dim_of};
use crate::convert::{self, rows, slice, states, ArrayPair};
use crate::errors::{model_error, model_error_at, to_pyerr};
use crate::generator::{checked, Generator};
use crate::run::steps_count;

/// Three arrays: the energy and its two terms.
type EnergyArrays<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The energy function E = p·q̇ − L (= ½pᵀM⁻¹p + V for mechanical systems) at each state, with
/// its kinetic and potential terms T and V: (E, T, V).
#[pyfunction]
fn energy_terms<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<EnergyArrays<'py>> {
    let n = dim_of(py, model)?;
    let (t, q, p) = states(n, &t, &q, &p)?;
    let result: Result<Vec<EnergyTerms>, ModelError> = bind_model(py, model, |sys, _poll| {
        let l = sys.as_lagrangian();
        t.iter()
            .zip(q.chunks_exact(n).zip(p.chunks_exact(n)))
            .map(|(t, (q, p))| l.energy_terms(q, p, *t))
            .collect()
    })?;
    let terms = result.map_err(model_error)?;
    let column = |f: fn(&EnergyTerms) -> f64| PyArray1::from_vec(py, terms.iter().map(f).collect());
    Ok((column(|e| e.energy), column(|e| e.kinetic), column(|e| e.potential)))
}

/// A first derivative of L at each state (t, q, x): `"momentum"`, p = ∂L/∂q̇(q, x, t) from
/// velocities x (Mq̇ for mechanical systems); `"velocity"`, the inverse Legendre transform,
/// q̇ with ∂L/∂q̇ = x from momenta x (M⁻¹p); `"dl_dq"`, ∂L/∂q(q, x, t) from velocities x;
/// `"dp_dt"`, ṗ = ∂L/∂q + f(q, x, t) from velocities x. With `names` (the user's arguments the
/// states come from), the core's own errors name them.
#[pyfunction]
#[pyo3(signature = (model, what, t, q, x, *, names=None))]
fn derivative<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    what: &str,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    x: PyReadonlyArray2<'py, f64>,
    names: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    if !matches!(what, "momentum" | "velocity" | "dl_dq" | "dp_dt") {
        return Err(PyValueError::new_err(format!(
            "what: expected \"momentum\", \"velocity\", \"dl_dq\" or \"dp_dt\", got {what:?}"
        )));
    }
    let n = dim_of(py, model)?;
    let (t, q, x) = states(n, &t, &q, &x)?;
    let result: Result<Vec<f64>, ModelError> = bind_model(py, model, |sys, _poll| {
        let l = sys.as_lagrangian();
        let mut y = vec![0.0; x.len()];
        let mut rows = t
            .iter()
            .zip(q.chunks_exact(n).zip(x.chunks_exact(n)))
            .zip(y.chunks_exact_mut(n));
        rows.try_for_each(|((t, (q, x)), y)| match what {
            "velocity" => l.velocity(q, x, *t, y),
            "momentum" => l.dl_dv(q, x, *t, y),
            "dl_dq" => l.dl_dq(q, x, *t, y),
            // ṗ = ∂L/∂q + f along the (forced) Euler–Lagrange flow.
            _ => {
                l.dl_dq(q, x, *t, y)?;
                let mut f = vec![0.0; n];
                l.force(q, x, *t, &mut f)?;
                y.iter_mut().zip(&f).for_each(|(y, f)| *y += f);
                Ok(())
            }
        })
        .map(|()| y)
    })?;
    let result = result.map_err(|e| match names {
        Some(names) => model_error_at(e, names),
        None => model_error(e),
    });
    Ok(convert::matrix(py, result?, n)?.into_any())
}

/// J = p·ξ(q) of a generator for each row of (q, p), and the size Σ|pᵢξᵢ| of its terms; a
/// generator that does not apply to the rows' n coordinates is a ValueError naming `argument`.
#[pyfunction]
#[pyo3(signature = (generator, q, p, *, argument="generator"))]
fn momentum<'py>(
    py: Python<'py>,
    generator: Generator,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
    argument: &str,
) -> PyResult<ArrayPair<'py>> {
    let ((q, n), (p, _)) = (rows("q", &q)?, rows("p", &p)?);
    let g = checked(generator, n, argument)?;
    let (j, size): (Vec<f64>, Vec<f64>) = q
        .chunks_exact(n.max(1))
        .zip(p.chunks_exact(n.max(1)))
        .map(|(q, p)| g.momentum_terms(q, p))
        .unzip();
    Ok((PyArray1::from_vec(py, j), PyArray1::from_vec(py, size)))
}

/// J = p·ξ for each row of (ξ, p), a field ξ(q) evaluated at the states, and its size.
#[pyfunction]
fn momentum_along<'py>(
    py: Python<'py>,
    xi: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
) -> PyResult<ArrayPair<'py>> {
    let ((xi, n), (p, _)) = (rows("xi", &xi)?, rows("p", &p)?);
    let (j, size): (Vec<f64>, Vec<f64>) = xi
        .chunks_exact(n.max(1))
        .zip(p.chunks_exact(n.max(1)))
        .map(|(xi, p)| model::momentum_along(xi, p))
        .unzip();
    Ok((PyArray1::from_vec(py, j), PyArray1::from_vec(py, size)))
}

/// The error of a conserved quantity against its scale, and its verdict (the core's
/// `Statistics`).
#[pyclass(frozen, get_all, module = "varmech._core")]
pub struct Statistics {
    scale: f64,
    judged_scale: f64,
    round_off: f64,
    max_abs_error: f64,
    max_rel_error: f64,
    band: f64,
    drift_rate: f64,
    drift_rate_stderr: f64,
    oscillations: f64,
    first_non_finite: Option<usize>,
    verdict: &'static str,
}

impl From<diagnostics::Statistics> for Statistics {
    fn from(s: diagnostics::Statistics) -> Self {
        Statistics {
            scale: s.scale,
            judged_scale: s.judged_scale,
            round_off: s.round_off,
            max_abs_error: s.max_abs_error,
            max_rel_error: s.max_rel_error,
            band: s.band,
            drift_rate: s.drift_rate,
            drift_rate_stderr: s.drift_rate_stderr,
            oscillations: s.oscillations,
            first_non_finite: s.first_non_finite,
            verdict: s.verdict.name(),
        }
    }
}

/// The statistics of the energy E (with terms T and V) along a run of `steps` steps, balanced
/// against the work W of its forces.
#[pyfunction]
fn energy_statistics(
    py: Python<'_>,
    t: PyReadonlyArray1<'_, f64>,
    energy: PyReadonlyArray1<'_, f64>,
    kinetic: PyReadonlyArray1<'_, f64>,
    potential: PyReadonlyArray1<'_, f64>,
    work: PyReadonlyArray1<'_, f64>,
    steps: u64,
) -> PyResult<Statistics> {
    let (t, e, k, v) = (
        slice("t", &t)?,
        slice("energy", &energy)?,
        slice("kinetic", &kinetic)?,
        slice("potential", &potential)?,
    );
    if e.len() != k.len() || e.len() != v.len() {
        return Err(PyValueError::new_err(
            "energy, kinetic, potential: need one value each per state",
        ));
    }
    let terms: Vec<EnergyTerms> = e
        .iter()
        .zip(k.iter().zip(v))
        .map(|(&energy, (&kinetic, &potential))| EnergyTerms {
            energy,
            kinetic,
            potential,
        })
        .collect();
    let s = diagnostics::energy_statistics(t, &terms, slice("work", &work)?, steps).map_err(|e| to_pyerr(py, e))?;
    Ok(s.into())
}

/// The statistics of a conserved quantity's `error` series with its `size` (whose mean is the
/// scale) and the size of its `terms`, along a run of `steps` steps.
#[pyfunction]
fn statistics(
    py: Python<'_>,
    t: PyReadonlyArray1<'_, f64>,
    error: PyReadonlyArray1<'_, f64>,
    size: PyReadonlyArray1<'_, f64>,
    terms: PyReadonlyArray1<'_, f64>,
    steps: u64,
) -> PyResult<Statistics> {
    let series = Series {
        t: slice("t", &t)?,
        error: slice("error", &error)?,
        size: slice("size", &size)?,
        terms: slice("terms", &terms)?,
        steps,
    };
    Ok(diagnostics::Statistics::new(&series)
        .map_err(|e| to_pyerr(py, e))?
        .into())
}

/// Frobenius' test of a nonholonomic model's velocity constraints at each row of `q`
/// ([`model::curvature`]): the curvature of ker A(q) relative to ∂A/∂q, round-off where the
/// constraints integrate to holonomic ones. None for a model without velocity constraints.
#[pyfunction]
fn constraint_curvature(
    py: Python<'_>,
    model: &Bound<'_, PyAny>,
    q: PyReadonlyArray2<'_, f64>,
) -> PyResult<Option<Vec<f64>>> {
    let n = dim_of(py, model)?;
    let (q, width) = rows("q", &q)?;
    if width != n {
        return Err(PyValueError::new_err(format!(
            "q: rows of {n} coordinates expected, got {width}"
        )));
    }
    let result: Option<Result<Vec<f64>, ModelError>> = bind_model(py, model, |sys, _poll| {
        let constraints = sys.velocity_constraints()?;
        Some(
            q.chunks_exact(n.max(1))
                .map(|q| model::curvature(constraints, q))
                .collect(),
        )
    })?;
    result.transpose().map_err(model_error)
}

/// The arrays of a Lyapunov run: the times of the re-orthonormalizations, the sums Σ ln Rⱼⱼ
/// there (rows × k), the run's end (q, p) and the tangent map's evaluations.
type StretchingArrays<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<f64>>,
    ArrayPair<'py>,
    u64,
);

/// The stretching of k tangent vectors carried by the step's tangent map along a run, from the
/// columns (δq, δq̇) of `start` (column-major) where given (`varmech.lyapunov_spectrum` turns it
/// into exponents).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (model, method, q0, p0, *, t0, dt, steps, k, every, start=None))]
fn lyapunov<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = convert::method)] method: Method,
    q0: PyReadonlyArray1<'py, f64>,
    p0: PyReadonlyArray1<'py, f64>,
    t0: f64,
    dt: f64,
    #[pyo3(from_py_with = steps_count)] steps: usize,
    k: usize,
    every: usize,
    start: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<StretchingArrays<'py>> {
    let (q0, p0) = (slice("q0", &q0)?, slice("p0", &p0)?);
    let start = start.as_ref().map(|s| slice("start", s)).transpose()?;
    let options = LyapunovOptions {
        t0,
        dt,
        steps,
        k,
        every,
        start,
    };
    let stretching = bind_model(py, model, |sys, poll| {
        diagnostics::lyapunov(sys, method, q0, p0, &options, poll)
    })?
    .map_err(|e| to_pyerr(py, e))?;
    let Stretching {
        k,
        t,
        sums,
        q,
        p,
        evaluations,
    } = stretching;
    let state = (PyArray1::from_vec(py, q), PyArray1::from_vec(py, p));
    Ok((
        PyArray1::from_vec(py, t),
        convert::matrix(py, sums, k)?,
        state,
        evaluations,
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    add_functions!(
        m,
        [
            lyapunov,
            constraint_curvature,
            energy_terms,
            derivative,
            momentum,
            momentum_along,
            energy_statistics,
            statistics
        ]
    );
    m.add_class::<Statistics>()?;
    m.add("VERDICTS", PyTuple::new(m.py(), Verdict::ALL.map(Verdict::name))?)?;
    m.add("FAILURE", Scale::FAILURE)?;
    m.add("TOO_COARSE", diagnostics::Statistics::TOO_COARSE)?;
    m.add("ROUND_OFF", Scale::ROUND_OFF)?;
    Ok(())
}
