# SPDX-License-Identifier: LGPL-2.1-or-later
"""(u, v) points of a scattered layout: scaling and the checks every scattered fit needs.

Shared by the smoothing fit (:mod:`surfcomp.core.compensation.scattered_fit`) and the
Clough-Tocher field (:mod:`surfcomp.core.compensation.scattered_field`); no FreeCAD.
"""

import numpy as np
from scipy.spatial import cKDTree

from ...errors import InputError


def scaled_points(u, v, scale, what="points"):
    """Points ``(u * scale_u, v * scale_v)`` (N, 2) after checking shapes, finiteness and
    scale factors (length per unit parameter, > 0); ``what`` names the points in errors."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    if u.ndim != 1 or u.shape != v.shape:
        raise InputError("u and v of the %s must be 1-D arrays of equal length, got shapes %r "
                         "and %r" % (what, u.shape, v.shape))
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
        k = int(np.flatnonzero(~(np.isfinite(u) & np.isfinite(v)))[0])
        raise InputError("point %d of the %s has a non-finite (u, v) = (%g, %g)"
                         % (k, what, u[k], v[k]))
    su, sv = (float(s) for s in scale)
    if not (su > 0 and sv > 0 and np.isfinite(su) and np.isfinite(sv)):
        raise InputError("scale factors must be finite and > 0 (length per unit parameter), "
                         "got %r" % (scale,))
    return np.stack([u * su, v * sv], axis=1)


def check_spread(x, what, minimum=3):
    """Refuse fewer than ``minimum`` points (N, 2) or points on one line."""
    n = x.shape[0]
    if n < minimum:
        raise InputError("%s: %d points given, at least %d (not on one line) are needed"
                         % (what, n, minimum))
    c = x - x.mean(axis=0)
    sv = np.linalg.svd(c, compute_uv=False)
    if sv[-1] <= 1e-9 * sv[0]:
        raise InputError("%s: the %d points lie on one line in (u, v); a surface field needs "
                         "points spread over the face" % (what, n))


def check_duplicates(x, what):
    """Refuse two points (N, 2) closer than 1e-9 of the larger extent (the same (u, v))."""
    ext = float(np.max(np.ptp(x, axis=0)))
    pairs = cKDTree(x).query_pairs(1e-9 * ext, output_type="ndarray")
    if len(pairs):
        i, j = sorted(pairs[0])
        raise InputError("%s: points %d and %d have the same (u, v); merge or drop duplicate "
                         "measurements first" % (what, i, j))
