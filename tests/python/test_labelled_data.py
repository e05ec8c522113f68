"""Data out, labelled: a run and an ensemble as xarray Datasets named from the model and carrying
how they were computed, a table as a pandas DataFrame, and the HDF5 file's names and units."""

from __future__ import annotations

import numpy as np
import pytest

import varmech
from varmech.events import crossing
from varmech.table import Table

xarray = pytest.importorskip("xarray")


def test_a_runs_dataset_is_its_arrays_named_from_the_model_with_how_it_was_run():
    scene = varmech.scenes.double_pendulum()
    traj = varmech.integrate(scene, dt=0.01, steps=200, save_every=20, method="galerkin4")
    data = traj.to_xarray()
    assert data.coordinate.values.tolist() == ["theta1", "theta2"]
    for name in ("q", "p", "v"):
        assert np.array_equal(data[name].values, getattr(traj, name))
    assert np.array_equal(data.time.values, traj.t) and np.array_equal(data.newton.values, traj.newton)
    assert data.attrs == {
        "method": "galerkin4", "dt": 0.01, "model": repr(traj.model), "varmech_version": varmech.__version__,
        "steps": 200, "nfev": traj.nfev, "status": 0, "message": traj.message,
    }  # fmt: skip
    assert data.p.attrs["names"] == ["p_theta1", "p_theta2"]
    # A catalogue scene is dimensionless; each variable says what it is.
    assert {data[v].attrs["units"] for v in ("time", "q", "p", "v")} == {"1"}
    assert data.q.attrs["long_name"] == "generalized coordinates q" and data.newton.attrs["units"] == "1"
    # The attributes survive a serialisation round trip.
    assert xarray.Dataset.from_dict(data.to_dict()).identical(data)


def test_ones_own_model_is_named_by_its_symbols_and_states_no_units_it_was_not_given():
    sp = pytest.importorskip("sympy")
    x, w, t = sp.symbols("x w t")
    forced = varmech.symbolic.lagrangian(w**2 / 2 - x**2 / 2 + x * sp.cos(t), [x], [w], t=t)
    traj = varmech.integrate(forced, [1.0], v0=[0.0], dt=0.01, steps=100, save_every=50)
    data = traj.to_xarray()
    assert data.coordinate.values.tolist() == ["x"] and data.p.attrs["names"] == ["p_x"]
    assert "units" not in data.q.attrs and "units" not in data.time.attrs
    # The balance's work is there, by time, labelled.
    assert np.array_equal(data.work.values, traj.work) and data.work.dims == ("time",)
    assert data.work.attrs["long_name"].startswith("energy put in")


def test_an_ensembles_dataset_carries_the_runs_attributes_and_names():
    q0 = np.array([[0.5, 0.0], [0.6, 0.0]])
    p0 = np.array([[0.0, 1.5], [0.0, 1.4]])
    runs = varmech.ensemble(varmech.scenes.kepler(), q0, p0, dt=0.01, steps=200, save_every=50, method="verlet", progress=False)
    data = runs.to_xarray()
    assert data.coordinate.values.tolist() == ["x", "y"]
    assert (data.attrs["method"], data.attrs["dt"], data.attrs["members"]) == ("verlet", 0.01, 2)
    assert data.attrs["varmech_version"] == varmech.__version__
    assert np.array_equal(data.q.values, runs.q) and data.q.attrs["units"] == "1"
    assert np.array_equal(data.q.sel(member=1).values, runs[1].to_xarray().q.values)


def test_a_tables_frame_has_its_rows_and_says_what_was_measured_and_how():
    pytest.importorskip("pandas")
    table = varmech.work_precision(varmech.scenes.harmonic_oscillator(), ["verlet", "rk4"], steps=[64, 128],
                                   baselines=(), rebound=(), repeat=1)  # fmt: skip
    frame = table.to_pandas()
    assert list(frame.columns) == list(table.columns) and len(frame) == len(table)
    assert frame.attrs["title"] == table.title and frame.attrs["scene"] == table.meta["scene"]
    back = Table(tuple(frame.columns), [tuple(row) for row in frame.itertuples(index=False)], frame.attrs["title"])
    assert back.rows == table.rows
    # The frame's attributes are a copy: changing them leaves the table as it was.
    frame.attrs["notes"] = ["mine"]
    assert table.meta.get("notes", []) != ["mine"]


def test_the_files_datasets_carry_their_names_and_units(tmp_path):
    h5py = pytest.importorskip("h5py")
    scene = varmech.scenes.get("outer_solar_system")
    path = tmp_path / "planets.h5"
    event = crossing(1, 0.0)
    varmech.integrate(scene, dt=10.0, steps=2000, save_every=100, output=path, events=[event])
    with h5py.File(path, "r") as f:
        assert (f["t"].attrs["units"], f["q"].attrs["units"], f["p"].attrs["units"]) == ("days", "AU", "solar masses AU/day")
        assert f["t"].attrs["long_name"] == "time" and "newton" not in f   # an explicit method's
        assert list(f["q"].attrs["names"]) == list(scene.model.coordinates)
        # Each event's crossings are labelled as the run's.
        assert f["events/0/q"].attrs["units"] == "AU" and f["events/0/t"].attrs["units"] == "days"
    # The file's run is the in-memory run's, labels and all.
    loaded = varmech.load(path)
    assert loaded.to_xarray().q.attrs == varmech.integrate(scene, dt=10.0, steps=0).to_xarray().q.attrs
