# SPDX-License-Identifier: LGPL-2.1-or-later
"""Checks of a nominal surface read from a user's file, before any numerics run on it.

A hostile or damaged CAD file can hold a surface no numerics should meet: a degree above
OpenCASCADE's limit, a pole of ``1.E400`` (infinite once read) or NaN, weights of zero,
knots that decrease, a face range outside the knot domain. Each is refused here with what
is wrong and what was expected, instead of a NaN deep in the projection or a traceback.
Closed (periodic) surfaces are made non-periodic by the app layer before they get here;
collapsed edges (a sphere's pole, a cone's apex) are valid and handled by
:func:`surfcomp.core.surface.bspline.normals`.
"""

import numpy as np

from ...errors import GeometryError
from ..limits import MAX_DEGREE

#: largest accepted pole coordinate, mm (10 km: beyond any machined part; squares and
#: products of such values stay far from overflow)
MAX_COORDINATE = 1e7
#: largest accepted ratio of the largest to the smallest weight of a rational surface
MAX_WEIGHT_RATIO = 1e12
#: largest accepted number of poles (a 4000 x 4000 net: 384 MB of coordinates)
MAX_POLES = 16_000_000


def _where(array, bad):
    """``'at pole (i, j)'`` of the first True of ``bad`` (shape of ``array[..., 0]``)."""
    idx = np.argwhere(bad)[0]
    return "at pole (%s)" % ", ".join(str(int(i)) for i in idx)


def check_nominal(surf, source=None, what="the nominal surface"):
    """Refuse a surface the numerics cannot work on.

    Parameters
    ----------
    surf : surfcomp.core.surface.bspline.Surface
    source : str, optional
        The file, for the message.

    Raises
    ------
    GeometryError
        Degree outside 1 .. :data:`MAX_DEGREE`; more than :data:`MAX_POLES` poles; a pole,
        weight or knot NaN or infinite; a pole coordinate beyond :data:`MAX_COORDINATE`
        mm; a weight not positive or weights spread beyond :data:`MAX_WEIGHT_RATIO`;
        decreasing knots, an empty knot domain, or a face range outside it.
    """
    def fail(message):
        raise GeometryError("%s %s" % (what, message), file=source)

    for name, d in (("u", surf.degree_u), ("v", surf.degree_v)):
        if not 1 <= d <= MAX_DEGREE:
            fail("has degree %d along %s (expected 1 to %d)" % (d, name, MAX_DEGREE))
    nu, nv = surf.shape
    if nu * nv > MAX_POLES:
        fail("has %d x %d poles (expected at most %d in all)" % (nu, nv, MAX_POLES))
    poles = surf.poles
    finite = np.isfinite(poles).all(axis=-1)
    if not finite.all():
        fail("has a pole that is NaN or infinite %s (expected finite coordinates)"
             % _where(poles, ~finite))
    big = (np.abs(poles) > MAX_COORDINATE).any(axis=-1)
    if big.any():
        fail("has a pole coordinate beyond %g mm %s (expected a part of machinable size)"
             % (MAX_COORDINATE, _where(poles, big)))
    if surf.weights is not None:
        w = surf.weights
        ok = np.isfinite(w) & (w > 0)
        if not ok.all():
            fail("has a weight that is not a positive number %s" % _where(w, ~ok))
        if w.max() > MAX_WEIGHT_RATIO * w.min():
            fail("has weights from %g to %g (expected a ratio below %g)"
                 % (w.min(), w.max(), MAX_WEIGHT_RATIO))
    for name, knots, d, rng in (("u", surf.knots_u, surf.degree_u, surf.u_range),
                                ("v", surf.knots_v, surf.degree_v, surf.v_range)):
        _check_knots(fail, name, knots, d, rng)


def _check_knots(fail, name, knots, degree, rng):
    if not np.isfinite(knots).all():
        fail("has a %s knot that is NaN or infinite" % name)
    if np.any(np.diff(knots) < 0):
        fail("has decreasing %s knots (expected a non-decreasing knot vector)" % name)
    lo, hi = knots[degree], knots[knots.size - degree - 1]
    if not hi > lo:
        fail("has an empty %s knot domain [%g, %g]" % (name, lo, hi))
    a, b = (float(x) for x in rng)
    tol = 1e-9 * max(1.0, hi - lo, abs(lo), abs(hi))
    if not (np.isfinite(a) and np.isfinite(b) and a < b and a >= lo - tol and b <= hi + tol):
        fail("has the face's %s range [%g, %g] outside its knot domain [%g, %g]"
             % (name, a, b, lo, hi))
