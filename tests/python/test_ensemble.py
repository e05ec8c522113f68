"""Ensembles: every member bit for bit its single ``integrate`` run, failures per member,
parameter sweeps, Ctrl-C, and bad input named."""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import varmech
from varmech import scenes


def _same(a, b):
    """Bit for bit: the saved states, the steps, the force evaluations and the checkpoint."""
    return (
        np.array_equal(a.t, b.t)
        and np.array_equal(a.q, b.q)
        and np.array_equal(a.p, b.p)
        and a.steps == b.steps
        and a.nfev == b.nfev
        and a.checkpoint == b.checkpoint
    )


def _double_pendulum_rows(members):
    scene = scenes.double_pendulum()
    rng = np.random.default_rng(19)
    q0 = scene.q0 + 0.1 * rng.standard_normal((members, 2))
    p0 = scene.p0 + 0.1 * rng.standard_normal((members, 2))
    return scene, q0, p0


@pytest.mark.parametrize("workers", [1, 2])
@pytest.mark.parametrize("chunk_size", [1, 7, 64])
def test_every_member_is_bit_for_bit_its_single_integrate(workers, chunk_size):
    scene, q0, p0 = _double_pendulum_rows(20)
    run = dict(dt=0.01, steps=300, method="midpoint", save_every=7)
    runs = varmech.ensemble(scene, q0, p0, workers=workers, chunk_size=chunk_size, progress=False, **run)
    assert runs.q.shape == (20, 300 // 7 + 2, 2) and runs.failed == []
    for i in range(20):
        single = varmech.integrate(scene.model, q0[i], p0[i], **run)
        assert _same(runs[i], single), f"member {i}"
        assert np.array_equal(runs.q[i], single.q) and np.array_equal(runs.p[i], single.p)
    assert np.array_equal(runs.t, runs[0].t)


@pytest.mark.parametrize("workers, chunk_size", [(None, None), (2, None), (2, 1), (3, 2)])
def test_a_closure_model_runs_bit_for_bit_serially_or_in_processes(workers, chunk_size):
    pendulum = varmech.MechanicalSystem(1, potential=lambda q: -np.cos(q[0]), gradient=lambda q: np.sin(q))
    q0 = np.array([[0.1], [1.0], [2.5], [3.0], [-1.0]])
    p0 = np.zeros((5, 1))
    run = dict(dt=0.05, steps=200, method="verlet")
    runs = varmech.ensemble(pendulum, q0, p0, workers=workers, chunk_size=chunk_size, progress=False, **run)
    for i in range(5):
        assert _same(runs[i], varmech.integrate(pendulum, q0[i], p0[i], **run))


class LeftTheChart(Exception):
    """A user's own exception, raised in a closure."""


def _gradient_off_the_chart(q):
    if abs(q[0]) > 2.0:
        raise LeftTheChart(f"left the chart at q = {q[0]}")
    return q.copy()


@pytest.mark.parametrize("workers", [1, 2])
def test_members_watching_events_have_their_single_runs_crossings_and_stops(workers):
    # The built-in crossing runs in the core's parallel loop; a Python event function holds the
    # GIL and runs member by member; either way member i is its single run, crossings included,
    # and a terminal event stops that member alone.
    from varmech.events import Event, crossing

    scene, q0, p0 = _double_pendulum_rows(5)
    q0[4] = [0.01, 0.0]
    p0[4] = [0.0, 0.0]
    run = dict(dt=0.01, steps=2000, method="midpoint", save_every=50)
    lower = Event(lambda t, q, p: q[1] - 0.2, name="lower", terminal=2)
    for events in ([crossing(0, 0.0, direction=1)], [crossing(0, 0.0, direction=1), lower]):
        runs = varmech.ensemble(scene, q0, p0, events=events, workers=workers, progress=False, **run)
        assert runs.failed == []
        for i in range(5):
            single = varmech.integrate(scene.model, q0[i], p0[i], events=events, **run)
            assert _same(runs[i], single), f"member {i}"
            assert runs[i].status == single.status
            for a, b in zip(runs[i].events, single.events):
                assert np.array_equal(a.t, b.t) and np.array_equal(a.q, b.q) and np.array_equal(a.p, b.p)
        if len(events) == 1:
            assert min(len(tr.events[0]) for tr in runs) >= 5, "every member crosses the vertical upward"
        else:
            stopped = [i for i in range(5) if runs[i].status == 1]
            assert 0 < len(stopped) < 5, "the terminal event stops some members, not the small swing"
            assert runs[4].status == 0 and runs[4].steps == 2000


def test_velocities_give_each_members_momenta():
    scene, q0, p0 = _double_pendulum_rows(4)
    v0 = scene.model.velocity(q0, p0)
    runs = varmech.ensemble(scene, q0, v0=v0, dt=0.01, steps=50, method="midpoint", progress=False)
    for i in range(4):
        assert _same(runs[i], varmech.integrate(scene.model, q0[i], v0=v0[i], dt=0.01, steps=50, method="midpoint"))


def test_a_member_past_its_stability_limit_fails_alone_with_its_step_and_partial_trajectory():
    # Verlet is stable on q'' = −ω²q for hω < 2: at h = 0.1, ω = 30 (hω = 3) grows by ≈ 6.85 a
    # step and trips the energy check within a few steps; the others run to the end.
    omegas = np.array([1.0, 30.0, 2.0])
    scene = scenes.harmonic_oscillator()
    run = dict(dt=0.1, steps=200, method="verlet")
    runs = varmech.ensemble(scene, np.zeros((3, 1)), np.ones((3, 1)), parameters={"omega": omegas}, progress=False, **run)
    assert runs.failed == [1]
    assert list(runs.status) == [0, -1, 0]
    error = runs.errors[1]
    assert isinstance(error, varmech.DivergenceError) and 1 <= error.step < 20
    partial = runs[1]
    assert len(partial) == error.step + 1 and np.all(np.isnan(runs.q[1, error.step + 1 :]))
    with pytest.raises(varmech.DivergenceError) as single:
        varmech.integrate(scenes.harmonic_oscillator(30.0), [0.0], [1.0], **run)
    assert _same(partial, single.value.partial)
    for i in (0, 2):
        assert runs[i].steps == 200 and _same(runs[i], varmech.integrate(scenes.harmonic_oscillator(omegas[i]), [0.0], [1.0], **run))
    summary = runs.check_conservation()
    assert summary.not_bounded == [1] and summary.worst_energy_error >= 1.0
    assert summary.reports[0].verdict in ("bounded", "conserved to round-off")


@pytest.mark.parametrize("workers", [None, 2])
def test_a_closure_members_failure_leaves_the_others_complete(workers):
    # The user's exception comes back as itself, with the step, the time and the states so far,
    # also from a worker process.
    oscillator = varmech.MechanicalSystem(1, potential=lambda q: 0.5 * q[0] ** 2, gradient=_gradient_off_the_chart)
    q0, p0 = [[0.5], [1.0], [1.0], [1.5]], [[0.0], [0.0], [2.0], [0.0]]
    run = dict(dt=0.1, steps=100)
    runs = varmech.ensemble(oscillator, q0, p0, workers=workers, chunk_size=1, progress=False, **run)
    assert runs.failed == [2] and type(runs.errors[2]) is LeftTheChart and "left the chart" in str(runs.errors[2])
    assert runs[0].steps == runs[1].steps == runs[3].steps == 100
    with pytest.raises(LeftTheChart) as single:
        varmech.integrate(oscillator, q0[2], p0[2], **run)
    assert runs.errors[2].step == single.value.step > 0
    assert _same(runs[2], single.value.partial)


def _unshippable():
    """An oscillator whose potential holds an object that refuses to be pickled."""

    class Local:
        def __reduce__(self):
            raise TypeError("not picklable")

    local = Local()
    return varmech.MechanicalSystem(1, potential=lambda q: local and 0.5 * q[0] ** 2, gradient=lambda q: q.copy())


def test_a_closure_model_that_cannot_go_to_processes_is_named():
    model = _unshippable()
    with pytest.raises(TypeError, match="^model: .* cannot be shipped to worker processes"):
        varmech.ensemble(model, [[1.0], [2.0]], [[0.0], [0.0]], dt=0.1, steps=10, workers=2, progress=False)
    # Serially it needs no shipping.
    assert varmech.ensemble(model, [[1.0], [2.0]], [[0.0], [0.0]], dt=0.1, steps=10, progress=False).failed == []


def test_ctrl_c_stops_closure_processes_and_keeps_the_chunks_gathered(interrupt_after):
    # Members at q0 = 100 sleep at every evaluation: they cannot finish before the interrupt; the
    # members at rest at 0 finish first and are kept, bit for bit.
    def gradient(q):
        if q[0] > 50.0:
            time.sleep(1e-3)
        return np.zeros(1)

    free = varmech.MechanicalSystem(1, potential=lambda q: 0.0, gradient=gradient)
    q0, p0 = np.array([[0.0], [0.0], [100.0], [100.0]]), np.zeros((4, 1))
    run = dict(dt=0.1, steps=20_000, method="verlet", save_every=1000)
    timer, _ = interrupt_after(3.0)
    with pytest.raises(KeyboardInterrupt) as stopped:
        varmech.ensemble(free, q0, p0, workers=2, chunk_size=1, progress=False, **run)
    timer.join()
    partial = stopped.value.partial
    assert partial.failed == [2, 3] and [len(tr) for tr in partial][2:] == [0, 0]
    for i in (0, 1):
        assert _same(partial[i], varmech.integrate(free, q0[i], p0[i], **run))


def test_a_drive_amplitude_sweep_equals_separate_runs():
    amplitudes = np.array([0.9, 1.07, 1.15, 1.35, 1.45, 1.5])
    scene = scenes.damped_driven_pendulum()
    members = len(amplitudes)
    run = dict(dt=0.05, steps=2000, save_every=10, method="midpoint")
    runs = varmech.ensemble(
        scene, np.zeros((members, 1)), np.zeros((members, 1)), parameters={"amplitude": amplitudes}, workers=2, progress=False, **run
    )
    for i, a in enumerate(amplitudes):
        assert _same(runs[i], varmech.integrate(scenes.damped_driven_pendulum(amplitude=a), [0.0], [0.0], **run))
    # The drive matters: the members end apart.
    final = runs.q[:, -1, 0]
    assert np.min(np.abs(np.subtract.outer(final, final)) + np.eye(members)) > 1e-3
    assert list(runs.parameters["amplitude"]) == list(amplitudes)


def test_a_symbolic_models_parameter_sweep_equals_separate_runs():
    pytest.importorskip("sympy")
    from varmech.symbolic import examples

    scene = examples.scene("elastic_pendulum")
    stiffness = [10.0, 12.5, 40.0]
    q0, p0 = np.tile(scene.q0, (3, 1)), np.tile(scene.p0, (3, 1))
    runs = varmech.ensemble(scene.model, q0, p0, parameters={"k": stiffness}, dt=0.01, steps=500, workers=2, progress=False)
    for i, k in enumerate(stiffness):
        assert _same(runs[i], varmech.integrate(scene.model, scene.q0, scene.p0, dt=0.01, steps=500, parameters={"k": k}))
    assert not np.array_equal(runs.q[0], runs.q[2])


def test_ctrl_c_stops_every_member_and_keeps_what_was_computed(interrupt_after):
    scene, q0, p0 = _double_pendulum_rows(3)
    run = dict(dt=1e-4, save_every=1000, method="midpoint")
    timer, _ = interrupt_after(0.3)
    with pytest.raises(KeyboardInterrupt) as stopped:
        varmech.ensemble(scene, q0, p0, steps=10**9, workers=2, progress=False, **run)
    timer.join()
    partial = stopped.value.partial
    assert len(partial) == 3 and partial.failed == [0, 1, 2]
    started = [tr for tr in partial if len(tr) > 1]
    assert started, "the running members kept their states"
    for i, tr in enumerate(partial):
        if len(tr) > 1:
            # The states so far, the last where the member stopped: a run to that step's.
            single = varmech.integrate(scene.model, q0[i], p0[i], steps=tr.steps, **run)
            assert np.array_equal(tr.q, single.q) and np.array_equal(tr.p, single.p)


@pytest.mark.parametrize(
    "change, argument",
    [
        (dict(q0=np.zeros((4, 3))), "q0"),
        (dict(q0=np.zeros(2)), "q0"),
        (dict(p0=np.zeros((3, 2))), "p0"),
        (dict(parameters={"stiffness": [1.0] * 4}), "parameters"),
        (dict(parameters={"m1": [1.0] * 3}), "parameters"),
        (dict(workers=0), "workers"),
        (dict(workers=-2), "workers"),
        (dict(chunk_size=0), "chunk_size"),
        (dict(steps=10**12, dt=1e-12, q0=np.zeros((10**4, 2)), p0=np.zeros((10**4, 2))), "save_every"),
    ],
)
def test_bad_input_is_a_value_error_naming_the_argument(change, argument):
    scene, q0, p0 = _double_pendulum_rows(4)
    args = dict(model=scene, q0=q0, p0=p0, dt=0.01, steps=10, progress=False) | change
    with pytest.raises(ValueError, match=f"^{argument}"):
        varmech.ensemble(**args)


def test_to_xarray_labels_members_times_and_parameters():
    xarray = pytest.importorskip("xarray")
    runs = varmech.ensemble(
        scenes.harmonic_oscillator(), np.zeros((2, 1)), np.ones((2, 1)), parameters={"omega": [1.0, 2.0]}, dt=0.1, steps=10, progress=False
    )
    data = runs.to_xarray()
    assert isinstance(data, xarray.Dataset) and data["q"].dims == ("member", "time", "coordinate")
    assert list(data["omega"].values) == [1.0, 2.0] and np.array_equal(data["q"].values, runs.q)


@pytest.fixture(scope="module")
def cluster_client():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            yield client


@pytest.mark.parametrize("chunk_size", [None, 7])
def test_a_dask_cluster_gives_every_member_bit_for_bit(cluster_client, chunk_size):
    scene, q0, p0 = _double_pendulum_rows(20)
    run = dict(dt=0.01, steps=300, method="midpoint", save_every=7)
    runs = varmech.ensemble(scene, q0, p0, client=cluster_client, chunk_size=chunk_size, progress=False, **run)
    for i in range(20):
        assert _same(runs[i], varmech.integrate(scene.model, q0[i], p0[i], **run)), f"member {i}"
    swept = varmech.ensemble(
        scenes.harmonic_oscillator(), np.zeros((3, 1)), np.ones((3, 1)), parameters={"omega": [1.0, 30.0, 2.0]},
        dt=0.1, steps=200, method="verlet", client=cluster_client, chunk_size=chunk_size, progress=False,
    )
    assert swept.failed == [1] and isinstance(swept.errors[1], varmech.DivergenceError) and swept.errors[1].step >= 1


def test_a_dask_cluster_runs_struck_and_sampled_bouncing_balls_bit_for_bit(cluster_client):
    # Contacts, impulses and t_eval go to the workers with the settings: every member (the
    # native ball on its floor, struck downwards at t = 0.25 and sampled at 40 times) is its
    # single run, with the same impacts.
    ball = scenes.bouncing_ball()
    q0, p0 = np.linspace(0.5, 1.5, 6)[:, None], np.zeros((6, 1))
    run = dict(
        dt=1e-3, t_end=2.0, method="verlet", impulses=[varmech.Impulse(generalized=[-1.0], t=0.2505)],
        t_eval=np.linspace(0.0, 2.0, 40),
    )
    runs = varmech.ensemble(ball, q0, p0, client=cluster_client, chunk_size=2, progress=False, **run)
    for i in range(6):
        single = varmech.integrate(ball.model, q0[i], p0[i], contacts=ball.contacts, **run)
        assert len(single.events[0]) >= 2
        assert _same(runs[i], single), f"member {i}"
        assert np.array_equal(runs[i].events[0].t, single.events[0].t)


def test_ctrl_c_on_a_cluster_keeps_the_chunks_it_finished(cluster_client, monkeypatch):
    # Ctrl-C arriving as the first chunk is gathered (raised from the progress bar's update): the
    # KeyboardInterrupt carries the ensemble so far, the finished chunk's members bit for bit,
    # the rest marked interrupted with no state.
    ensemble_module = sys.modules["varmech.ensemble"]  # the module, which varmech.ensemble (the function) shadows

    class Interrupted:
        def update(self, n):
            raise KeyboardInterrupt

        def close(self):
            pass

    monkeypatch.setattr(ensemble_module, "progress_bar", lambda **kwargs: Interrupted())
    scene, q0, p0 = _double_pendulum_rows(12)
    run = dict(dt=0.01, steps=200, method="midpoint", save_every=7)
    with pytest.raises(KeyboardInterrupt) as info:
        varmech.ensemble(scene, q0, p0, client=cluster_client, chunk_size=4, **run)
    partial = info.value.partial
    done = [i for i in range(12) if partial.errors[i] is None]
    assert len(done) == 4 and done[0] % 4 == 0 and done == list(range(done[0], done[0] + 4))
    for i in done:
        assert _same(partial[i], varmech.integrate(scene.model, q0[i], p0[i], **run)), f"member {i}"
    assert sorted(partial.failed) == sorted(set(range(12)) - set(done))
    assert all(len(partial[i].t) == 0 and partial[i].status == -1 for i in partial.failed)


def test_a_model_that_cannot_be_shipped_is_named(cluster_client):
    model = _unshippable()
    with pytest.raises(TypeError, match="^model"):
        varmech.ensemble(model, [[1.0]], [[0.0]], dt=0.1, steps=10, client=cluster_client, progress=False)


def test_a_killed_dask_worker_is_retried_and_the_ensemble_is_complete_and_equal(cluster_client):
    scene, q0, p0 = _double_pendulum_rows(8)
    run = dict(dt=1e-3, steps=1_000_000, method="midpoint", save_every=10_000)
    address, victim = sorted(cluster_client.run(os.getpid).items())[0]
    killed = {}
    done = threading.Event()

    def kill():
        # Once the victim runs a chunk: its task is lost with it, and Dask runs it again.
        while not done.is_set() and not cluster_client.processing().get(address):
            time.sleep(0.01)
        time.sleep(0.2)
        killed["while_running"] = not done.is_set()
        os.kill(victim, signal.SIGKILL)

    killer = threading.Thread(target=kill)
    killer.start()
    try:
        runs = varmech.ensemble(scene, q0, p0, client=cluster_client, chunk_size=1, progress=False, **run)
    finally:
        done.set()
        killer.join()
    assert killed["while_running"], "the worker was killed during the run"
    assert victim not in cluster_client.run(os.getpid).values()
    local = varmech.ensemble(scene, q0, p0, workers=2, progress=False, **run)
    assert runs.failed == [] and len(runs) == 8
    for i in range(8):
        assert _same(runs[i], local[i]), f"member {i}"


LEAK = """
import numpy as np, varmech

class LeftTheChart(Exception):
    pass

def gradient(q):
    if abs(q[0]) > 2.0:
        raise LeftTheChart(f"left the chart at q = {q[0]}")
    return q.copy()

if __name__ == "__main__":
    oscillator = varmech.MechanicalSystem(1, potential=lambda q: 0.5 * q[0] ** 2, gradient=gradient)
    q0, p0 = [[0.5], [1.0], [1.0], [1.5]], [[0.0], [0.0], [2.0], [0.0]]
    runs = varmech.ensemble(oscillator, q0, p0, dt=0.1, steps=100, workers=2, chunk_size=1, progress=False)
    print(runs.failed)
"""


def test_a_closure_ensemble_in_processes_leaks_no_semaphore_at_exit(tmp_path):
    # Issue 32: with a raising member the interpreter warned at exit "resource_tracker: There
    # appear to be 1 leaked semaphore objects": each worker's tqdm made a process lock (a named
    # semaphore) that the pool's terminate left behind. Twice, since the leak was a race.
    script = tmp_path / "leak.py"
    script.write_text(LEAK)
    for _ in range(2):
        done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=os.environ.copy())
        assert done.returncode == 0, done.stderr
        assert done.stdout.strip() == "[2]"
        assert "leaked" not in done.stderr and "resource_tracker" not in done.stderr, done.stderr
