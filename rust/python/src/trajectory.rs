//! The saved states of a run, as Python reads them.

use numpy::{PyArray1, PyArray2, PyUntypedArrayMethods};

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use varmech::integrators::{Impacts, Occurrence, Switch, Switches, Trajectory};

use crate::convert::matrix;

/// The saved states of a run (or of a failed run, up to the failure): times `t` (N,), positions
/// `q` and momenta `p` (N, n), the steps completed and force evaluations made, and at each
/// saved state the cumulative Newton iterations `newton` and work of the non-conservative
/// forces `work` (N,). A run without Newton iterations or forces stores neither; the getters
/// then return zeros, made when asked for. `checkpoint` is the last state's, as bytes, for
/// `resume`.
#[pyclass(frozen, module = "varmech._core")]
pub struct TrajectoryRecord {
    #[pyo3(get)]
    t: Py<PyArray1<f64>>,
    #[pyo3(get)]
    q: Py<PyArray2<f64>>,
    #[pyo3(get)]
    p: Py<PyArray2<f64>>,
    #[pyo3(get)]
    steps: usize,
    #[pyo3(get)]
    force_evaluations: u64,
    newton: Option<Py<PyArray1<u64>>>,
    work: Option<Py<PyArray1<f64>>>,
    #[pyo3(get)]
    checkpoint: Py<PyBytes>,
    /// The located event crossings in order of time: the event's index (k,), t (k,), q and p
    /// (k, n), and the state (q, p) at the start of each one's step (k, n).
    #[pyo3(get)]
    events: EventArrays,
    /// The index of the event whose terminal count stopped the run, if one did.
    #[pyo3(get)]
    terminated_by: Option<usize>,
    /// The impacts on the run's contacts in order of time: the contact's index (k,), t (k,),
    /// the contact configuration q and the momenta just before and just after (k, n).
    #[pyo3(get)]
    impacts: ImpactArrays,
    /// The contacts' switches in order of time: the contact's index (k,), t (k,), the kind (k,:
    /// 0 closed, 1 released, 2 stuck, 3 slipped), q and p (k, n).
    #[pyo3(get)]
    switches: SwitchArrays,
    /// Impacts under the variational law that took Newton's law for want of a discrete-energy
    /// root near the reflection (grazing).
    #[pyo3(get)]
    grazing: usize,
}

/// Impacts as arrays: the contact's index (k,), t (k,), q, p before and p after (k, n).
pub(crate) type ImpactArrays = (
    Py<PyArray1<usize>>,
    Py<PyArray1<f64>>,
    Py<PyArray2<f64>>,
    Py<PyArray2<f64>>,
    Py<PyArray2<f64>>,
);

/// Switches as arrays: the contact's index (k,), t (k,), the kind's code (k,: [`switch_code`]),
/// q and p (k, n).
pub(crate) type SwitchArrays = (
    Py<PyArray1<usize>>,
    Py<PyArray1<f64>>,
    Py<PyArray1<u8>>,
    Py<PyArray2<f64>>,
    Py<PyArray2<f64>>,
);

/// A switch's code, as Python's `impacts.SWITCHES` spells them.
fn switch_code(kind: Switch) -> u8 {
    match kind {
        Switch::Closed => 0,
        Switch::Released => 1,
        Switch::Stuck => 2,
        Switch::Slipped => 3,
    }
}

/// The arrays of `switches` (a run's, or a stepper's so far) of n coordinates.
pub(crate) fn switch_arrays(py: Python<'_>, switches: Switches, n: usize) -> PyResult<SwitchArrays> {
    Ok((
        PyArray1::from_vec(py, switches.contact).unbind(),
        PyArray1::from_vec(py, switches.t).unbind(),
        PyArray1::from_iter(py, switches.kind.into_iter().map(switch_code)).unbind(),
        matrix(py, switches.q, n)?.unbind(),
        matrix(py, switches.p, n)?.unbind(),
    ))
}

/// Event crossings as arrays: the event's index (k,), t (k,), q and p (k, n), and the start of
/// each one's step, q and p (k, n).
pub(crate) type EventArrays = (
    Py<PyArray1<usize>>,
    Py<PyArray1<f64>>,
    Py<PyArray2<f64>>,
    Py<PyArray2<f64>>,
    Py<PyArray2<f64>>,
    Py<PyArray2<f64>>,
);

/// The arrays of `impacts` (a run's, or a stepper's so far) of n coordinates.
pub(crate) fn impact_arrays(py: Python<'_>, impacts: Impacts, n: usize) -> PyResult<ImpactArrays> {
    Ok((
        PyArray1::from_vec(py, impacts.contact).unbind(),
        PyArray1::from_vec(py, impacts.t).unbind(),
        matrix(py, impacts.q, n)?.unbind(),
        matrix(py, impacts.p_before, n)?.unbind(),
        matrix(py, impacts.p_after, n)?.unbind(),
    ))
}

/// The arrays of event crossings (a run's, or a stepper's so far) of n coordinates.
pub(crate) fn event_arrays(py: Python<'_>, events: &[Occurrence], n: usize) -> PyResult<EventArrays> {
    let (mut index, mut t, mut q, mut p) = (vec![], vec![], vec![], vec![]);
    let (mut q_start, mut p_start) = (vec![], vec![]);
    for e in events {
        index.push(e.event);
        t.push(e.t);
        q.extend_from_slice(&e.q);
        p.extend_from_slice(&e.p);
        q_start.extend_from_slice(&e.q_start);
        p_start.extend_from_slice(&e.p_start);
    }
    Ok((
        PyArray1::from_vec(py, index).unbind(),
        PyArray1::from_vec(py, t).unbind(),
        matrix(py, q, n)?.unbind(),
        matrix(py, p, n)?.unbind(),
        matrix(py, q_start, n)?.unbind(),
        matrix(py, p_start, n)?.unbind(),
    ))
}

/// The recorded column, or None when the run recorded none (an empty vector).
fn recorded<'py, T: numpy::Element>(py: Python<'py>, column: Vec<T>) -> Option<Py<PyArray1<T>>> {
    (!column.is_empty()).then(|| PyArray1::from_vec(py, column).unbind())
}

impl TrajectoryRecord {
    pub fn new(py: Python<'_>, mut traj: Trajectory) -> PyResult<Self> {
        let n = traj.dim;
        let events = event_arrays(py, &traj.events, n)?;
        let grazing = traj.impacts.grazing;
        let switches = switch_arrays(py, std::mem::take(&mut traj.impacts.switches), n)?;
        let impacts = impact_arrays(py, traj.impacts, n)?;
        Ok(TrajectoryRecord {
            t: PyArray1::from_vec(py, traj.t).unbind(),
            q: matrix(py, traj.q, n)?.unbind(),
            p: matrix(py, traj.p, n)?.unbind(),
            steps: traj.steps,
            force_evaluations: traj.force_evaluations,
            newton: recorded(py, traj.newton),
            work: recorded(py, traj.work),
            checkpoint: PyBytes::new(py, &traj.checkpoint).unbind(),
            events,
            terminated_by: traj.terminated_by,
            impacts,
            switches,
            grazing,
        })
    }

    /// The column, or zeros of the length of `t`.
    fn column<'py, T: numpy::Element>(
        &self,
        py: Python<'py>,
        column: &Option<Py<PyArray1<T>>>,
    ) -> Bound<'py, PyArray1<T>> {
        match column {
            Some(c) => c.bind(py).clone(),
            None => PyArray1::zeros(py, self.t.bind(py).len(), false),
        }
    }
}

#[pymethods]
impl TrajectoryRecord {
    /// Cumulative Newton iterations at each saved state (zeros for the explicit methods).
    #[getter]
    fn newton<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        self.column(py, &self.newton)
    }

    /// Cumulative work of the non-conservative forces at each saved state (zeros without forces).
    #[getter]
    fn work<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.column(py, &self.work)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "TrajectoryRecord(states={}, steps={})",
            self.t.bind(py).len(),
            self.steps
        )
    }
}
