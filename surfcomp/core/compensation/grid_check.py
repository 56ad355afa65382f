# SPDX-License-Identifier: LGPL-2.1-or-later
"""Can a measurement grid's correction field be placed over the whole face? (no FreeCAD)

The grid route's field (:class:`surfcomp.core.compensation.field.GridField`) maps grid indices to
the face's (u, v) and, to build the corrected face, inverts that map at samples over the whole
face, the parts beyond the measured region included (there the map is continued). A grid
found in nearly-regular points can be so sheared (a staggered layout read as twice as many
rows, neighbouring rows a fraction of a cell apart and offset half a row along) that the
inversion does not converge. :func:`unlocatable` tries the inversion on a coarse sample of
the face before the grid is accepted, so such points take the scattered route with the
reason stated instead of failing half way through the compensation. The coarse sample
cannot foresee every sample of the corrected face: :func:`as_scattered` turns a grid that
fails one of those into the scattered route too (``pipeline.compensate`` makes the
compensation again), so near-grid points never end in that ComputationError.
"""

from dataclasses import replace

import numpy as np

from ...errors import ComputationError, GridError
from ..surface.grid import Scattered
from .field import GridField

#: samples per direction of the face on which the grid's map is inverted
SAMPLES = 33


def unlocatable(grid, u, v, u_range, v_range):
    """None when every sample of the face ``u_range x v_range`` (SAMPLES per side) is
    located on the grid's map of the points' ``u``, ``v``; else the reason (text)."""
    index = grid.index
    field = GridField(np.asarray(u, dtype=float)[index], np.asarray(v, dtype=float)[index],
                      np.zeros(index.shape))
    us = np.linspace(u_range[0], u_range[1], SAMPLES)
    vs = np.linspace(v_range[0], v_range[1], SAMPLES)
    try:
        field.locate_grid(us, vs)
    except ComputationError as exc:
        return ("the %d x %d grid found in the points (%s) is too distorted for the grid "
                "route: %s" % (index.shape + (grid.rows_from, exc)))
    return None


def as_scattered(prepared, options, exc):
    """``prepared`` with its grid given up for the scattered route after the grid's map
    could not be inverted at a sample of the face while the corrected face was built
    (``exc``, a ComputationError from :mod:`surfcomp.core.compensation.field`); None when that is
    not the case or ``--layout grid`` was asked for (then a GridError with the reason)."""
    if isinstance(prepared.grid, Scattered) or "on the measurement grid" not in str(exc):
        return None
    why = ("the %d x %d grid found in the points (%s) is too distorted for the grid route: %s"
           % (prepared.grid.shape + (prepared.grid.rows_from, exc)))
    if options.layout == "grid":
        raise GridError("%s (expected a grid whose map to the face can be inverted; layout "
                        "'scattered' uses the points as they are)" % why, file=prepared.source,
                        options=("layout",))
    # the warning goes into the caller's list too (the reports read it from there)
    where = "%s: " % prepared.source if prepared.source else ""
    prepared.warnings.append("%s%s; the points are used as a scattered layout" % (where, why))
    return replace(prepared, grid=Scattered(np.arange(prepared.u.size),
                                            "scattered (grid too distorted)"))
