# SPDX-License-Identifier: LGPL-2.1-or-later
"""Can a measurement grid's correction field be placed over the whole face? (no FreeCAD)

The grid route's field (:class:`surfcomp.core.field.GridField`) maps grid indices to the
face's (u, v) and, to build the corrected face, inverts that map at samples over the whole
face, the parts beyond the measured region included (there the map is continued). A grid
found in nearly-regular points can be so sheared (a staggered layout read as twice as many
rows, neighbouring rows a fraction of a cell apart and offset half a row along) that the
inversion does not converge. :func:`unlocatable` tries the inversion on a coarse sample of
the face before the grid is accepted, so such points take the scattered route with the
reason stated instead of failing half way through the compensation.
"""

import numpy as np

from ..errors import ComputationError
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
