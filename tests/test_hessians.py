"""Exact second derivatives from closures: Newton's Jacobian assembled from them."""

import math

import numpy as np
import pytest

import varmech
from varmech import examples, scenes

K, A, D, G = 2.0 * 2.0 * 3.0, 3.0 * 4.0, 2.0 * 9.0, 9.80665  # m2·l1·l2, (m1+m2)·l1², m2·l2², g


def hessians(q, v, t):
    """Of the double pendulum (m = (1, 2), l = (2, 3)), δ = θ1 − θ2."""
    s, c = math.sin(q[0] - q[1]), math.cos(q[0] - q[1])
    w = K * v[0] * v[1] * c
    lqq = np.array([[-w - 3.0 * G * 2.0 * math.cos(q[0]), w], [w, -w - 2.0 * G * 3.0 * math.cos(q[1])]])
    lqv = K * s * np.array([[-v[1], -v[0]], [v[1], v[0]]])
    lvv = np.array([[A, K * c], [K * c, D]])
    return lqq, lqv, lvv


def with_hessians(h=hessians):
    base = examples.double_pendulum()
    return varmech.Lagrangian(2, base.lagrangian, dl_dq=base.dl_dq, dl_dv=base.dl_dv, hessians=h, name="exact Jacobian")


@pytest.mark.parametrize("method", ["midpoint", "trapezoid", "galerkin4", "galerkin6"])
def test_exact_hessians_give_the_same_steps_with_fewer_evaluations(method):
    scene = scenes.double_pendulum()
    exact = varmech.integrate(with_hessians(), scene.q0, scene.p0, dt=0.01, steps=200, method=method)
    differenced = varmech.integrate(examples.double_pendulum(), scene.q0, scene.p0, dt=0.01, steps=200, method=method)
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
