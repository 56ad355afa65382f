# SPDX-License-Identifier: LGPL-2.1-or-later
"""The virtual machining loop's measurement points: the grid nodes or a plan's points, as
the in-memory measurement set :func:`surfcomp.core.compensation.pipeline.prepare` reads (no
FreeCAD)."""

import numpy as np

from ..measurement_set import MeasurementSet
from ..surface import bspline
from ..surface.projection import Projector

#: the source the simulated measurement sets name in messages
SIMULATED = "<simulated measurement>"


def measurement_set(surface, outward, layout, points=None):
    """The measurement set (deviations zero) of the grid nodes, or of ``points`` (P, 3)."""
    b = layout.between
    if points is not None:
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        proj = Projector(surface).project(P)
        return MeasurementSet(nominal=P, normal=proj.normal * outward,
                              deviation=np.zeros(len(P)), source=SIMULATED)
    n, m = layout.grid
    S, Su, Sv = bspline.evaluate_grid(surface, layout.us[::b], layout.vs[::b], order=1)
    nrm = np.cross(Su, Sv)
    nrm *= outward / np.linalg.norm(nrm, axis=-1, keepdims=True)
    rows, cols = np.indices((n, m))
    return MeasurementSet(nominal=S.reshape(-1, 3), normal=nrm.reshape(-1, 3),
                          deviation=np.zeros(n * m), row=rows.ravel(), col=cols.ravel(),
                          source=SIMULATED)


def file_order(prepared, grid_values):
    """Grid (n, m) values back in the measurement set's point order (N,)."""
    out = np.empty(prepared.u.size)
    out[prepared.grid.index.ravel()] = np.asarray(grid_values, dtype=float).ravel()
    return out
