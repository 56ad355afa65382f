# SPDX-License-Identifier: LGPL-2.1-or-later
"""Points a region's moved sharp edge slides past (surfcomp/core/compensation/region_slide.py):
a wedge whose normals are 72 deg apart (the BladeX trailing edge's angle where the bench's
points lay beyond it), corrected by 29 um."""

import math

import numpy as np
import pytest

from surfcomp.core.compensation import region_build, region_edges
from surfcomp.core.compensation.region_slide import edge_slide

ANGLE = math.radians(72.0)
DELTA = 0.029


def _wedge(convex=True):
    """Face 0 the plane z = 0 over x > 0, face 1 through the y axis at 72 deg: below it
    (a convex edge) or above it (concave); the edge sampled along y."""
    s, c = math.sin(ANGLE), math.cos(ANGLE)
    na = np.array([0.0, 0.0, 1.0])
    nb, inb = ((np.array([-s, 0.0, c]), np.array([-c, 0.0, -s])) if convex else
               (np.array([s, 0.0, c]), np.array([-c, 0.0, s])))
    ys = np.linspace(-1.0, 1.0, 21)
    pts = np.stack([0 * ys, ys, 0 * ys], axis=1)
    k = len(ys)
    m, exact = region_build.miters(np.tile(na, (k, 1)), np.tile(nb, (k, 1)),
                                   np.tile([1.0, 0.0, 0.0], (k, 1)), np.tile(inb, (k, 1)))
    normals = np.stack([np.tile(na, (k, 1)), np.tile(nb, (k, 1))], axis=1)
    sharp = region_edges.SharpEdges(pts, m, exact, np.zeros(k, dtype=int), 1.0, normals,
                                    np.tile([0, 1], (k, 1)))
    return sharp.for_face(0)


DIST = np.array([0.3, 5.0, 15.0, 20.5, 21.8, 30.0, 60.0, 500.0]) * 1e-3


def _points():
    x = np.stack([DIST, np.full(len(DIST), 0.3), 0 * DIST], axis=1)
    return x, np.tile([0.0, 0.0, 1.0], (len(x), 1))


def test_a_convex_edge_corrected_inwards_slides_past_the_points_nearer_than_its_slide():
    """The offset wedge ends ``delta (1 - cos 72) / sin 108 = delta tan 36`` = 21.07 um
    short of the offset of its edge, along each face: the points nearer than that are
    passed, the rest (and a point on the edge itself) are not."""
    x, n = _points()
    slide, dist = edge_slide(x, n, np.full(len(x), DELTA), _wedge())
    expected = DELTA * math.tan(math.radians(36.0))
    assert expected * 1e3 == pytest.approx(21.07, abs=0.01)
    # the edges are searched within the largest slide: beyond it, no distance
    np.testing.assert_allclose(dist[:-1], DIST[:-1], rtol=1e-9)
    assert dist[-1] == np.inf
    near = DIST < 0.1
    np.testing.assert_allclose(slide[near], expected, rtol=1e-6)
    assert list(slide > dist) == [True, True, True, True, False, False, False, False]
    on = edge_slide(np.array([[0.0, 0.2, 0.0]]), n[:1], np.array([DELTA]), _wedge())
    assert not on[0][0] > on[1][0]


@pytest.mark.parametrize("convex, sign", [(True, -1.0), (False, 1.0), (False, -1.0)])
def test_an_edge_that_extends_the_face_passes_no_point(convex, sign):
    """Corrected outwards a convex edge moves away from its faces' points (the faces grow),
    and so does a concave one corrected inwards: the check's line meets the corrected
    face and no point is set apart. (A concave edge corrected outwards slides into its
    faces as a convex one corrected inwards does.)"""
    x, n = _points()
    slide, dist = edge_slide(x, n, np.full(len(x), sign * DELTA), _wedge(convex))
    passed = slide > dist
    if not convex and sign < 0:
        assert passed[0] and not passed[-1]
    else:
        assert not passed.any()
        assert np.all(slide[DIST < 0.1] < 0)


def test_no_sharp_edges_pass_nothing():
    x, n = _points()
    slide, dist = edge_slide(x, n, np.full(len(x), DELTA), None)
    assert not np.any(slide > dist)
