# SPDX-License-Identifier: LGPL-2.1-or-later
"""The three linear axes of a 3-axis machine: names and point arrays (no FreeCAD)."""

import numpy as np

from ...errors import InputError

#: the three axes, in order
AXES = ("x", "y", "z")


def axis_index(name):
    """0, 1 or 2 for ``'x'``, ``'y'``, ``'z'`` (any case, blanks ignored).

    Raises
    ------
    InputError
        Any other name.
    """
    key = str(name).strip().lower()
    if key not in AXES:
        raise InputError("axis must be one of x, y, z (got %r)" % (name,))
    return AXES.index(key)


def as_points(points):
    """``points`` as a float array of shape (..., 3) (mm).

    Raises
    ------
    InputError
        The last dimension is not 3.
    """
    p = np.asarray(points, dtype=float)
    if p.shape[-1:] != (3,):
        raise InputError("points must have shape (..., 3), got %s" % (p.shape,))
    return p
