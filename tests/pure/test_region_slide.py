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


def _wedge(convex=True, inward=True, shift=0.0):
    """Face 0 the plane z = 0 over x > 0, face 1 through the y axis at 72 deg: below it
    (a convex edge) or above it (concave); the edge sampled along y, ``shift`` mm along x
    (two faces that do not quite meet), with the faces' directions into themselves or
    without."""
    s, c = math.sin(ANGLE), math.cos(ANGLE)
    na = np.array([0.0, 0.0, 1.0])
    nb, inb = ((np.array([-s, 0.0, c]), np.array([-c, 0.0, -s])) if convex else
               (np.array([s, 0.0, c]), np.array([-c, 0.0, s])))
    ys = np.linspace(-1.0, 1.0, 21)
    pts = np.stack([0 * ys + shift, ys, 0 * ys], axis=1)
    k = len(ys)
    m, exact = region_build.miters(np.tile(na, (k, 1)), np.tile(nb, (k, 1)),
                                   np.tile([1.0, 0.0, 0.0], (k, 1)), np.tile(inb, (k, 1)))
    normals = np.stack([np.tile(na, (k, 1)), np.tile(nb, (k, 1))], axis=1)
    into = np.stack([np.tile([1.0, 0.0, 0.0], (k, 1)), np.tile(inb, (k, 1))], axis=1)
    sharp = region_edges.SharpEdges(pts, m, exact, np.zeros(k, dtype=int), 1.0, normals,
                                    np.tile([0, 1], (k, 1)), into if inward else None)
    return sharp.for_face(0)


DIST = np.array([0.3, 5.0, 15.0, 20.5, 21.8, 30.0, 60.0, 500.0]) * 1e-3


def _points():
    x = np.stack([DIST, np.full(len(DIST), 0.3), 0 * DIST], axis=1)
    return x, np.tile([0.0, 0.0, 1.0], (len(x), 1))


@pytest.mark.parametrize("inward", [True, False])
def test_a_convex_edge_corrected_inwards_slides_past_the_points_nearer_than_its_slide(inward):
    """The offset wedge ends ``delta (1 - cos 72) / sin 108 = delta tan 36`` = 21.07 um
    short of the offset of its edge, along each face: the points nearer than that are
    passed, the rest are not. A point on the edge is passed with the face's own direction
    into itself and not classified without it (no direction from the edge to the point)."""
    x, n = _points()
    slide, dist = edge_slide(x, n, np.full(len(x), DELTA), _wedge(inward=inward))
    expected = DELTA * math.tan(math.radians(36.0))
    assert expected * 1e3 == pytest.approx(21.07, abs=0.01)
    np.testing.assert_allclose(dist, DIST, rtol=1e-9)
    near = DIST < 0.1
    np.testing.assert_allclose(slide[near], expected, rtol=1e-6)
    assert list(slide > dist) == [True, True, True, True, False, False, False, False]
    on = edge_slide(np.array([[0.0, 0.2, 0.0]]), n[:1], np.array([DELTA]),
                    _wedge(inward=inward))
    assert (on[0][0] > on[1][0]) == inward


def test_the_distance_is_signed_where_the_edge_polyline_lies_inside_the_face():
    """The other face's edge 3 um inside this one (the BladeX sides' trailing edges lie
    up to 3.3 um apart): a point 1 um from its face's own edge lies 2 um beyond the
    polyline; with the face's direction into itself it is still passed, 2 um away (before,
    the direction from the polyline to it pointed out of the face and its slide read
    negative)."""
    x = np.array([[0.001, 0.3, 0.0], [0.030, 0.3, 0.0]])
    n = np.tile([0.0, 0.0, 1.0], (2, 1))
    slide, dist = edge_slide(x, n, np.full(2, DELTA), _wedge(shift=0.003))
    np.testing.assert_allclose(dist, [0.002, 0.027], atol=1e-12)
    assert list(slide > dist) == [True, False]
    slide, dist = edge_slide(x, n, np.full(2, DELTA), _wedge(shift=0.003, inward=False))
    assert slide[0] < 0 and list(slide > dist) == [False, False]


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


def test_a_direction_into_the_face_given_the_wrong_way_is_turned_by_the_faces_points():
    """The face's direction into itself given out of it (as the BladeX pressure side's
    boundary gives it along its leading edge): the face's points 10 um to 1 mm from the
    edge lie on the other side, so it is turned round, and the points read as with the
    right one."""
    x, n = _points()
    sharp = _wedge()
    sharp.own_inward = -sharp.own_inward
    slide, dist = edge_slide(x, n, np.full(len(x), DELTA), sharp)
    np.testing.assert_allclose(slide[DIST < 0.1], DELTA * math.tan(math.radians(36.0)),
                               rtol=1e-6)
    assert list(slide > dist) == [True, True, True, True, False, False, False, False]
