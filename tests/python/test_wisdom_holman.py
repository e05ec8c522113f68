"""The Wisdom–Holman methods through the Python API: listed, integrating the N-body scenes, and
refusing other models."""

import numpy as np
import pytest

import varmech
from varmech import scenes


def test_the_wisdom_holman_methods_are_listed_as_nbody_methods():
    nbody = {m.name: m for m in varmech.methods() if m.nbody}
    assert set(nbody) == {"wh", "whc", "whckl"}
    assert nbody["whckl"].order == 4 and nbody["whckl"].force_evaluations == 2
    assert all(m.symplectic and not m.constrained and not m.implicit for m in nbody.values())
    kind = scenes.get("outer_solar_system").model.kind
    assert kind.name == "gravitational" and kind.separable and kind.admits("whc") and kind.admits("verlet")


def test_whc_reaches_the_outer_solar_system_reference_and_saving_does_not_change_it():
    """whc over 500 000 days at h = 100 days ends 5.02e-6 AU from HLW's reference state (measured;
    WHFast with corrector=11 gives the same), whatever states are kept on the way."""
    scene = scenes.get("outer_solar_system")
    steps = 5000
    sparse = varmech.integrate(scene, method="whc", dt=100.0, steps=steps, save_every=steps)
    error = np.linalg.norm(sparse.q[-1] - scene.reference.q)
    assert error == pytest.approx(5.02e-6, rel=0.01)
    dense = varmech.integrate(scene, method="whc", dt=100.0, steps=steps, save_every=7)
    np.testing.assert_array_equal(dense.q[-1], sparse.q[-1])
    np.testing.assert_array_equal(dense.p[-1], sparse.p[-1])


def test_the_wisdom_holman_methods_refuse_other_models():
    with pytest.raises(ValueError, match="^method: whc integrates the gravitational N-body problem alone"):
        varmech.integrate(scenes.get("kepler"), method="whc", dt=0.01, steps=10)
