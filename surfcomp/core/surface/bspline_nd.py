# SPDX-License-Identifier: LGPL-2.1-or-later
"""Surface points by scipy's compiled tensor-product B-spline, where the installed scipy
has it (no FreeCAD).

``scipy.interpolate.NdBSpline`` (scipy 1.12 and later: Debian 13 and sid have it, Debian
12's scipy 1.10 does not) evaluates a tensor-product spline in compiled code. Which
evaluator runs is decided by what the installed scipy has (:func:`ndbspline`), never by a
version number. ``bench/bench_basis.py`` measured it beside the hand-written evaluation
(:func:`surfcomp.core.surface.bspline.evaluate` without it): faster for points on scipy 1.15 and
1.17 (1.3 and 3.5 times), slower for derivatives on 1.15 (0.56 times for the first, 0.33
for the second, 1.4 times faster on 1.17), so :func:`surfcomp.core.surface.bspline.evaluate` uses
it for points only. Rational faces
are evaluated in homogeneous coordinates and divided, as the hand-written path does;
outside the knot domain both extrapolate the end polynomial pieces.
"""

import functools

from .bspline_basis import SCIPY_FROM


@functools.cache
def ndbspline():
    """``scipy.interpolate.NdBSpline`` when the installed scipy has it, else None (imported
    on the first call: ``scipy.interpolate`` is slow to import, see
    :data:`surfcomp.core.surface.bspline_basis.SCIPY_FROM`)."""
    import scipy.interpolate

    return getattr(scipy.interpolate, "NdBSpline", None)


def point_evaluator(surf, Pw, count=None):
    """A function ``(xi (n, 2)) -> (n, 3)`` giving points of ``surf`` (homogeneous poles
    ``Pw`` for rational faces, else its poles) by :func:`ndbspline`, or None without it, or
    for ``count`` points fewer than :data:`~surfcomp.core.surface.bspline_basis.SCIPY_FROM`
    (where the import would cost more than the compiled evaluation saves)."""
    if count is not None and count < SCIPY_FROM:
        return None
    nd = ndbspline()
    if nd is None:
        return None
    spline = nd((surf.knots_u, surf.knots_v), Pw, (surf.degree_u, surf.degree_v),
                       extrapolate=True)
    if surf.weights is None:
        return spline
    def rational(xi):
        A = spline(xi)
        return A[:, :3] / A[:, 3:4]
    return rational
