"""Trajectories in HDF5 files: save and load give back the same bits and metadata, and bad paths
and bad files raise ValueErrors naming the argument."""

import h5py
import numpy as np
import pytest

import varmech


def _same(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.mark.parametrize(
    ("scene", "method", "newton", "work"),
    [
        (varmech.scenes.kepler(0.3), "kahan_li8", False, False),
        (varmech.scenes.double_pendulum(), "midpoint", True, False),
        (varmech.scenes.damped_driven_pendulum(), "midpoint", True, True),
        (varmech.scenes.cartesian_pendulum(), "rattle", True, False),
    ],
    ids=["kepler", "double_pendulum", "damped_driven_pendulum", "cartesian_pendulum"],
)
def test_a_saved_trajectory_loads_bit_for_bit_and_integrates_on_alike(tmp_path, scene, method, newton, work):
    traj = varmech.integrate(scene, dt=scene.dt, steps=200, save_every=20, method=method)
    path = traj.save(tmp_path / "run.h5")
    back = varmech.load(path)
    for name in ("t", "q", "p"):
        assert _same(getattr(back, name), getattr(traj, name)), name
    assert (back.method, back.dt, back.steps, back.nfev, back.status, back.message) == (
        traj.method,
        traj.dt,
        traj.steps,
        traj.nfev,
        traj.status,
        traj.message,
    )
    np.testing.assert_array_equal(back.newton_iterations_per_step, traj.newton_iterations_per_step)
    np.testing.assert_array_equal(back.energy(), traj.energy())
    with h5py.File(path) as f:
        # Only what the run has is stored.
        assert ("newton" in f, "work" in f) == (newton, work)
        assert f.attrs["format"] == "varmech-trajectory" and f["q"].shape == traj.q.shape
    if work:
        assert _same(back.work, traj.work)
    # The model comes back as what builds it: the same run again, to the bit.
    again = varmech.integrate(back.model, scene.q0, scene.p0, dt=scene.dt, steps=200, save_every=20, method=method)
    assert _same(again.q, traj.q) and _same(again.p, traj.p)


def test_an_existing_file_needs_overwrite_and_a_bad_path_is_named(tmp_path):
    s = varmech.scenes.harmonic_oscillator()
    traj = varmech.integrate(s, dt=0.1, steps=10)
    path = traj.save(tmp_path / "a.h5")
    with pytest.raises(ValueError, match="^path: .* exists; pass overwrite=True"):
        traj.save(path)
    traj.save(path, overwrite=True)
    with pytest.raises(ValueError, match="^path: .*is a directory"):
        traj.save(tmp_path, overwrite=True)
    with pytest.raises(ValueError, match="^path: cannot write"):
        traj.save(tmp_path / "missing" / "a.h5")


def test_corrupt_truncated_and_foreign_files_raise_clear_errors(tmp_path):
    s = varmech.scenes.kepler()
    traj = varmech.integrate(s, dt=s.dt, steps=100)
    good = traj.save(tmp_path / "good.h5").read_bytes()
    (tmp_path / "truncated.h5").write_bytes(good[: len(good) // 2])
    (tmp_path / "noise.h5").write_bytes(np.random.default_rng(0).bytes(4096))
    with h5py.File(tmp_path / "foreign.h5", "w") as f:
        f["x"] = np.arange(3)
    for name, message in [
        ("truncated.h5", "corrupt or truncated"),
        ("noise.h5", "corrupt or truncated"),
        ("foreign.h5", "not a varmech trajectory file"),
        ("absent.h5", "no file"),
    ]:
        with pytest.raises(ValueError, match=f"^path: .*{message}"):
            varmech.load(tmp_path / name)


def test_a_model_of_another_dimension_is_refused_and_a_given_one_is_used(tmp_path):
    s = varmech.scenes.kepler()
    path = varmech.integrate(s, dt=s.dt, steps=10).save(tmp_path / "k.h5")
    with pytest.raises(ValueError, match="^model: has dimension 1"):
        varmech.load(path, model=varmech.scenes.harmonic_oscillator().model)
    other = varmech.scenes.kepler(0.3).model
    assert varmech.load(path, model=other).model is other
