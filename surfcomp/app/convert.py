# SPDX-License-Identifier: LGPL-2.1-or-later
"""Conversion between ``Part.BSplineSurface`` and :class:`surfcomp.core.surface.bspline.Surface`."""

import numpy as np

from ..core.memory import collector_paused
from ..core.surface.bspline import Surface, compress_knots
from .face_data import raw_surface


def _flat_knots(knots, mults):
    return np.repeat(np.asarray(knots, dtype=float), np.asarray(mults, dtype=int))


def surface_from_part(bs, u_range=None, v_range=None):
    """Return the core :class:`Surface` of a ``Part.BSplineSurface``.

    Periodic surfaces are converted to non-periodic ones of the same geometry
    (on a copy: the argument is never modified).

    Parameters
    ----------
    bs : Part.BSplineSurface
    u_range, v_range : (float, float), optional
        The face's parameter bounds; default: the surface's own bounds.
    """
    return surface_from_raw(raw_surface(bs), u_range, v_range)


def surface_from_raw(raw, u_range=None, v_range=None):
    """The core :class:`Surface` of a :class:`surfcomp.app.face_data.RawSurface`
    (``u_range``, ``v_range`` as :func:`surface_from_part`)."""
    with collector_paused():
        poles = np.array(raw.poles, dtype=float)
    weights = None if raw.weights is None else np.array(raw.weights, dtype=float)
    ku = _flat_knots(raw.u_knots, raw.u_mults)
    kv = _flat_knots(raw.v_knots, raw.v_mults)
    return Surface(poles, ku, kv, raw.u_degree, raw.v_degree, weights, u_range, v_range)


def surface_to_part(surf):
    """Return a new ``Part.BSplineSurface`` with the geometry of ``surf``."""
    import Part

    ku, mu = compress_knots(surf.knots_u)
    kv, mv = compress_knots(surf.knots_v)
    out = Part.BSplineSurface()
    with collector_paused():
        # nested [x, y, z] lists: much faster than Vectors for millions of poles
        kwargs = dict(poles=surf.poles.tolist(), umults=mu, vmults=mv, uknots=ku, vknots=kv,
                      uperiodic=False, vperiodic=False, udegree=surf.degree_u,
                      vdegree=surf.degree_v)
        if surf.weights is not None:
            kwargs["weights"] = surf.weights.tolist()
        out.buildFromPolesMultsKnots(**kwargs)
    return out
