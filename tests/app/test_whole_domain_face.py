# SPDX-License-Identifier: LGPL-2.1-or-later
"""A face bounded by its surface's whole domain, told from its edges' ends
(:func:`surfcomp.app.nominal.bounds_whole_domain`) instead of 400 samples of every pcurve:
the same answer as ``whole_domain`` on the sampled boundary, and the routes that use it
(the trim warning, the correction's volume, the direct program's trim) give what the
sampled boundary gives."""

import FreeCAD
import numpy as np
import Part
import pytest

from surfcomp.app.nominal import (
    boundary_polylines,
    bounds_whole_domain,
    nominal_from_face,
    outside_trim,
)
from surfcomp.app.volumes import correction_volume
from surfcomp.core.compensation.program_trim import Trim
from surfcomp.core.surface import bspline
from surfcomp.core.surface.trimmed import correction_integral, whole_domain
from tests.app.helpers import EXAMPLE_STEP
from tests.app.trim_cases import HOLE, circle_face


def _surface():
    return Part.read(EXAMPLE_STEP).Faces[0].Surface


def _polygon(corners, holes=()):
    """The example surface bounded by straight lines in (u, v) through ``corners``."""
    bs = _surface()

    def wire(pts):
        edges = [Part.Geom2d.Line2dSegment(FreeCAD.Base.Vector2d(*a), FreeCAD.Base.Vector2d(*b))
                 .toShape(bs) for a, b in zip(pts, pts[1:] + pts[:1])]
        return Part.Wire(edges)

    face = Part.Face(bs, wire(corners))
    if holes:
        face.cutHoles([wire(h) for h in holes])
        face.fix(1e-7, 1e-7, 1e-7)
    assert face.isValid()
    return face


def _faces():
    return {
        "example": Part.read(EXAMPLE_STEP).Faces[0],
        "sub-rectangle (its own whole domain)": _surface().toShape(0.1, 0.8, 0.2, 0.9),
        "triangle": _polygon([(0, 0), (1, 0), (1, 1)]),
        "square with a square hole": _polygon([(0, 0), (1, 0), (1, 1), (0, 1)],
                                              [[(0.4, 0.4), (0.4, 0.6), (0.6, 0.6), (0.6, 0.4)]]),
        "pentagon on the sides": _polygon([(0, 0), (1, 0), (1, 1), (0.5, 1), (0, 1)]),
        "circle": circle_face(),
        "circle with a hole": circle_face(hole=HOLE),
    }


EXPECTED = {"example": True, "sub-rectangle (its own whole domain)": True, "triangle": False,
            "square with a square hole": False, "pentagon on the sides": True,
            "circle": False, "circle with a hole": False}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_the_ends_tell_what_the_samples_tell(name):
    nominal = nominal_from_face(_faces()[name])
    s = nominal.surface
    sampled = whole_domain(boundary_polylines(nominal.bspline_face), s.u_range, s.v_range)
    assert bounds_whole_domain(nominal.bspline_face, s.u_range, s.v_range) is EXPECTED[name]
    assert sampled is EXPECTED[name]


def test_the_routes_give_what_the_sampled_boundary_gives():
    """On the example (whole domain): no point outside the trim, the volume of the tensor
    rule to the last bit, no trim for the program; on a triangle the sampled route."""
    nominal = nominal_from_face(Part.read(EXAMPLE_STEP).Faces[0])
    s = nominal.surface
    corrected = bspline.Surface(s.poles + 0.01 * np.array([0.0, 0.0, 1.0]), s.knots_u,
                                s.knots_v, s.degree_u, s.degree_v, s.weights)
    sampled = correction_integral(s, corrected, nominal.outward,
                                  boundary_polylines(nominal.bspline_face))
    assert correction_volume(nominal, corrected) == sampled
    assert abs(sampled) > 1.0                   # 10 um over about 2000 mm^2 (|nz| ~ 1)
    assert Trim.of(s, boundary_polylines(nominal.bspline_face)) is None

    class Prepared:     # the measured points' feet: the surface's nodes, its corners included
        u, v = (a.ravel() for a in np.meshgrid(np.linspace(*s.u_range, 9),
                                               np.linspace(*s.v_range, 9), indexing="ij"))
        nominal = bspline.evaluate(s, u, v)

    idx, dist = outside_trim(nominal, Prepared)
    assert idx.size == 0 and dist.size == 0 and idx.dtype.kind == "i"
    tri = nominal_from_face(_polygon([(0, 0), (1, 0), (1, 1)]))
    idx, dist = outside_trim(tri, Prepared)
    # the nodes above the diagonal (v > u), beyond the 1 um the warning allows
    above = np.flatnonzero(Prepared.v > Prepared.u + 1e-12)
    assert np.array_equal(idx, above) and np.all(dist > 1e-3)
