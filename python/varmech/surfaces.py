"""Contact surfaces the core watches natively: φ(q) evaluated in Rust at every step (no Python
call per step), and φ and ∇φ as picklable Python functions for the impact itself.

A :class:`varmech.Contact` whose ``phi`` is one of these (:meth:`varmech.Contact.wall`,
:meth:`varmech.Contact.ellipsoid`) is watched by the core's event of the same name; each
evaluates φ with the same arithmetic in the same order as the core, so a run is the same to the
bit whichever evaluates it. They compare by value and pickle by their parameters, so a scene
with its contacts does too.

Examples
--------
>>> import numpy as np
>>> from varmech.surfaces import Ellipsoid, Gradient
>>> table = Ellipsoid((0, 1), (0.0, 0.0), (2.0, 1.0))   # x²/4 + y² ≤ 1
>>> table(np.array([1.0, 0.5])), Gradient(table)(np.array([1.0, 0.5]))
(0.5, array([-0.5, -1. ]))
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Wall:
    """φ(q) = q_k − ``value``: a wall, floor or side of a box, q_k ≥ ``value`` (the core's
    ``crossing`` event).

    Attributes
    ----------
    k : int
        The coordinate bounded.
    value : float
        The wall's position.
    coordinates : tuple of int
        The coordinates φ depends on, ``(k,)``.
    native : tuple
        The core's event kind and payload, ``("crossing", (k, value))``.

    See Also
    --------
    varmech.Contact.wall : the contact built on it.

    Examples
    --------
    >>> import numpy as np
    >>> from varmech.surfaces import Wall
    >>> floor = Wall(1, 0.5)                      # y ≥ 0.5
    >>> floor(np.array([3.0, 2.0])), floor.gradient(np.array([3.0, 2.0]))
    (1.5, array([0., 1.]))
    """

    k: int
    value: float

    def __call__(self, q: np.ndarray) -> float:
        return float(q[self.k] - self.value)

    @property
    def coordinates(self) -> tuple[int, ...]:
        """The coordinate φ depends on, (k,)."""
        return (self.k,)

    def gradient(self, q: np.ndarray) -> np.ndarray:
        """∇φ = e_k.

        Parameters
        ----------
        q : ndarray, shape (n,)
            The configuration.

        Returns
        -------
        ndarray, shape (n,)
            The unit vector along coordinate k.

        Examples
        --------
        The same unit vector wherever q is, in as many coordinates as q has:

        >>> import numpy as np
        >>> Wall(2, -1.0).gradient(np.array([5.0, 6.0, 7.0])).tolist()
        [0.0, 0.0, 1.0]
        """
        return np.eye(len(q))[self.k]

    @property
    def native(self) -> tuple[str, Any]:
        """The core's event kind and payload."""
        return "crossing", (self.k, self.value)


@dataclass(frozen=True)
class Ellipsoid:
    """φ(q) = s(1 − Σᵢ uᵢ²), uᵢ = (q_{kᵢ} − cᵢ)/aᵢ, over the ``coordinates`` kᵢ with the
    ``centre`` c and ``semi_axes`` a, s = +1 ``inside`` (a billiard table, φ ≥ 0 within) and −1
    outside (an obstacle): the core's ``ellipsoid`` event. The sum runs in the order of the
    coordinates, from 0.

    Attributes
    ----------
    coordinates : tuple of int
        The coordinates kᵢ it bounds (non-negative).
    centre : tuple of float
        The centre c, one entry per coordinate.
    semi_axes : tuple of float
        The semi-axes a, finite and positive, one per coordinate.
    inside : bool, default True
        The side kept: inside (a table, a bowl) or outside (an obstacle).
    native : tuple
        The core's event kind and payload, ``("ellipsoid", (coordinates, centre, semi_axes,
        inside))``.

    Raises
    ------
    ValueError
        ``semi_axes`` not of the length of ``coordinates`` and ``centre`` (or empty), or not
        finite and positive; ``centre`` not finite; ``coordinates`` negative.

    See Also
    --------
    varmech.Contact.ellipsoid : the contact built on it.

    Examples
    --------
    A round obstacle of radius 1 about (2, 0), in coordinates 0 and 1:

    >>> import numpy as np
    >>> from varmech.surfaces import Ellipsoid
    >>> post = Ellipsoid((0, 1), (2.0, 0.0), (1.0, 1.0), inside=False)
    >>> post(np.array([0.0, 0.0])), post.gradient(np.array([0.0, 0.0]))
    (3.0, array([-4.,  0.]))
    """

    coordinates: tuple[int, ...]
    centre: tuple[float, ...]
    semi_axes: tuple[float, ...]
    inside: bool = True

    def __post_init__(self) -> None:
        m = len(self.coordinates)
        if m == 0 or len(self.centre) != m or len(self.semi_axes) != m:
            raise ValueError(
                f"semi_axes: coordinates, centre and semi_axes must be non-empty and of equal length,"
                f" got {m}, {len(self.centre)} and {len(self.semi_axes)}"
            )
        if not all(math.isfinite(a) and a > 0.0 for a in self.semi_axes):
            raise ValueError(f"semi_axes: must be finite and positive, got {self.semi_axes}")
        if not all(math.isfinite(c) for c in self.centre):
            raise ValueError(f"centre: must be finite, got {self.centre}")
        if any(k < 0 for k in self.coordinates):
            raise ValueError(f"coordinates: must be non-negative, got {self.coordinates}")

    def _scaled(self, q: np.ndarray) -> list[float]:
        return [(float(q[k]) - c) / a for k, c, a in zip(self.coordinates, self.centre, self.semi_axes)]

    def __call__(self, q: np.ndarray) -> float:
        total = 0.0
        for u in self._scaled(q):
            total += u * u
        return 1.0 - total if self.inside else total - 1.0

    def gradient(self, q: np.ndarray) -> np.ndarray:
        """∂φ/∂q_{kᵢ} = −2s uᵢ/aᵢ, zero in the other coordinates.

        Parameters
        ----------
        q : ndarray, shape (n,)
            The configuration.

        Returns
        -------
        ndarray, shape (n,)
            ∇φ(q).

        Examples
        --------
        An elliptic table x²/4 + y² ≤ 1 in the first two of three coordinates: at its rim
        (2, 0), ∇φ points inwards, and the third coordinate plays no part.

        >>> import numpy as np
        >>> table = Ellipsoid((0, 1), (0.0, 0.0), (2.0, 1.0))
        >>> table.gradient(np.array([2.0, 0.0, 5.0])).tolist()
        [-1.0, 0.0, 0.0]
        """
        out = np.zeros(len(q))
        sign = -2.0 if self.inside else 2.0
        for k, u, a in zip(self.coordinates, self._scaled(q), self.semi_axes):
            out[k] += sign * u / a
        return out

    @property
    def native(self) -> tuple[str, Any]:
        """The core's event kind and payload."""
        return "ellipsoid", (list(self.coordinates), list(self.centre), list(self.semi_axes), self.inside)


#: A surface the core evaluates.
Surface = Wall | Ellipsoid


@dataclass(frozen=True)
class Gradient:
    """∇φ of a native surface as a function of q, which compares and pickles by its surface.

    Attributes
    ----------
    surface : Wall or Ellipsoid
        The surface whose gradient it evaluates.

    Examples
    --------
    >>> import pickle, numpy as np
    >>> from varmech.surfaces import Gradient, Wall
    >>> grad = Gradient(Wall(0, 0.0))
    >>> grad(np.zeros(2)), pickle.loads(pickle.dumps(grad)) == grad
    (array([1., 0.]), True)
    """

    surface: Surface

    def __call__(self, q: np.ndarray) -> np.ndarray:
        return self.surface.gradient(q)


__all__ = ["Ellipsoid", "Gradient", "Surface", "Wall"]
