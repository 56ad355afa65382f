# SPDX-License-Identifier: LGPL-2.1-or-later
"""The large-N smoothing fit as a field over the face's (u, v) (no FreeCAD).

The P-spline fit of scattered deviations (:mod:`surfcomp.core.compensation.pspline`) is a cubic
tensor-product B-spline on a uniform knot grid over the points' bounding box. With the
``filtered`` method its values at the points are the intended corrections, so the
corrected face can be built from the spline itself (:func:`surfcomp.core.compensation.corrected.
construct_smooth`) instead of from a field through a million point values: its knots
are few (at most :data:`~surfcomp.core.compensation.pspline.PSPLINE_MAX_COEFFS` coefficients), and a
space holding the nominal's knots and the fit's reproduces it.

:class:`CellSpline`
    The spline as one bicubic polynomial per knot cell, evaluated with its gradient.
:class:`SplineField`
    The spline over face parameters with the continuation the grid field has
    (:mod:`surfcomp.core.compensation.field`): beyond the knot box the field continues from its
    border value with its border slope damped as ``g L tanh(e / L)`` (``L`` one knot
    span), C1 across the border; and it is limited softly to plus or minus the largest
    value at the points, ``M + w tanh((f - M) / w)`` above ``M`` (likewise below
    ``-M``), C2, at most ``w`` = :data:`SOFT_LIMIT` beyond, so no correction exceeds the
    largest intended one by more than that. (A limit at the values' range instead of
    their largest magnitude would bend the continuation wherever it passes the smallest
    value, within ``w`` / slope of the border: a corner no span of the corrected face
    follows, 0.56 um off at the points on the example face against 0.002 um.)
"""

import numpy as np

#: points per pass of the evaluation loops (bounds the temporaries)
CHUNK = 1 << 17
#: how far (mm) the field may go beyond the range of its values at the points
SOFT_LIMIT = 2.5e-4


def powers(s, count=4):
    """The powers 1, s, ..., s^(count-1) of ``s`` (count, M)."""
    out = np.empty((count, s.size))
    out[0] = 1.0
    for k in range(1, count):
        out[k] = out[k - 1] * s
    return out


def _dpowers(s):
    """Derivatives of the powers 1, s, s^2, s^3."""
    return np.stack([np.zeros_like(s), np.ones_like(s), 2.0 * s, 3.0 * s * s])


def uniform_locate(lo, hi, spans, t):
    """Span index and local coordinate in [0, 1] of ``t`` on a uniform knot grid of
    ``spans`` spans over [lo, hi] (clamped to the first and last span)."""
    i = np.clip(np.floor((t - lo) * (spans / (hi - lo))).astype(np.intp), 0, spans - 1)
    h = (hi - lo) / spans
    return i, (t - (lo + i * h)) / h


class CellSpline:
    """A cubic tensor spline on uniform knot grids over ``[lo, hi]`` (2,) as bicubic
    polynomials per cell: ``P[i, j, k, l]`` multiplies ``s^k t^l`` on cell (i, j)
    (``s``, ``t`` local coordinates in [0, 1]).

    Parameters
    ----------
    cu, cv : ndarray, shape (spans, 4, 4)
        Power coefficients of the cubic basis functions per span (see
        :func:`surfcomp.core.compensation.pspline.span_polynomials`).
    coefficients : ndarray, shape (nsu + 3, nsv + 3)
    lo, hi : array_like, shape (2,)
        The knot box.
    """

    def __init__(self, cu, cv, coefficients, lo, hi):
        nsu, nsv = cu.shape[0], cv.shape[0]
        i = np.arange(nsu)[:, None] + np.arange(4)
        j = np.arange(nsv)[:, None] + np.arange(4)
        net = coefficients[i[:, None, :, None], j[None, :, None, :]]     # (nsu, nsv, 4, 4)
        self.P = np.einsum("ika,ijab,jlb->ijkl", cu, net, cv,
                           optimize=True).reshape(nsu * nsv, 4, 4)
        self.spans = (nsu, nsv)
        self.lo, self.hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)

    @property
    def width(self):
        """Knot span length along each direction (2,)."""
        return (self.hi - self.lo) / np.array(self.spans)

    def knots(self, axis):
        """The distinct knots along ``axis`` (0 or 1)."""
        return np.linspace(self.lo[axis], self.hi[axis], self.spans[axis] + 1)

    def values(self, x, gradient=False):
        """Values at points ``x`` (M, 2) (cells beyond the box continue their polynomial);
        with ``gradient`` also ``(values, d/dx0, d/dx1)``."""
        m = x.shape[0]
        out = np.empty((3 if gradient else 1, m))
        h = self.width
        for a in range(0, m, CHUNK):
            iu, s = uniform_locate(self.lo[0], self.hi[0], self.spans[0], x[a:a + CHUNK, 0])
            iv, t = uniform_locate(self.lo[1], self.hi[1], self.spans[1], x[a:a + CHUNK, 1])
            Q = self.P[iu * self.spans[1] + iv]                            # (c, 4, 4)
            S, T = powers(s), powers(t)
            out[0, a:a + CHUNK] = np.einsum("kc,ckl,lc->c", S, Q, T)
            if gradient:
                out[1, a:a + CHUNK] = np.einsum("kc,ckl,lc->c", _dpowers(s), Q, T) / h[0]
                out[2, a:a + CHUNK] = np.einsum("kc,ckl,lc->c", S, Q, _dpowers(t)) / h[1]
        return tuple(out) if gradient else out[0]


class SplineField:
    """The smoothing fit's spline as a field over face parameters (see the module
    docstring): ``field(u, v)`` in mm, bounded, C1.

    Parameters
    ----------
    spline : CellSpline
        Over the scaled plane ``(u * scale_u, v * scale_v)``.
    scale : (float, float)
    value_range : (float, float)
        The soft limits (see the module docstring).
    """

    def __init__(self, spline, scale, value_range):
        self.spline = spline
        self.scale = np.array([float(s) for s in scale])
        self.value_range = (float(value_range[0]), float(value_range[1]))

    def knots(self, axis):
        """The spline's distinct knots along u (0) or v (1) in face parameters."""
        return self.spline.knots(axis) / self.scale[axis]

    @property
    def box(self):
        """``((u0, u1), (v0, v1))``: the knot box in face parameters (the field is a cubic
        spline inside, C1 beyond)."""
        return tuple((self.spline.lo[k] / self.scale[k], self.spline.hi[k] / self.scale[k])
                     for k in (0, 1))

    def __call__(self, u, v):
        shape = np.shape(u)
        x = np.stack([np.ravel(u) * self.scale[0], np.ravel(v) * self.scale[1]], axis=1)
        sp = self.spline
        inside = np.clip(x, sp.lo, sp.hi)
        beyond = x - inside
        if np.any(beyond):
            f, fu, fv = sp.values(inside, gradient=True)
            L = sp.width
            f = (f + fu * L[0] * np.tanh(beyond[:, 0] / L[0])
                 + fv * L[1] * np.tanh(beyond[:, 1] / L[1]))
        else:
            f = sp.values(x)
        return soft_limit(f, *self.value_range).reshape(shape)


def soft_limit(f, lo, hi, width=SOFT_LIMIT):
    """``f`` inside [lo, hi]; beyond, ``hi + width tanh((f - hi) / width)`` (and the same
    below ``lo``): C2, never more than ``width`` beyond the range."""
    f = np.asarray(f, dtype=float)
    out = f.copy()
    above, below = f > hi, f < lo
    out[above] = hi + width * np.tanh((f[above] - hi) / width)
    out[below] = lo - width * np.tanh((lo - f[below]) / width)
    return out


class ConstantField:
    """A uniform correction (the ``offset`` method, a constant ``delta``) as a field with
    no knots of its own, for :func:`surfcomp.core.compensation.corrected.construct_smooth`: the
    face is the nominal's space, split only where the offset surface needs it."""

    #: smooth everywhere: checked over the whole work area
    box = None

    def __init__(self, value):
        self.value = float(value)

    def knots(self, axis):
        return np.empty(0)

    def __call__(self, u, v):
        return np.full(np.shape(u), self.value)

