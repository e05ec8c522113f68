"""Every built-in scene over the parameters a user may pass gets an honest verdict (issue 64).

Each scene runs at its own step and horizon (shortened to 10⁶ steps where longer, to keep
this file within about 30 s) with the energy check off, and is judged by ``check_conservation``:

- a "failed" quantity is honest only where the run at h/2 fails too (the step does not resolve
  the motion); a run whose refinement converges must not fail;
- an impact scene's balance E − W (W the laws' losses, ``traj.work``) closes to round-off for
  e < 1 (verlet is exact on the parabolas and every impact is located to round-off), and its
  energy, elastic, to round-off or at the method's order (the variational law's O(h²) jumps);
- a momentum that a contact, its friction or a force pushes along is reported not judged,
  naming what pushes it, and the others are judged.

The bouncing ball's own step resolves its tenth flight, 2e⁹t₁/50: 3.5e-14 at e = 0.05 (10¹³
steps); there the sweep takes t_end/4000, which holds the balance all the same (the contact
closes at the limit of its Zeno series).
"""

import math

import pytest

import varmech
from varmech import scenes
from varmech.conservation import NOT_JUDGED

#: The parameters swept, over each scene's documented ranges (defaults included).
SWEEP: dict[str, list[dict[str, float]]] = {
    "harmonic_oscillator": [{"omega": w} for w in (0.5, 1.0, 4.0)],
    "pendulum": [{}],
    "kepler": [{"e": e} for e in (0.0, 0.3, 0.6, 0.9)],
    "henon_heiles": [{}],
    "fermi_pasta_ulam": [{}],
    "outer_solar_system": [{}],
    "double_pendulum": [{}],
    "spherical_pendulum": [{}],
    "heavy_top": [{}],
    "kepler_polar": [{"e": e} for e in (0.0, 0.6, 0.9)],
    "charged_particle": [{"B": b} for b in (0.0, 1.0, -3.0)],
    "charged_particle_nonuniform": [{}],
    "damped_driven_pendulum": [
        {"gamma": g, "amplitude": a, "drive": d} for g in (0.0, 0.5, 2.0) for a in (0.0, 1.5) for d in (2 / 3, 2.0)
    ],
    "cartesian_pendulum": [{}],
    "cartesian_spherical_pendulum": [{}],
    "planar_chain": [{"links": k} for k in (1, 2, 8)],
    "rigid_body": [{}],
    "bouncing_ball": [{"restitution": e} for e in (0.05, 0.3, 0.8, 1.0)] + [{"restitution": 0.8, "h0": 3.0, "g": 1.62}],
    "elliptic_billiard": [
        {},
        {"A": 1.0, "B": 1.0},
        {"A": 3.0, "B": 1.0, "x0": -2.0, "y0": 0.5, "px0": 1.0, "py0": -0.3},
        {"x0": 0.0, "y0": 0.0, "px0": 1.0, "py0": 0.0},
    ],
    "rolling_disk": [{"radius": r, "turn": t, "roll": o} for r, t, o in ((1.0, 0.7, 2.0), (0.3, -2.0, 0.0), (2.0, 0.1, 5.0))],
    "chaplygin_sleigh": [
        {"inertia": i, "blade": b, "spin": s} for i, b, s in ((1.0, 1.0, 1.0), (0.2, 2.0, -3.0), (5.0, 0.3, 0.5), (1.0, 1.0, 0.0))
    ],
    "rolling_sphere": [{"alpha": a} for a in (0.0, 0.5, 1.2)] + [{"vx0": 0.0, "vy0": 0.0, "spin": 0.0}],
    "ball_on_turntable": [
        {},
        {"omega": 0.5, "radius": 0.2, "x0": -1.0, "y0": 2.0, "vx0": 0.3, "vy0": -0.1, "spin": -2.0},
        {"omega": 3.0, "x0": 0.0, "y0": 0.0},
    ],
}

CASES = [(name, params) for name, sets in SWEEP.items() for params in sets]
MOST_STEPS = 1_000_000
ORDER = {m.name: m.order for m in varmech.methods()}


def test_the_sweep_covers_every_scene_of_the_catalogue():
    assert set(SWEEP) == set(scenes.CATALOGUE)


def _run(scene: scenes.Scene, dt: float) -> varmech.Trajectory:
    steps = min(round(scene.t_end / dt), MOST_STEPS)
    return varmech.integrate(scene, dt=dt, steps=steps, save_every=max(1, steps // 4000), max_energy_error=None, progress=False)


def _step(name: str, scene: scenes.Scene) -> float:
    return max(scene.dt, scene.t_end / 4000) if name == "bouncing_ball" else scene.dt


@pytest.mark.parametrize(("name", "params"), CASES, ids=[f"{n}-{'-'.join(f'{k}={v:g}' for k, v in p.items())}" for n, p in CASES])
def test_every_scene_over_its_parameters_gets_an_honest_verdict(name, params):
    scene = scenes.get(name, **params)
    dt = _step(name, scene)
    traj = _run(scene, dt)
    report = varmech.check_conservation(traj)
    failed = [q.name for q in report.quantities if q.verdict == "failed"]
    if failed:
        # Honest only where the step does not resolve the motion: h/2 fails too.
        finer = varmech.check_conservation(_run(scene, dt / 2))
        assert all(q.verdict == "failed" for q in finer.quantities if q.name in failed), (report, finer)
    for m in report.momenta:
        if m.verdict == NOT_JUDGED:
            assert "can push along ξ" in m.advice and ("contact" in m.advice or "force" in m.advice), m
    if scene.contacts:
        energy = report.energy
        if all(c.restitution == 1.0 and c.friction is None for c in scene.contacts):
            assert energy.name == "energy", report
            if energy.verdict != "conserved to round-off":
                # The variational law's jumps: O(h²), at verlet's order.
                finer = varmech.check_conservation(_run(scene, dt / 2)).energy
                order = math.log2(energy.max_abs_error / finer.max_abs_error)
                assert order > ORDER[traj.method] - 0.5, (order, energy, finer)
        else:
            # Each impact's loss, −(1 − e²)/2 (n·q̇)²/(nᵀM⁻¹n), in W: E − W to round-off.
            assert energy.name == "energy balance" and energy.verdict == "conserved to round-off", report
            assert energy.max_abs_error <= energy.round_off
