"""Shared set-up of the Python tests: the repository's reference data, the closure models that
several tests build, closures that raise the user's own exception, and helpers to run the
command line, to press Ctrl-C, to wait for a streamed run's rows and to see whether a run lets go
of the GIL."""

import math
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import varmech
from varmech import scenes

#: reference/ of the repository (published data), two levels above this folder.
REFERENCE_DIR = Path(__file__).resolve().parents[2] / "reference"


@pytest.fixture
def kepler():
    """The native Kepler scene (e = 0.6)."""
    return scenes.kepler()


@pytest.fixture
def kepler_polar():
    """Kepler in polar coordinates (r, θ) from closures: L = ½(ṙ² + r²θ̇²) + 1/r, θ cyclic."""

    def lagrangian(q, v, t):
        return 0.5 * (v[0] ** 2 + q[0] ** 2 * v[1] ** 2) + 1.0 / q[0]

    def dl_dq(q, v, t):
        return np.array([q[0] * v[1] ** 2 - 1.0 / q[0] ** 2, 0.0])

    def dl_dv(q, v, t):
        return np.array([v[0], q[0] ** 2 * v[1]])

    return varmech.Lagrangian(2, lagrangian, dl_dq=dl_dq, dl_dv=dl_dv, name="kepler (polar)")


@pytest.fixture
def spherical_natural():
    """Makes the spherical pendulum as a closure mechanical system with mass M(θ) = diag(1, sin²θ)
    and V = −cos θ; keyword arguments go to :class:`varmech.MechanicalSystem`."""

    def make(**kwargs):
        return varmech.MechanicalSystem(
            2,
            lambda q: -math.cos(q[0]),
            lambda q: np.array([math.sin(q[0]), 0.0]),
            mass=lambda q: np.diag([1.0, math.sin(q[0]) ** 2]),
            mass_derivative=lambda q: np.array([np.diag([0.0, math.sin(2.0 * q[0])]), np.zeros((2, 2))]),
            **kwargs,
        )

    return make


def henon_heiles_gradient(q):
    return np.array([q[0] + 2 * q[0] * q[1], q[1] + q[0] ** 2 - q[1] ** 2])


@pytest.fixture
def henon_heiles_closure():
    """Makes Hénon–Heiles from closures, V = ½(x² + y²) + x²y − y³/3, with ∇V given or
    ``gradient``; keyword arguments go to :class:`varmech.MechanicalSystem`."""

    def make(gradient=henon_heiles_gradient, **kwargs):
        return varmech.MechanicalSystem(
            2, potential=lambda q: 0.5 * (q[0] ** 2 + q[1] ** 2) + q[0] ** 2 * q[1] - q[1] ** 3 / 3, gradient=gradient, **kwargs
        )

    make.gradient = henon_heiles_gradient
    return make


@pytest.fixture
def damped_oscillator():
    """Makes the oscillator L = ½q̇² − ½q² with Rayleigh dissipation R = ½cq̇² from closures."""

    def make(c):
        return varmech.Lagrangian(
            1,
            lambda q, v, t: 0.5 * v[0] ** 2 - 0.5 * q[0] ** 2,
            dl_dq=lambda q, v, t: -q.copy(),
            dl_dv=lambda q, v, t: v.copy(),
            rayleigh=c,
        )

    return make


@pytest.fixture
def kink():
    """V = 5|q| with its exact derivatives: from rest at the kink, the midpoint step's equations
    jump over 0 at q₁ = q₀ (the force is ±5 on either side), and have no solution."""
    return varmech.Lagrangian(
        1,
        lambda q, v, t: 0.5 * v[0] ** 2 - 5 * abs(q[0]),
        dl_dq=lambda q, v, t: np.array([-5.0 if q[0] >= 0 else 5.0]),
        dl_dv=lambda q, v, t: v.copy(),
        hessians=lambda q, v, t: (np.zeros((1, 1)), np.zeros((1, 1)), np.ones((1, 1))),
    )


@pytest.fixture
def run_cli():
    """Runs ``python -m varmech <args>`` in a subprocess, capturing its text output."""

    def run(*args, check=True):
        return subprocess.run([sys.executable, "-m", "varmech", *map(str, args)], capture_output=True, text=True, check=check)

    return run


@pytest.fixture
def interrupt_after():
    """Sends this process SIGINT (Ctrl-C) after ``delay`` seconds: returns the started timer and
    a dict whose "at" is the perf_counter time the signal went out."""
    timers = []

    def start(delay):
        sent = {}

        def fire():
            sent["at"] = time.perf_counter()
            os.kill(os.getpid(), signal.SIGINT)

        timer = threading.Timer(delay, fire)
        timers.append(timer)
        timer.start()
        return timer, sent

    yield start
    for timer in timers:
        timer.join()


class Boom(Exception):
    """The user's own exception, raised by a closure under test: varmech must pass it on unchanged."""


def raising_when(condition, closure, message):
    """``closure`` (a model function, an event), raising ``Boom(message)`` instead at a call whose
    arguments meet ``condition``."""

    def raising(*args):
        if condition(*args):
            raise Boom(message)
        return closure(*args)

    return raising


def raising_after(calls, closure, message):
    """``closure``, raising ``Boom(message)`` instead from its call ``calls + 1`` on; the calls so
    far are the result's attribute ``calls``, which a test may move on."""

    def raising(*args):
        raising.calls += 1
        if raising.calls > calls:
            raise Boom(message)
        return closure(*args)

    raising.calls = 0
    return raising


def committed(path, rows, poll, seconds=60):
    """Whether the streamed run writing ``path`` commits ``rows`` rows within ``seconds``, read in
    SWMR mode every ``poll`` seconds (a file not there yet, or not laid out yet, is waited for)."""
    import h5py

    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        time.sleep(poll)
        try:
            with h5py.File(path, "r", swmr=True) as f:
                if f["committed"][0] >= rows:
                    return True
        except (OSError, KeyError):
            pass
    return False


def releases_the_gil(run):
    """Whether ``run()``, started in another thread, lets this one run while it is still going:
    that is, whether it let go of the GIL. ``run`` must take well over 50 ms."""
    done = threading.Event()

    def worker():
        run()
        done.set()

    thread = threading.Thread(target=worker)
    thread.start()
    time.sleep(0.05)
    # This line runs only if the worker let go of the GIL while running.
    running_while_we_run = not done.is_set()
    thread.join()
    return running_while_we_run and done.is_set()


def refix_crc(checkpoint):
    """``checkpoint`` with its CRC recomputed, as an editor of the bytes would (docs/file_format.md:
    a 12-byte header, the postcard payload, its CRC-32C little-endian in the last 4 bytes)."""
    payload = checkpoint[12:-4]
    crc = 0xFFFFFFFF
    for byte in payload:
        crc ^= byte
        for _ in range(8):
            # CRC-32C (Castagnoli, iSCSI): the reflected polynomial 0x82F63B78.
            crc = (crc >> 1) ^ (0x82F63B78 if crc & 1 else 0)
    return checkpoint[:12] + payload + (crc ^ 0xFFFFFFFF).to_bytes(4, "little")
