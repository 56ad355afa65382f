# SPDX-License-Identifier: LGPL-2.1-or-later
"""The text of a measurement plan file (no FreeCAD).

``csv``
    The measurement-file contract of :mod:`surfcomp.io.measurements`: ``#`` comment lines
    saying how the plan was made, then the header ``id,x_nom,y_nom,z_nom,i,j,k`` and one
    row per point in visiting order: its name, the nominal surface point (mm, 6 decimals)
    and the outward unit normal (9 decimals). :func:`surfcomp.io.measurements.read_measurements`
    reads it back (nominal points, normals and ids; no deviation: nothing is measured yet).
``xyzijk``
    A PC-DMIS nominal point file, as :mod:`surfcomp.io.pointfiles` reads it: line 1
    ``XYZIJK    METRIC`` (``XYZIJK`` in columns 1-6, ``METRIC`` in columns 11-16), then
    ``X,Y,Z,I,J,K`` per point, in mm, in visiting order (the format has no names and no
    comments).
"""

import numpy as np

from ..core.choices import PLAN_FORMATS  # noqa: F401  (the option registry's choices)
from ..errors import InputError

#: the header of the plan's CSV
CSV_HEADER = "id,x_nom,y_nom,z_nom,i,j,k"


def plan_text(fmt, ids, points, normals, comments=()):
    """The plan file's text.

    Parameters
    ----------
    fmt : {'csv', 'xyzijk'}
    ids : list of str
        Point names (csv only), without commas.
    points, normals : array_like (N, 3)
        Nominal points (mm) and outward unit normals.
    comments : iterable of str
        Lines written as ``# ...`` before the csv header (ignored for xyzijk).
    """
    P = np.asarray(points, dtype=float)
    n = np.asarray(normals, dtype=float)
    if fmt not in PLAN_FORMATS:
        raise InputError("fmt %r: expected one of %s" % (fmt, ", ".join(PLAN_FORMATS)),
                         options=("fmt",))
    if P.shape != n.shape or P.ndim != 2 or P.shape[1] != 3:
        raise InputError("points and normals must both have shape (N, 3), got %r and %r"
                         % (P.shape, n.shape))
    rows = np.column_stack([P, n])
    if fmt == "xyzijk":
        body = ["%.6f,%.6f,%.6f,%.9f,%.9f,%.9f" % tuple(r) for r in rows]
        return "\n".join(["XYZIJK    METRIC"] + body) + "\n"
    if len(ids) != len(P) or any("," in str(i) or not str(i).strip() for i in ids):
        raise InputError("every plan point needs a name without commas (%d names for %d points)"
                         % (len(ids), len(P)))
    head = ["# " + c for c in comments] + [CSV_HEADER]
    body = ["%s,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f" % ((i,) + tuple(r)) for i, r in zip(ids, rows)]
    return "\n".join(head + body) + "\n"


def dropped_text(rows):
    """CSV of the points a plan left out: ``index,reason,u,v,x,y,z`` per row of ``rows``
    (``(layout index, reason text, u, v, (x, y, z))``); ``index`` is 1-based in the layout."""
    out = ["index,reason,u,v,x,y,z"]
    for k, why, u, v, p in rows:
        out.append("%d,%s,%.9g,%.9g,%.6f,%.6f,%.6f" % ((k + 1, why.replace(",", ";"), u, v)
                                                      + tuple(p)))
    return "\n".join(out) + "\n"
