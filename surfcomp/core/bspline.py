"""B-spline surfaces as plain numpy arrays (no FreeCAD).

The app layer converts ``Part.BSplineSurface`` to and from :class:`Surface`
(``surfcomp.app.convert``). Everything numeric on surfaces (evaluation,
derivatives, normals, projection) works on this type.
"""

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Surface:
    """A non-periodic (clamped or unclamped) tensor-product B-spline surface.

    Attributes
    ----------
    poles : ndarray, shape (nu, nv, 3)
        Control points in mm, first index along u.
    knots_u, knots_v : ndarray, shape (nu + degree_u + 1,), (nv + degree_v + 1,)
        Flat (expanded) knot vectors, non-decreasing.
    degree_u, degree_v : int
    weights : ndarray, shape (nu, nv), or None
        Rational weights (all > 0); None for a polynomial surface.
    u_range, v_range : tuple of float
        The face's parameter bounds (the work area); defaults to the knot domain
        ``(knots[degree], knots[-degree-1])``.
    """

    poles: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    degree_u: int
    degree_v: int
    weights: np.ndarray = None
    u_range: tuple = field(default=None)
    v_range: tuple = field(default=None)

    def __post_init__(self):
        poles = np.asarray(self.poles, dtype=float)
        ku = np.asarray(self.knots_u, dtype=float)
        kv = np.asarray(self.knots_v, dtype=float)
        object.__setattr__(self, "poles", poles)
        object.__setattr__(self, "knots_u", ku)
        object.__setattr__(self, "knots_v", kv)
        if poles.ndim != 3 or poles.shape[2] != 3:
            raise ValueError("poles must have shape (nu, nv, 3), got %r" % (poles.shape,))
        nu, nv = poles.shape[:2]
        if ku.size != nu + self.degree_u + 1 or kv.size != nv + self.degree_v + 1:
            raise ValueError("knot vector lengths do not match poles and degrees")
        if self.weights is not None:
            w = np.asarray(self.weights, dtype=float)
            if w.shape != (nu, nv) or np.any(w <= 0):
                raise ValueError("weights must be positive with shape (nu, nv)")
            object.__setattr__(self, "weights", w)
        if self.u_range is None:
            object.__setattr__(self, "u_range", (float(ku[self.degree_u]), float(ku[-self.degree_u - 1])))
        if self.v_range is None:
            object.__setattr__(self, "v_range", (float(kv[self.degree_v]), float(kv[-self.degree_v - 1])))

    @property
    def rational(self):
        """True when the surface has non-uniform weights."""
        return self.weights is not None and not np.allclose(self.weights, self.weights.flat[0])

    @property
    def shape(self):
        """(nu, nv): the number of poles along u and v."""
        return self.poles.shape[:2]

    def with_range(self, u_range, v_range):
        """Return a copy whose work area is ``u_range`` x ``v_range``."""
        return Surface(self.poles, self.knots_u, self.knots_v, self.degree_u, self.degree_v,
                       self.weights, tuple(map(float, u_range)), tuple(map(float, v_range)))
