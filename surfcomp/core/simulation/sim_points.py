# SPDX-License-Identifier: LGPL-2.1-or-later
"""The virtual machining loop's measurement points: the grid nodes or a plan's points, as
the in-memory measurement set :func:`surfcomp.core.compensation.pipeline.prepare` reads (no
FreeCAD)."""

from dataclasses import dataclass, field

import numpy as np

from ..surface import bspline
from ..surface.projection import Projector


@dataclass
class GridMeasurements:
    """A measurement set built in memory, with the attributes of
    :class:`surfcomp.io.measurements.MeasurementSet` that :func:`pipeline.prepare` reads
    (core does not import io): nominal points and outward normals (N, 3), deviations
    (N,), grid indices ``row``/``col`` (N,)."""

    nominal: np.ndarray
    normal: np.ndarray
    deviation: np.ndarray
    row: np.ndarray
    col: np.ndarray
    measured: np.ndarray = None
    source: str = "<simulated measurement>"
    warnings: list = field(default_factory=list)
    lines: np.ndarray = None

    def __post_init__(self):
        if self.lines is None:
            self.lines = np.arange(1, len(self.nominal) + 1, dtype=np.int64)

    def __len__(self):
        return len(self.lines)


def measurement_set(surface, outward, layout, points=None):
    """The measurement set (deviations zero) of the grid nodes, or of ``points`` (P, 3)."""
    b = layout.between
    if points is not None:
        P = np.asarray(points, dtype=float).reshape(-1, 3)
        proj = Projector(surface).project(P)
        return GridMeasurements(nominal=P, normal=proj.normal * outward,
                                deviation=np.zeros(len(P)), row=None, col=None)
    n, m = layout.grid
    S, Su, Sv = bspline.evaluate_grid(surface, layout.us[::b], layout.vs[::b], order=1)
    nrm = np.cross(Su, Sv)
    nrm *= outward / np.linalg.norm(nrm, axis=-1, keepdims=True)
    rows, cols = np.indices((n, m))
    return GridMeasurements(nominal=S.reshape(-1, 3), normal=nrm.reshape(-1, 3),
                            deviation=np.zeros(n * m), row=rows.ravel(), col=cols.ravel())


def file_order(prepared, grid_values):
    """Grid (n, m) values back in the measurement set's point order (N,)."""
    out = np.empty(prepared.u.size)
    out[prepared.grid.index.ravel()] = np.asarray(grid_values, dtype=float).ravel()
    return out
