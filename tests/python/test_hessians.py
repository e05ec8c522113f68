"""Exact second derivatives from closures (examples.double_pendulum supplies them): Newton's
Jacobian assembled from them."""

import numpy as np
import pytest

import varmech
from varmech import examples, scenes


def first_derivatives_only():
    base = examples.double_pendulum()
    return varmech.Lagrangian(2, base.lagrangian, dl_dq=base.dl_dq, dl_dv=base.dl_dv, name="differenced Jacobian")


def with_hessians(h):
    base = examples.double_pendulum()
    return varmech.Lagrangian(2, base.lagrangian, dl_dq=base.dl_dq, dl_dv=base.dl_dv, hessians=h, name="bad hessians")


@pytest.mark.parametrize("method", ["midpoint", "trapezoid", "galerkin4", "galerkin6"])
def test_exact_hessians_give_the_same_steps_with_fewer_evaluations(method):
    scene = scenes.double_pendulum()
    exact = varmech.integrate(examples.double_pendulum(), scene.q0, scene.p0, dt=0.01, steps=200, method=method)
    differenced = varmech.integrate(first_derivatives_only(), scene.q0, scene.p0, dt=0.01, steps=200, method=method)
    native = varmech.integrate(scene, dt=0.01, steps=200, method=method)
    assert np.max(np.abs(exact.q - native.q)) < 1e-12 and np.max(np.abs(exact.q - differenced.q)) < 1e-12
    # One Jacobian a step at least, 2 evaluations per unknown (s·n of them) when differenced.
    unknowns = 2 * (next(m.order for m in varmech.methods() if m.name == method) // 2)  # n = 2, s = order/2
    assert differenced.nfev - exact.nfev >= 2 * unknowns * 200


def test_bad_hessians_are_named():
    scene = scenes.double_pendulum()
    wrong = with_hessians(lambda q, v, t: (np.eye(2), np.eye(3), np.eye(2)))
    with pytest.raises(ValueError, match=r"hessians\(q, v, t\)'s L_qv returned an array of shape \[3, 3\]"):
        varmech.integrate(wrong, scene.q0, scene.p0, dt=0.01, steps=2, method="midpoint")
    with pytest.raises(TypeError, match=r"hessians\(q, v, t\) must return three arrays"):
        varmech.integrate(with_hessians(lambda q, v, t: 1.0), scene.q0, scene.p0, dt=0.01, steps=2, method="midpoint")
