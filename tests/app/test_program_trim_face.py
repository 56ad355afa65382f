# SPDX-License-Identifier: LGPL-2.1-or-later
"""The direct route's ball offset honours a FreeCAD face's trim (issue 27): the example
surface trimmed by a circle with a circular hole (the parts of tests/app/test_trim.py), its
corrected surface 20 um below: a contact inside the trimmed face moves, a ball over the
middle of the hole or outside the outer circle does not; the untrimmed example has no trim."""

import dataclasses

import numpy as np

from surfcomp.app.nominal import load_nominal, nominal_from_face
from surfcomp.app.program_geometry import offset_of
from surfcomp.core.surface import bspline
from tests.app.helpers import EXAMPLE_STEP
from tests.app.trim_cases import HOLE, circle_face

R = 3.0
DZ = 0.02


def tips(surf, uv):
    """Tips of a ball touching the surface at parameters ``uv`` (k, 2) from outside."""
    u, v = np.asarray(uv, dtype=float).T
    S, Su, Sv = bspline.derivatives(surf, u, v, order=1)
    n = bspline.unit_normals(surf, u, v, Su, Sv)
    return S + R * n - [0.0, 0.0, R]


def lowered(surf):
    P = surf.poles.copy()
    P[:, :, 2] -= DZ
    return dataclasses.replace(surf, poles=P)


def test_the_untrimmed_example_has_no_trim():
    nominal = load_nominal(EXAMPLE_STEP)
    assert offset_of(nominal, lowered(nominal.surface), R, 1.0).trim is None


def test_a_hole_and_the_outer_circle_fade_the_correction_out():
    nominal = nominal_from_face(circle_face(hole=HOLE))
    off = offset_of(nominal, lowered(nominal.surface), R, 1.0)
    assert off.trim is not None
    inside, hole_middle, outer = (0.5, 0.3), HOLE[0], (0.05, 0.05)
    d = off.displace(tips(nominal.surface, [inside, hole_middle, outer]))
    size = np.linalg.norm(d.move, axis=1)
    assert 0.9 * DZ < size[0] < 1.01 * DZ
    assert size[1] == 0.0 and size[2] == 0.0
    assert d.gap[1] > 1.0 and d.gap[2] > 1.0
    assert d.interior.tolist() == [True, False, False]
