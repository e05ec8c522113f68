"""Measurement tools: each returns a :class:`~varmech.Table` that :mod:`varmech.charts` draws.

- :mod:`.work_precision`: cost against accuracy over a sweep of steps and tolerances;
- :mod:`.energy_growth`: the energy error over a long run, log-spaced in t, with verdicts;
- :mod:`.baselines`: SciPy's ``solve_ivp`` and REBOUND driven on a varmech scene;
- :mod:`.stability`: linear stability on q̈ = −ω²q, the implicit methods' failure regions, and a
  model's spectrum against the stability intervals;
- :mod:`.sections`: Poincaré sections and orbit divergence (a chaos indicator);
- :mod:`.lyapunov`: Lyapunov spectra from the step's tangent map;
- :mod:`.strobe`: stroboscopic sections of time-periodic models and orbit diagrams;
- :mod:`.phase_portrait`: orbits of one degree of freedom, librations and rotations;
- :mod:`.nonholonomic`: a rolling disk's energy over a long run, the discrete
  Lagrange–d'Alembert integrators against RK4 with a velocity projection.

Every sweep honours Ctrl-C: the KeyboardInterrupt propagates with the rows measured so far as
``err.partial`` (:func:`._interrupt.interruptible`).
"""

__all__: list[str] = []  # internal: importable, not part of the public API
