"""Long runs: continued in memory, streamed to a file, resumed from it, bit for bit with one
uninterrupted run; files left by Ctrl-C and SIGKILL load and resume; bad input is named."""

import os
import signal
import subprocess
import sys
import textwrap

import h5py
import numpy as np
import pytest

import varmech
from conftest import committed
from varmech import scenes

N, M, EVERY = 100, 150, 17


def _same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _routh():
    scene = scenes.kepler_polar()
    reduced = varmech.routh(scene)
    x0, px0 = reduced.reduce(scene.q0, scene.p0)
    return reduced, x0, px0, 0.01, "midpoint"


def _case(name):
    if name == "routh":
        return _routh()
    scene, method = {
        "verlet": (scenes.kepler(0.6), "verlet"),
        "kahan_li8": (scenes.kepler(0.6), "kahan_li8"),
        "midpoint": (scenes.double_pendulum(), "midpoint"),
        "galerkin4": (scenes.double_pendulum(), "galerkin4"),
        "rattle": (scenes.cartesian_pendulum(), "rattle"),
    }[name]
    return scene.model, scene.q0, scene.p0, scene.dt, method


FAMILIES = ["verlet", "kahan_li8", "midpoint", "galerkin4", "rattle", "routh"]


def _assert_continues(whole, parts):
    """The states of ``parts`` (runs one after another, each starting with the last one's final
    state) are ``whole``'s at the same times, and they end on its final state and counts."""
    t = np.asarray(whole.t)
    for part in parts:
        rows = np.searchsorted(t, np.asarray(part.t))
        on_whole = (rows < len(t)) & (t[np.minimum(rows, len(t) - 1)] == np.asarray(part.t))
        for name in ("q", "p"):
            assert _same(np.asarray(getattr(part, name))[on_whole], np.asarray(getattr(whole, name))[rows[on_whole]]), (
                name
            )
    last = parts[-1]
    assert _same(last.q[-1], whole.q[-1]) and _same(last.p[-1], whole.p[-1])
    assert _same(last.energy()[-1:], whole.energy()[-1:])
    assert (last.steps, last.newton_iterations) == (whole.steps, whole.newton_iterations)


@pytest.mark.parametrize("family", FAMILIES)
def test_save_load_and_go_on_is_one_run_to_the_bit(tmp_path, family):
    model, q0, p0, dt, method = _case(family)
    whole = varmech.integrate(model, q0, p0, dt=dt, steps=N + M, save_every=EVERY, method=method)
    first = varmech.integrate(model, q0, p0, dt=dt, steps=N, save_every=EVERY, method=method)
    # In memory, and through a file.
    _assert_continues(whole, [first, varmech.integrate(first, steps=M, save_every=EVERY)])
    loaded = varmech.load(first.save(tmp_path / "first.h5"))
    _assert_continues(whole, [loaded, varmech.integrate(loaded, steps=M, save_every=EVERY)])
    resumed = varmech.resume(tmp_path / "first.h5", steps=M, save_every=EVERY)
    _assert_continues(whole, [resumed])


@pytest.mark.parametrize("family", ["verlet", "midpoint", "rattle"])
def test_a_streamed_run_is_the_run_in_memory(tmp_path, family):
    model, q0, p0, dt, method = _case(family)
    whole = varmech.integrate(model, q0, p0, dt=dt, steps=N + M, save_every=EVERY, method=method)
    # Segments of two saving periods: 8 segments, each from the last one's checkpoint.
    streamed = varmech.integrate(
        model,
        q0,
        p0,
        dt=dt,
        steps=N + M,
        save_every=EVERY,
        method=method,
        output=tmp_path / "s.h5",
        checkpoint_every=2 * EVERY,
    )
    for name in ("t", "q", "p"):
        assert _same(getattr(streamed, name), getattr(whole, name)), name
    np.testing.assert_array_equal(streamed.newton_iterations_per_step, whole.newton_iterations_per_step)
    assert (streamed.steps, streamed.nfev, streamed.status) == (whole.steps, whole.nfev, 0)
    with h5py.File(tmp_path / "s.h5") as f:
        assert f.attrs["complete"] and f.attrs["save_every"] == EVERY


def test_resume_goes_on_in_the_same_file(tmp_path):
    s = scenes.kepler()
    path = tmp_path / "k.h5"
    varmech.integrate(s, dt=s.dt, steps=10 * EVERY, save_every=EVERY, output=path)
    traj = varmech.resume(path, t_end=s.dt * 25 * EVERY)
    whole = varmech.integrate(s, dt=s.dt, steps=25 * EVERY, save_every=EVERY)
    # On the cadence, the file holds exactly the states of one run.
    for name in ("t", "q", "p"):
        assert _same(getattr(traj, name), getattr(whole, name)), name
    assert traj.steps == 25 * EVERY and traj.status == 0


def test_resume_without_steps_goes_on_to_the_end_the_run_was_asked_for(tmp_path):
    # A run asked for 25·EVERY steps stops early (here a terminal event, as a kill would):
    # resume(path) goes on to those 25·EVERY, one run to the bit; then it has reached its end.
    s = scenes.kepler()
    path = tmp_path / "k.h5"
    stop = varmech.events.crossing(1, 0.0, direction=-1, terminal=True)
    early = varmech.integrate(s, dt=s.dt, steps=25 * EVERY, save_every=EVERY, output=path, events=[stop])
    assert early.steps < 25 * EVERY
    traj = varmech.resume(path)
    whole = varmech.integrate(s, dt=s.dt, steps=25 * EVERY, save_every=EVERY)
    assert traj.steps == 25 * EVERY and traj.status == 0
    assert _same(traj.q[-1], whole.q[-1]) and _same(traj.p[-1], whole.p[-1])
    with pytest.raises(ValueError, match=rf"^steps, t_end: the run in .* has reached the end it was asked for \(step {25 * EVERY}"):
        varmech.resume(path)
    # steps= is how many more, and moves the planned end with it.
    assert varmech.resume(path, steps=EVERY).steps == 26 * EVERY
    with pytest.raises(ValueError, match=rf"\(step {26 * EVERY}"):
        varmech.resume(path)
    # A saved trajectory records no planned end: resume asks how much further.
    saved = tmp_path / "saved.h5"
    whole.save(saved)
    with pytest.raises(ValueError, match="^steps, t_end: give how much further: .* does not record"):
        varmech.resume(saved)


RUN = """
import sys, varmech
s = varmech.scenes.kepler()
print("started", flush=True)
varmech.integrate(s, dt=1e-3, steps=10**10, save_every=1000, output=sys.argv[1], checkpoint_every=10**5)
"""


def _start(path):
    proc = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(RUN), str(path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout.readline().strip() == "started"
    # Until a few segments are committed.
    if committed(path, 500, poll=0.2):
        return proc
    proc.kill()
    pytest.fail("the run committed nothing in 60 s")


def _check_left_file(path, status, message):
    traj = varmech.load(path)
    assert traj.status == status and message in traj.message
    # Killed: the committed rows, on the saving cadence. Stopped: and the last good state.
    cadence = len(traj.t) - (traj.steps % 1000 != 0)
    assert cadence > 500 and (cadence - 1) * 1000 <= traj.steps < (cadence + 1) * 1000
    s = scenes.kepler()
    # Every committed state is the uninterrupted run's, and the run resumes from the last.
    whole = varmech.integrate(s, dt=1e-3, steps=traj.steps + 5000, save_every=1000)
    assert _same(traj.q[:cadence], whole.q[:cadence]) and _same(traj.p[:cadence], whole.p[:cadence])
    resumed = varmech.resume(path, steps=5000)
    _assert_continues(whole, [resumed])
    assert resumed.status == 0


def test_a_run_killed_while_streaming_leaves_a_file_that_loads_and_resumes(tmp_path):
    path = tmp_path / "killed.h5"
    proc = _start(path)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    _check_left_file(path, -1, "without closing its file")


def test_a_run_stopped_by_ctrl_c_leaves_a_complete_file(tmp_path):
    path = tmp_path / "interrupted.h5"
    proc = _start(path)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert "KeyboardInterrupt" in err
    with h5py.File(path) as f:
        assert f.attrs["complete"]
    _check_left_file(path, -1, "KeyboardInterrupt")


def test_bad_output_and_checkpoint_arguments_are_named(tmp_path):
    s = scenes.harmonic_oscillator()
    path = tmp_path / "a.h5"
    varmech.integrate(s, dt=0.1, steps=10, output=path)
    with pytest.raises(ValueError, match="^output: .* exists; pass overwrite=True"):
        varmech.integrate(s, dt=0.1, steps=10, output=path)
    varmech.integrate(s, dt=0.1, steps=10, output=path, overwrite=True)
    with pytest.raises(ValueError, match="^output: cannot write .*its directory does not exist"):
        varmech.integrate(s, dt=0.1, steps=10, output=tmp_path / "no" / "a.h5")
    with pytest.raises(ValueError, match="^output: .* is a directory"):
        varmech.integrate(s, dt=0.1, steps=10, output=tmp_path, overwrite=True)
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(ValueError, match="^output: cannot write"):
            varmech.integrate(s, dt=0.1, steps=10, output=locked / "a.h5")
    with pytest.raises(ValueError, match="^checkpoint_every: checkpoints are written to a file; pass output="):
        varmech.integrate(s, dt=0.1, steps=10, checkpoint_every=5)
    with pytest.raises(ValueError, match="^checkpoint_every: must be"):
        varmech.integrate(s, dt=0.1, steps=10, output=path, overwrite=True, checkpoint_every=0)
    traj = varmech.integrate(s, dt=0.1, steps=10)
    with pytest.raises(ValueError, match="^dt: a continued run keeps its trajectory's dt"):
        varmech.integrate(traj, dt=0.2, steps=10)
    # A continued run's samples lie in its own span, after the checkpoint.
    with pytest.raises(ValueError, match=r"^t_eval: must lie within the run's span"):
        varmech.integrate(traj, steps=10, t_eval=[float(traj.t[-1]) - 0.5])


def test_a_checkpoint_of_another_model_or_damaged_is_refused(tmp_path):
    kepler = scenes.kepler()
    traj = varmech.integrate(kepler, dt=0.01, steps=10)
    # Another model of the same dimension, which verlet does not integrate.
    other = varmech.load(traj.save(tmp_path / "k.h5"), model=scenes.double_pendulum().model)
    with pytest.raises(ValueError, match="^method: "):
        varmech.integrate(other, steps=10)
    with pytest.raises(ValueError, match="^model: has dimension"):
        varmech.load(tmp_path / "k.h5", model=scenes.heavy_top().model)
    damaged = bytearray(traj.checkpoint)
    damaged[len(damaged) // 2] ^= 1
    with pytest.raises(ValueError, match="^checkpoint: damaged or truncated"):
        varmech.Stepper.from_checkpoint(kepler, bytes(damaged))
    with pytest.raises(ValueError, match="^checkpoint: not a varmech checkpoint"):
        varmech.Stepper.from_checkpoint(kepler, b"")


def test_a_truncated_or_corrupt_file_is_a_clear_error(tmp_path):
    s = scenes.kepler()
    path = varmech.integrate(s, dt=s.dt, steps=10**4, save_every=10).save(tmp_path / "k.h5")
    data = path.read_bytes()
    cut = tmp_path / "cut.h5"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="^path: .*(corrupt or truncated|not a varmech)"):
        varmech.load(cut)
    garbage = tmp_path / "garbage.h5"
    garbage.write_bytes(os.urandom(4096))
    with pytest.raises(ValueError, match="^path: "):
        varmech.load(garbage)


def test_a_file_loaded_lazily_reads_rows_when_used_and_analyses_alike(tmp_path):
    s = scenes.kepler()
    path = tmp_path / "k.h5"
    eager = varmech.integrate(s, dt=s.dt, steps=2000, save_every=10, output=path)
    lazy = varmech.load(path, lazy=True)
    assert isinstance(lazy.q, varmech.files.Rows) and lazy.q.shape == eager.q.shape
    assert _same(lazy.q[-1], eager.q[-1]) and _same(lazy.p[5, 1:], eager.p[5, 1:]) and _same(lazy.t[3], eager.t[3])
    assert _same(lazy.energy(), eager.energy())
    assert varmech.check_conservation(lazy).verdict == varmech.check_conservation(eager).verdict


def test_a_streamed_run_watches_its_events_across_segments(tmp_path):
    from varmech.events import crossing, energy_error

    s = scenes.pendulum()
    events = [crossing(0, 0.0, direction=+1), crossing(0, 0.0, direction=-1, terminal=7)]
    memory = varmech.integrate(s, dt=0.01, steps=10**5, save_every=50, events=events)
    # Segments of 500 steps: crossings in every segment, the terminal count over the whole run.
    streamed = varmech.integrate(s, dt=0.01, steps=10**5, save_every=50, events=events, output=tmp_path / "e.h5", checkpoint_every=500)
    assert streamed.status == memory.status == 1 and streamed.message == memory.message
    assert streamed.steps == memory.steps and _same(streamed.q, memory.q)
    for a, b in zip(streamed.events, memory.events):
        assert a.name == b.name and len(a) == len(b) > 0
        for name in ("t", "q", "p"):
            assert _same(getattr(a, name), getattr(b, name)), name
    # The energy error is measured from the run's first energy in every segment.
    e = scenes.harmonic_oscillator()
    bound = [energy_error(0.05)]
    memory = varmech.integrate(e, dt=0.01, steps=10**5, method="explicit_euler", max_energy_error=None, events=bound)
    streamed = varmech.integrate(
        e, dt=0.01, steps=10**5, method="explicit_euler", max_energy_error=None, events=bound, output=tmp_path / "f.h5", checkpoint_every=100
    )
    assert streamed.status == memory.status == 1 and streamed.steps == memory.steps > 100
    assert _same(streamed.events[0].t, memory.events[0].t)


def test_resume_watches_the_files_events_on(tmp_path):
    from varmech.events import crossing

    s = scenes.pendulum()
    events = [crossing(0, 0.0, direction=+1)]
    path = tmp_path / "p.h5"
    varmech.integrate(s, dt=0.01, steps=4000, save_every=50, events=events, output=path)
    resumed = varmech.resume(path, steps=6000, events=events)
    whole = varmech.integrate(s, dt=0.01, steps=10000, save_every=50, events=events)
    assert len(resumed.events[0]) == len(whole.events[0]) > 3
    assert _same(resumed.events[0].t, whole.events[0].t)
    with pytest.raises(ValueError, match="^events: the file's events are"):
        varmech.resume(path, steps=10, events=[crossing(0, 0.5)])


def test_a_run_continued_in_memory_watches_events_on():
    from varmech.events import crossing

    s = scenes.pendulum()
    events = [crossing(0, 0.0, direction=+1, terminal=5)]
    whole = varmech.integrate(s, dt=0.01, steps=10**5, events=events)
    first = varmech.integrate(s, dt=0.01, steps=1500, events=events)
    assert first.status == 0 and 0 < len(first.events[0]) < 5
    rest = varmech.integrate(first, steps=10**5 - 1500, events=events)
    # The fifth crossing of the whole run stops the continuation, at the same step.
    assert rest.status == 1 and rest.steps == whole.steps
    both = np.concatenate([first.events[0].t, rest.events[0].t])
    assert _same(both, whole.events[0].t)


def test_a_streamed_run_that_fails_commits_its_last_segments_crossings(tmp_path):
    from varmech.events import crossing

    # Explicit Euler on the pendulum: crossings, then the energy check stops the run mid-segment.
    s = scenes.pendulum()
    events = [crossing(0, 0.0)]
    kwargs = dict(dt=0.05, steps=10**5, method="explicit_euler", events=events)
    with pytest.raises(varmech.DivergenceError) as memory:
        varmech.integrate(s, **kwargs)
    with pytest.raises(varmech.DivergenceError) as streamed:
        varmech.integrate(s, **kwargs, output=tmp_path / "d.h5", checkpoint_every=10**6)
    a, b = memory.value.partial, streamed.value.partial
    assert len(b.events[0]) == len(a.events[0]) > 0
    assert _same(b.events[0].t, a.events[0].t) and _same(b.q[-1], a.q[-1])


def test_a_continued_run_takes_the_energy_check_it_is_given(tmp_path):
    # Explicit Euler multiplies the oscillator's energy by 1 + h² a step: the run's own check
    # stops it at step 49 whether or not it was continued; None lifts the check, and a level
    # sets it; the states are the unbroken run's, bit for bit, whatever watches them.
    scene = scenes.harmonic_oscillator()
    first = varmech.integrate(scene, dt=0.1, steps=30, method="explicit_euler")
    with pytest.raises(varmech.DivergenceError) as unbroken:
        varmech.integrate(scene, dt=0.1, steps=2030, method="explicit_euler")
    with pytest.raises(varmech.DivergenceError) as kept:
        varmech.integrate(first, steps=2000)
    assert kept.value.step == unbroken.value.step == 49
    free = varmech.integrate(scene, dt=0.1, steps=2030, method="explicit_euler", max_energy_error=None)
    for output in (None, tmp_path / "more.h5"):
        lifted = varmech.integrate(first, steps=2000, max_energy_error=None, output=output)
        assert lifted.status == 0 and np.array_equal(np.asarray(lifted.q), np.asarray(free.q)[30:])
    with pytest.raises(varmech.DivergenceError) as tighter:
        varmech.integrate(first, steps=2000, max_energy_error=0.5)
    assert 30 < tighter.value.step < 49
    # A run without a check given one: measured from the continuation's start.
    with pytest.raises(varmech.DivergenceError, match="max_energy_error = 1.000e0"):
        unchecked = varmech.integrate(scene, dt=0.1, steps=30, method="explicit_euler", max_energy_error=None)
        varmech.integrate(unchecked, steps=2000, max_energy_error=1.0)
    with pytest.raises(ValueError, match="max_energy_error"):
        varmech.integrate(first, steps=10, max_energy_error=-1.0)
