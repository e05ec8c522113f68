//! The saved states of a run, as Python reads them.

use numpy::{PyArray1, PyArray2, PyUntypedArrayMethods};

use pyo3::prelude::*;
use varmech::integrators::Trajectory;

use crate::convert::matrix;

/// The saved states of a run (or of a failed run, up to the failure): times `t` (N,), positions
/// `q` and momenta `p` (N, n), the steps completed and force evaluations made, and at each
/// saved state the cumulative Newton iterations `newton` and work of the non-conservative
/// forces `work` (N,).
#[pyclass(frozen, get_all, module = "varmech._core")]
pub struct TrajectoryRecord {
    t: Py<PyArray1<f64>>,
    q: Py<PyArray2<f64>>,
    p: Py<PyArray2<f64>>,
    steps: usize,
    force_evaluations: u64,
    newton: Py<PyArray1<u64>>,
    work: Py<PyArray1<f64>>,
}

impl TrajectoryRecord {
    pub fn new(py: Python<'_>, traj: Trajectory) -> PyResult<Self> {
        let n = traj.dim;
        Ok(TrajectoryRecord {
            t: PyArray1::from_vec(py, traj.t).unbind(),
            q: matrix(py, traj.q, n)?.unbind(),
            p: matrix(py, traj.p, n)?.unbind(),
            steps: traj.steps,
            force_evaluations: traj.force_evaluations,
            newton: PyArray1::from_vec(py, traj.newton).unbind(),
            work: PyArray1::from_vec(py, traj.work).unbind(),
        })
    }
}

#[pymethods]
impl TrajectoryRecord {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "TrajectoryRecord(states={}, steps={})",
            self.t.bind(py).len(),
            self.steps
        )
    }
}
