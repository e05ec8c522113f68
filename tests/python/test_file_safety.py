"""Files one cannot trust: loading and resuming run no code from a file (models travel as data;
a pickle only with allow_pickle=True), damaged files are refused by name and never hang,
resume refuses a checkpoint that is not its last row's state, a full disk keeps the committed
rows, and a run killed before its first segment resumes bit for bit."""

import errno
import json
import os
import pickle
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import varmech
from conftest import committed
from varmech import files, scenes

DATA = Path(__file__).parent / "data"


def _same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def _marked(marker, model):
    """What the crafted pickle calls: leaves ``marker`` behind (the code a file ran)."""
    Path(marker).write_text("ran")
    return model


class _Payload:
    def __init__(self, marker, model):
        self.marker, self.model = marker, model

    def __reduce__(self):
        return (_marked, (str(self.marker), self.model))


def _crafted(tmp_path, version=3):
    """A streamed Kepler run whose /model is a pickle that writes a marker file when loaded."""
    s = scenes.kepler()
    path = tmp_path / "crafted.h5"
    varmech.integrate(s, dt=s.dt, steps=100, save_every=10, output=path)
    marker = tmp_path / "marker"
    blob = np.void(pickle.dumps(_Payload(marker, s.model)))
    with h5py.File(path, "r+") as f:
        del f["model"]
        if version == 3:
            f["model"] = json.dumps({"kind": "pickle"})
            f["model_pickle"] = blob
        else:
            f["model"] = blob
            f.attrs["format_version"] = 2
    return path, marker, s


@pytest.mark.parametrize("version", [3, 2])
def test_a_crafted_pickle_runs_no_code_unless_allowed(tmp_path, version):
    path, marker, s = _crafted(tmp_path, version)
    for action in (lambda: varmech.load(path), lambda: varmech.resume(path, steps=10)):
        with pytest.raises(ValueError, match="^path: .* is a pickle .*pass model= .*allow_pickle=True"):
            action()
        assert not marker.exists()
    # A model of one's own runs nothing from the file, and goes on as the run would.
    assert varmech.load(path, model=s.model).model is s.model
    traj = varmech.resume(path, steps=10, model=s.model)
    assert not marker.exists() and traj.steps == 110
    # Opted in, the pickle runs (the file is trusted).
    back = varmech.load(path, allow_pickle=True)
    assert marker.read_text() == "ran" and back.model.parameters == s.model.parameters


def test_models_travel_as_data_and_come_back_to_the_bit(tmp_path):
    sp = pytest.importorskip("sympy")
    import varmech.symbolic

    th, om, g = sp.symbols("theta omega g", real=True)
    # Floats of 30 digits, rationals and a function of two arguments come back exactly.
    L = om**2 / 2 + g * sp.cos(th) + sp.Rational(1, 3) * sp.atan2(th, 2) * sp.Float("0.1", 30)
    symbolic = varmech.symbolic.lagrangian(L, [th], [om], parameters={g: 9.81})
    kepler = scenes.kepler_polar()
    reduced = varmech.routh(kepler)
    x0, px0 = reduced.reduce(kepler.q0, kepler.p0)
    two = scenes.nbody([1.0, 1e-3], [[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]])
    cases = [
        (scenes.kepler(0.3).model, [1.0, 0.0], [0.0, 1.2], "verlet"),
        (two.model, two.q0, two.p0, "verlet"),
        (symbolic, [0.5], [0.0], "midpoint"),
        (reduced, x0, px0, "midpoint"),
    ]
    for k, (model, q0, p0, method) in enumerate(cases):
        traj = varmech.integrate(model, q0, p0, dt=0.01, steps=50, method=method)
        path = traj.save(tmp_path / f"{k}.h5")
        with h5py.File(path) as f:
            recipe = json.loads(f["model"][()])
            assert recipe["kind"] != "pickle" and "model_pickle" not in f
        back = varmech.load(path)
        assert type(back.model) is type(model)
        again = varmech.integrate(back.model, q0, p0, dt=0.01, steps=50, method=method)
        assert _same(again.q, traj.q) and _same(again.p, traj.p)
    assert back.model.full.name == reduced.full.name
    rebuilt = varmech.load(tmp_path / "2.h5").model
    assert rebuilt.L == symbolic.L and rebuilt.expressions == symbolic.expressions and rebuilt.q == symbolic.q


def test_a_crafted_recipe_is_data_never_code(tmp_path):
    sp = pytest.importorskip("sympy")
    import varmech.symbolic

    th, om = sp.symbols("theta omega")
    model = varmech.symbolic.lagrangian(om**2 / 2 + sp.cos(th), [th], [om])
    path = varmech.integrate(model, [0.5], [0.0], dt=0.01, steps=5).save(tmp_path / "s.h5")
    recipe = model._recipe()
    marker = tmp_path / "marker"
    evil = f"__import__('pathlib').Path({str(marker)!r}).write_text('ran')"
    for tampered, message in [
        # A symbol's name is a name: never parsed.
        ({**recipe, "L": ["Symbol", evil, {}]}, None),
        # Only the known classes are built.
        ({**recipe, "L": ["Function", evil]}, "not a known expression class"),
        ({**recipe, "L": ["Lambda", ["Symbol", "x", {}], ["Symbol", evil, {}]]}, "not a known expression class"),
        ({**recipe, "parameters": [evil]}, "not a list of numbers"),
        ({**recipe, "kind": "os.system"}, "not a model recipe of a known kind"),
    ]:
        with h5py.File(path, "r+") as f:
            del f["model"]
            f["model"] = json.dumps(tampered)
        if message is None:
            assert str(varmech.load(path).model.L) == evil
        else:
            with pytest.raises(ValueError, match=f"^path: cannot rebuild the model .*{message}"):
                varmech.load(path)
        assert not marker.exists()


def _load_and_resume(path, setup="", model="None", timeout=60):
    """What ``varmech.load`` and ``varmech.resume`` of ``path`` did, run after ``setup`` in a
    process of their own: a line each ("load passed", "resume ValueError …"), or a failure when
    either hangs."""
    code = f"""
import varmech
{setup}
path, model = {str(path)!r}, {model}
for what, action in (("load", lambda: varmech.load(path, model=model)),
                     ("resume", lambda: varmech.resume(path, steps=10, model=model))):
    try:
        action()
        print(what, "passed")
    except ValueError as e:
        print(what, "ValueError", e)
"""
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail("hung")
    out = done.stdout + done.stderr
    lines = [line for line in out.splitlines() if line.startswith(("load", "resume"))]
    assert len(lines) == 2, out
    return lines


@pytest.mark.parametrize("name", ["hang-truncated.h5", "hang-bitflip.h5"])
def test_a_damaged_file_is_refused_by_name_and_never_hangs(tmp_path, name):
    path = tmp_path / name
    shutil.copyfile(DATA / name, path)
    lines = _load_and_resume(path, model="varmech.scenes.kepler().model")
    # resume refuses whatever load says: both name the path.
    assert lines[1].startswith("resume ValueError path: "), lines
    if name == "hang-truncated.h5":
        assert lines[0].startswith("load ValueError path: ") and "corrupt or truncated: 5914 bytes" in lines[0], lines


def _killed_early(path):
    """A streamed run SIGKILLed once its initial state is committed: a file its writer left
    open (SWMR)."""
    proc = subprocess.Popen([sys.executable, "-c", KILLED_EARLY, str(path)], stderr=subprocess.PIPE, text=True)
    try:
        if not committed(path, 1, poll=0.1):
            pytest.fail("nothing committed in 60 s")
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    finally:
        proc.kill()


def test_a_damaged_file_left_open_by_a_killed_writer_is_refused_in_bounded_time(tmp_path):
    path = tmp_path / "killed.h5"
    _killed_early(path)
    data = bytearray(path.read_bytes())
    # A byte of the padding of a dataset's object header: its checksum fails. libhdf5 reads such
    # a file (marked open by its writer) in SWMR mode, where it retries the checksum forever.
    # (HDF5 format, version 2 object header: signature, version, flags, optional times and
    # attribute counts, then the size of its first chunk, which the checksum follows.)
    at = [i for i in range(len(data)) if data[i : i + 4] == b"OHDR"][2]
    flags = data[at + 5]
    size_at = at + 6 + (16 if flags & 0x20 else 0) + (4 if flags & 0x10 else 0)
    width = 1 << (flags & 3)
    checksum_at = size_at + width + int.from_bytes(data[size_at : size_at + width], "little")
    data[checksum_at - 2] ^= 1
    path.write_bytes(bytes(data))
    lines = _load_and_resume(path, setup="varmech.files.PROBE_SECONDS = 5")
    assert all(" ValueError path: " in line and "corrupt" in line for line in lines), lines


def _streamed(tmp_path, steps=1000, every=10, checkpoint_every=100):
    s = scenes.kepler()
    path = tmp_path / "k.h5"
    varmech.integrate(s, dt=s.dt, steps=steps, save_every=every, output=path, checkpoint_every=checkpoint_every)
    return s, path


def _flip(path, offset, bit=0):
    data = bytearray(path.read_bytes())
    data[offset] ^= 1 << bit
    path.write_bytes(bytes(data))


def test_a_flipped_bit_in_committed_or_in_the_rows_is_refused(tmp_path):
    s, path = _streamed(tmp_path)
    with h5py.File(path) as f:
        committed_at = f["committed"].id.get_chunk_info(0).byte_offset
        q_at = f["q"].id.get_chunk_info(0).byte_offset
    good = path.read_bytes()
    # The slot (committed[1]) flipped: before checksums, resume went on from the older checkpoint.
    _flip(path, committed_at + 8)
    for action in (lambda: varmech.load(path), lambda: varmech.resume(path, steps=10)):
        with pytest.raises(ValueError, match="^path: .*corrupt"):
            action()
    path.write_bytes(good)
    _flip(path, q_at + 8 * 7, bit=3)
    with pytest.raises(ValueError, match="^path: .*corrupt"):
        varmech.load(path)
    path.write_bytes(good)
    assert varmech.resume(path, steps=10).steps == 1010


def _older_committed(path):
    """``/committed`` rewritten with valid checksums to name the other checkpoint slot, which
    holds the checkpoint before the last."""
    with h5py.File(path, "r+") as f:
        committed = f["committed"][()]
        committed[1] = 1 - committed[1]
        committed[2] = f[f"checkpoint{committed[1]}"].shape[0]
        f["committed"][...] = committed


def test_resume_refuses_a_checkpoint_that_is_not_the_last_rows_state(tmp_path):
    s, path = _streamed(tmp_path)
    _older_committed(path)
    before = path.read_bytes()
    with pytest.raises(ValueError, match=r"^path: .*its checkpoint \(step 900, .*\) is not the state of its last committed row \(step 1000"):
        varmech.resume(path, steps=10)
    assert path.read_bytes() == before  # nothing appended
    # Rows at t_eval times are not the states a checkpoint goes on from: resume went on from t = 1
    # while appending after t = 0.5.
    traj = varmech.integrate(s, dt=0.01, steps=100, t_eval=[0.105, 0.5])
    with pytest.raises(ValueError, match=r"^path: .*its checkpoint \(step 100, t = 1.0\) .*\(step 100, t = 0.5\).*t_eval"):
        varmech.resume(traj.save(tmp_path / "t_eval.h5"), steps=10)


def test_resume_refuses_a_file_whose_model_or_method_was_swapped(tmp_path):
    # Issue 32: a file whose /model was swapped for another model of the same dimension resumed
    # 0.44 away from the real run. The checkpoint's fingerprint tells them apart, and the file's
    # method and dt attributes are checked against the checkpoint's too.
    s, path = _streamed(tmp_path)
    good = path.read_bytes()
    with h5py.File(path, "r+") as f:
        del f["model"]
        f.create_dataset("model", data=json.dumps(scenes.henon_heiles().model._recipe()))
    with pytest.raises(ValueError, match="^path: .*checkpoint: it is of another model"):
        varmech.resume(path, steps=10)
    for attribute, value, named in (("method", "yoshida4", "method "), ("dt", 0.02, "dt = ")):
        path.write_bytes(good)
        with h5py.File(path, "r+") as f:
            f.attrs[attribute] = value
        with pytest.raises(ValueError, match=f"^path: .*checkpoint: it is of a run of {named}"):
            varmech.resume(path, steps=10)


@pytest.mark.parametrize("column", ["t", "q", "p"])
def test_non_finite_rows_are_refused(tmp_path, column):
    s, path = _streamed(tmp_path)
    with h5py.File(path, "r+") as f:
        f[column][5] = np.nan
    for action in (lambda: varmech.load(path), lambda: np.asarray(getattr(varmech.load(path, lazy=True), column))):
        with pytest.raises(ValueError, match=f"^path: .*non-finite {column} rows"):
            action()
    with h5py.File(path, "r+") as f:
        f[column][5] = 0.0
        f[column][-1] = np.inf
    with pytest.raises(ValueError, match=f"^path: .*non-finite {column} rows"):
        varmech.resume(path, steps=10)


def test_a_full_disk_is_named_and_keeps_the_committed_rows_for_resume(tmp_path, monkeypatch):
    s = scenes.kepler()
    path = tmp_path / "full.h5"
    calls = []
    append = files.Writer._append

    def full_on_the_fourth(self, *args):
        calls.append(1)
        if len(calls) == 4:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return append(self, *args)

    monkeypatch.setattr(files.Writer, "_append", full_on_the_fourth)
    with pytest.raises(ValueError, match="^output: cannot write to .*No space left on device.*rows committed before are kept") as info:
        varmech.integrate(s, dt=s.dt, steps=1000, save_every=10, output=path, checkpoint_every=100)
    monkeypatch.undo()
    # The initial state and two segments of 100 steps were committed.
    kept = varmech.load(path)
    assert kept.steps == 200 and len(kept.t) == 21 and kept.status == -1
    assert info.value.partial.steps == 200
    whole = varmech.integrate(s, dt=s.dt, steps=1000, save_every=10)
    resumed = varmech.resume(path, steps=800)
    assert _same(resumed.q, whole.q) and _same(resumed.p, whole.p) and resumed.status == 0


def test_a_disk_about_to_fill_is_refused_before_the_write_and_resume_goes_on(tmp_path, monkeypatch):
    s = scenes.kepler()
    path = tmp_path / "full.h5"
    usage = shutil.disk_usage(tmp_path)
    calls = []

    def filling(where):
        calls.append(1)
        # Room for the initial state and two segments, then almost none.
        return usage._replace(free=usage.free if len(calls) < 4 else 50_000)

    monkeypatch.setattr(files.shutil, "disk_usage", filling)
    with pytest.raises(ValueError, match=r"^output: cannot write to .*\[Errno 28\].*50000 bytes free.*21 rows committed before"):
        varmech.integrate(s, dt=s.dt, steps=1000, save_every=10, output=path, checkpoint_every=100)
    monkeypatch.undo()
    kept = varmech.load(path)
    assert kept.steps == 200 and kept.status == -1 and "No space left" in kept.message
    whole = varmech.integrate(s, dt=s.dt, steps=1000, save_every=10)
    resumed = varmech.resume(path, steps=800)
    assert _same(resumed.q, whole.q) and _same(resumed.p, whole.p) and resumed.status == 0


KILLED_EARLY = """
import sys, varmech
s = varmech.scenes.kepler()
varmech.integrate(s, dt=1e-3, steps=10**12, save_every=10**9, output=sys.argv[1])
"""


def test_a_run_killed_in_its_first_segment_resumes_bit_for_bit(tmp_path):
    path = tmp_path / "early.h5"
    # Killed long before its first segment (4096 saving periods of 1e9 steps) is done.
    _killed_early(path)
    kept = varmech.load(path)
    assert kept.steps == 0 and len(kept.t) == 1 and kept.status == -1
    resumed = varmech.resume(path, steps=1000, save_every=100)
    s = scenes.kepler()
    whole = varmech.integrate(s, dt=1e-3, steps=1000, save_every=100)
    assert _same(resumed.q, whole.q) and _same(resumed.p, whole.p) and resumed.steps == 1000


def test_a_continued_run_streamed_to_a_file_starts_with_its_state_committed(tmp_path):
    s = scenes.kepler()
    traj = varmech.integrate(s, dt=s.dt, steps=100, save_every=10)
    in_memory = varmech.integrate(traj, steps=50, save_every=10)
    # Before, the file lacked the state the run went on from, and nothing was resumable
    # until the first segment was committed.
    streamed = varmech.integrate(traj, steps=50, save_every=10, output=tmp_path / "c.h5")
    for name in ("t", "q", "p"):
        assert _same(getattr(streamed, name), getattr(in_memory, name)), name
    assert (streamed.steps, streamed.nfev) == (in_memory.steps, in_memory.nfev)


def test_resume_reads_what_load_reads_before_it_writes(tmp_path):
    # Issue 64 (resume-hang.py): one bit flipped in the metadata between q's and p's chunks and
    # the Newton counts' chunk of a cleanly closed file. load refused it at once; resume, which
    # loads lazily, reached it first in its writer (appending Newton counts) and hung in libhdf5,
    # deaf to Ctrl-C. It now reads every committed row as load does before writing anything.
    path = tmp_path / "bitflip.h5"
    varmech.integrate(scenes.double_pendulum(), dt=0.01, method="midpoint", save_every=10, steps=2000, output=path,
                      checkpoint_every=500)
    with h5py.File(path, "r") as f:
        end_of_p = max(f[name].id.get_chunk_info(0).byte_offset + f[name].id.get_chunk_info(0).size for name in "qp")
        newton_at = f["newton"].id.get_chunk_info(0).byte_offset
    # The reproducer's byte: 424 bytes into that metadata.
    assert end_of_p + 424 < newton_at
    _flip(path, end_of_p + 424, bit=6)
    before = path.read_bytes()
    load, resume = _load_and_resume(path)
    assert load.startswith("load ValueError path: ") and "corrupt" in load, load
    assert resume.startswith("resume ValueError path: ") and "corrupt" in resume, resume
    assert path.read_bytes() == before


def test_a_loaded_file_goes_on_only_from_its_last_rows_checkpoint(tmp_path):
    # Issue 64 (load-continue.py): resume cross-checked /committed against the last row, load
    # followed by integrate(traj) did not, and went on from the older checkpoint (t jumping
    # back), with status 0. Both go through one check now.
    s, path = _streamed(tmp_path)
    _older_committed(path)
    traj = varmech.load(path)
    with pytest.raises(ValueError, match=r"^model: this trajectory cannot go on: its checkpoint \(step 900, .*\(step 1000"):
        varmech.integrate(traj, steps=10)
    with pytest.raises(ValueError, match=r"^path: .* cannot go on: its checkpoint \(step 900"):
        varmech.resume(path, steps=10)
    # An intact file goes on both ways to the same bits.
    (tmp_path / "good").mkdir()
    _, good = _streamed(tmp_path / "good")
    more = varmech.integrate(varmech.load(good), steps=100, save_every=10)
    resumed = varmech.resume(good, steps=100)
    assert _same(more.q[-1], resumed.q[-1]) and more.t[-1] == resumed.t[-1]
