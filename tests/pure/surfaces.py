# SPDX-License-Identifier: LGPL-2.1-or-later
"""Small core surfaces shared by tests (no FreeCAD)."""

import numpy as np

from surfcomp.core.surface import bspline


def wavy_patch():
    """A bicubic 30 x 30 mm patch, 5 x 5 poles, z = 2 sin(x/12) cos(y/15), one inner knot."""
    x = np.linspace(0.0, 30.0, 5)
    X, Y = np.meshgrid(x, x, indexing="ij")
    Z = 2.0 * np.sin(X / 12.0) * np.cos(Y / 15.0)
    k = np.array([0, 0, 0, 0, 0.5, 1, 1, 1, 1.0])
    return bspline.Surface(np.stack([X, Y, Z], axis=-1), k, k, 3, 3)
