"""Kinematics that embed a velocity constraint, as SymPy's rolling disc does: a point C whose
velocity is set to zero (``C.set_vel(N, 0)``) with no position in the inertial frame, about which
a body rolls (its centre's velocity ω × r from ``v2pt_theory(C, N, disc)``, though C is not
fixed in the disc). Kane's equations take that velocity as the rolling it is; L = T − V with it
substituted into T is other dynamics. The import gives the contact its coordinates in the
inertial frame and the rolling its velocity constraints instead."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp
from sympy.physics import mechanics as me

from ._mechanics_check import Draw, value

#: Two velocities are the same where they agree to this, relative to their size, at three random
#: states (evaluated to 30 digits: an identity differs by round-off, a different velocity by O(1)).
SAME = 1e-12


@dataclass
class Contact:
    """The contact point, the body rolling on it, the new coordinates of the point along the
    inertial frame's axes (those it moves along), their rates w(q, q̇) by the rolling, and the
    points placed from it (whose velocities are then its velocity plus their position's rate)."""

    point: Any
    body: Any
    coordinates: list[sp.Expr]
    axes: list[Any]
    rates: list[sp.Expr]
    placed: set[Any]


def _placed(point: Any) -> set[Any]:
    """The points connected to ``point`` by positions (``locatenew``, ``set_pos``)."""
    seen, todo = {point}, [point]
    while todo:
        for other in todo.pop()._pos_dict:
            if other not in seen:
                seen.add(other)
                todo.append(other)
    return seen


def _at_rest(point: Any, frame: Any) -> bool:
    """Whether ``point``'s velocity in ``frame`` is set to zero."""
    return frame in point._vel_dict and point._vel_dict[frame] == me.Vector(0)


class _Same:
    """Whether expressions in q̇ vanish, or vectors are equal, at three random states."""

    def __init__(self, frame: Any, q: Sequence[sp.Expr]) -> None:
        t = me.dynamicsymbols._t
        self.frame, self.draw = frame, Draw(None, seed=1)
        self.states = [{**{x: self.draw.number(0.2, 1.2) for x in q}, **{x.diff(t): self.draw.number(-1.0, 1.0) for x in q}} for _ in range(3)]

    def size(self, expr: Any) -> float:
        """The largest entry of ``expr`` (a Matrix) at the states, at least 1."""
        return max([1.0, *(float(np.abs(value(expr, self.draw.point([expr], s))).max(initial=0.0)) for s in self.states)])

    def zero(self, expr: Any, scale: float = 1.0) -> bool:
        """Whether ``expr`` (a Matrix) vanishes at the states, to SAME times ``scale``."""
        return all(np.abs(value(expr, self.draw.point([expr], s))).max(initial=0.0) <= SAME * scale for s in self.states)

    def equal(self, a: Any, b: Any) -> bool:
        first, second = a.to_matrix(self.frame), b.to_matrix(self.frame)
        return self.zero(first - second, max(self.size(first), self.size(second)))


def find(bodies: Sequence[Any], frame: Any, q: Sequence[sp.Expr], speeds: Mapping[sp.Expr, sp.Expr]) -> tuple[Contact | None, str]:
    """The rolling contact of the bodies' kinematics, if they embed one; otherwise None, with a
    note on a velocity that embeds a constraint of another kind ("" if none does)."""
    same = _Same(frame, q)
    embedding: list[tuple[Any, list[Any]]] = []
    for body in bodies:
        centre = body.masscenter
        fixed = [p for p in _placed(centre) if _at_rest(p, frame)]
        try:
            velocity = centre.vel(frame).xreplace(speeds)
        except ValueError:
            continue  # no velocity: Kane's equations cannot be formed either, and the check says so
        if fixed and not any(same.equal(velocity, centre.pos_from(p).dt(frame).xreplace(speeds)) for p in fixed):
            embedding.append((body, fixed))
    if not embedding:
        return None, ""
    points = {p for _, fixed in embedding for p in fixed}
    if len(points) == 1 and all(len(fixed) == 1 for _, fixed in embedding):
        (point,) = points
        for body in bodies:
            if isinstance(body, me.RigidBody) and point in _placed(body.masscenter):
                r = body.masscenter.pos_from(point)
                omega = body.frame.ang_vel_in(frame)
                if same.equal(body.masscenter.vel(frame).xreplace(speeds), omega.cross(r).xreplace(speeds)):
                    return _contact(point, body, frame, q, speeds, same), ""
    body, fixed = embedding[0]
    return None, (
        f"; its kinematics embed a velocity constraint: body {body.name}'s centre has a velocity that is not the rate of "
        f"its position from {', '.join(sorted(p.name for p in fixed))} (whose velocity is set to zero), nor that of a "
        "body rolling about such a point, and L(q, q̇, t) takes such a velocity as a constraint substituted into T. "
        "Give the point its coordinates in the inertial frame (C = O.locatenew('C', x*N.x + y*N.y) from a fixed O, "
        "with x, y among the coordinates) and the constraint as velocity_constraints (the contact point's velocity "
        "components in the coordinates' rates)"
    )


def _contact(point: Any, body: Any, frame: Any, q: Sequence[sp.Expr], speeds: Mapping[sp.Expr, sp.Expr], same: _Same) -> Contact:
    """The contact ``point`` of the rolling ``body``: its velocity w = ω × r − ṙ (r from it to
    the body's centre) in q̇, and a coordinate along each axis of ``frame`` that w moves it along."""
    r = body.masscenter.pos_from(point)
    w = (body.frame.ang_vel_in(frame).cross(r) - r.dt(frame)).xreplace(speeds)
    names = {x.func.__name__ for x in q}
    coordinates, axes, rates = [], [], []
    scale = same.size(w.to_matrix(frame))
    for index, axis in zip(frame.indices, [frame.x, frame.y, frame.z]):
        rate = sp.sympify(w.dot(axis))
        if same.zero(sp.Matrix([rate]), scale):
            continue  # the rolling holds the point still along this axis
        name = f"{point.name}_{index}"
        if name in names:
            raise ValueError(f"system: the contact {point.name}'s coordinate {name} is the name of one of its coordinates; rename it")
        coordinates.append(me.dynamicsymbols(name))
        axes.append(axis)
        rates.append(rate)
    return Contact(point, body, coordinates, axes, rates, _placed(point))


def velocity(contact: Contact, frame: Any) -> Any:
    """The velocity in ``frame`` of a point: for one placed from the contact, the contact's
    velocity (its coordinates' rates) plus the rate of its position from it; for the contact
    itself, that of the rolling body's material point there (zero by the rolling); for any
    other point, its own."""
    t = me.dynamicsymbols._t
    moving = sum((x.diff(t) * axis for x, axis in zip(contact.coordinates, contact.axes)), me.Vector(0))

    def of(point: Any) -> Any:
        if point not in contact.placed:
            return point.vel(frame)
        centre = contact.body.masscenter
        if point is contact.point:
            return moving + centre.pos_from(contact.point).dt(frame) + contact.body.frame.ang_vel_in(frame).cross(contact.point.pos_from(centre))
        return moving + point.pos_from(contact.point).dt(frame)

    return of
