# SPDX-License-Identifier: LGPL-2.1-or-later
"""Point projection (surfcomp.core.surface.projection) against OCCT's ``face.distToShape``.

OCCT's BRepExtrema answer is the reference: the closest point on the trimmed face
(interior, edge or vertex), its distance, and for interior hits the (u, v).
Accuracy target (issue 5): |d - d_OCCT| <= 1e-6 mm and foot within 1e-6 mm.
OCCT takes ~30 ms a point here, so each case uses ~100 points.
"""

import os

import FreeCAD
import numpy as np
import Part
import pytest
from numpy.testing import assert_allclose

from surfcomp.app.convert import surface_from_part, surface_to_part
from surfcomp.core.surface import bspline as bs
from surfcomp.core.surface.projection import Projector, project
from tests.conftest import REALDATA
from tests.pure.surfaces import random_surface

BLADE = os.path.join(REALDATA, "cad", "BladeX", "upper.iges")
SPHERE = os.path.join(REALDATA, "cad", "axom_data", "boxed_sphere.step")
TOL = 1e-6


def _face(path, index):
    face = Part.read(path).Faces[index]
    u0, u1, v0, v1 = face.ParameterRange
    return face, surface_from_part(face.Surface, (u0, u1), (v0, v1))


@pytest.fixture(scope="module")
def blade():
    return _face(BLADE, 0)


@pytest.fixture(scope="module")
def sphere_half():
    face, surf = _face(SPHERE, -1)
    assert surf.rational
    return face, surf


def _occt(face, X):
    """OCCT closest points: (distance, foot (n, 3), on_face (bool), signed distance)."""
    dist, feet, inside, signed = [], [], [], []
    surf = face.Surface
    for p in X.tolist():
        d, pairs, info = face.distToShape(Part.Vertex(FreeCAD.Vector(*p)))
        foot = pairs[0][0]
        dist.append(d)
        feet.append(tuple(foot))
        inside.append(info[0][0] == "Face")
        # BRepExtrema gives the (u, v) of a foot inside the face; a foot on an edge or a
        # vertex is projected onto the surface for its normal
        a, b = info[0][2] if inside[-1] else surf.parameter(foot)
        n = surf.normal(a, b)
        signed.append(np.sign((FreeCAD.Vector(*p) - foot).dot(n)) * d)
    return np.array(dist), np.array(feet), np.array(inside), np.array(signed)


def _check(face, surf, X, expect_outside=None, exact_feet=None):
    r = project(surf, X)
    d, feet, on_face, signed = _occt(face, X)
    assert r.converged.all()
    assert_allclose(np.abs(r.distance), d, atol=TOL, rtol=0)
    if exact_feet is None:
        assert_allclose(r.foot, feet, atol=TOL, rtol=0)
    else:
        assert_allclose(r.foot, exact_feet, atol=1e-9, rtol=0)
    # sign: the side of OCCT's Su x Sv normal (skip points on the surface)
    big = d > 1e-6
    assert_allclose(r.distance[big], signed[big], atol=TOL, rtol=0)
    assert (r.outside == ~on_face).all()
    if expect_outside is not None:
        assert (r.outside == expect_outside).all()
    return r


def _offset_points(surf, u, v, d):
    return bs.evaluate(surf, u, v) + d[:, None] * bs.normals(surf, u, v)


def test_blade_points_up_to_1mm_off(blade):
    face, surf = blade
    rng = np.random.default_rng(60)
    n = 100
    u, v = rng.uniform(0.001, 0.999, n), rng.uniform(0.001, 0.999, n)
    # a third of them in the leading/trailing edge regions (u near the ends, high curvature)
    u[:30] = np.r_[rng.uniform(0.0005, 0.02, 15), rng.uniform(0.98, 0.9995, 15)]
    X = _offset_points(surf, u, v, rng.uniform(-1, 1, n))
    _check(face, surf, X, expect_outside=np.zeros(n, dtype=bool))


def test_blade_region_certificate_matches_occt(blade):
    """Points certified per region of the face (most, 0.1 mm off) and points left to the
    point-by-point search (near the tight leading edge and the tip, 0.5 mm off): the
    same closest points as OCCT."""
    face, surf = blade
    rng = np.random.default_rng(65)
    n = 120
    u, v = rng.uniform(0.001, 0.999, n), rng.uniform(0.001, 0.999, n)
    d = rng.uniform(-0.1, 0.1, n)
    u[:20] = np.r_[rng.uniform(0.0005, 0.02, 10), rng.uniform(0.98, 0.9995, 10)]
    v[20:40] = rng.uniform(0.97, 0.999, 20)
    d[:40] = rng.uniform(-0.5, 0.5, 40)
    X = _offset_points(surf, u, v, d)
    P = Projector(surf)
    r = P.project(X)
    certified = P.regions().certified(r.u, r.v, r.distance)
    assert 60 < certified.sum() < n
    _check(face, surf, X)   # near the tip some closest points are on its edge


def test_blade_points_near_and_beyond_the_boundary(blade):
    face, surf = blade
    rng = np.random.default_rng(61)
    n = 80
    u, v = rng.uniform(0.01, 0.99, n), rng.uniform(0.01, 0.99, n)
    v[:40] = np.r_[np.zeros(20), np.ones(20)]  # on the v edges ...
    S, Su, Sv = bs.derivatives(surf, u, v)
    nrm = bs.normals(surf, u, v)
    out = -Sv[:40] / np.linalg.norm(Sv[:40], axis=1, keepdims=True)
    out[20:] *= -1
    X = S + rng.uniform(-0.5, 0.5, (n, 1)) * nrm
    X[:40] += rng.uniform(0.05, 2.0, (40, 1)) * out  # ... and moved outwards across them
    X[40:] = _offset_points(surf, u[40:], rng.uniform(0.0, 2e-3, 40), rng.uniform(-1, 1, 40))
    r = _check(face, surf, X)
    assert r.outside[:40].all()


def test_rational_sphere_concave_side_and_poles(sphere_half):
    face, surf = sphere_half
    rng = np.random.default_rng(62)
    n = 90
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    v[:10] = surf.v_range[0] + rng.uniform(0, 5.0, 10)  # near the collapsed pole
    S = bs.evaluate(surf, u, v)
    R = np.linalg.norm(S, axis=1)
    assert_allclose(R, 5.0, atol=1e-9, rtol=0)
    # inside the sphere down to 0.5 mm from its centre: distances close to the
    # radius of curvature (5 mm) on the concave side; and outside up to 1 mm
    rho = np.r_[rng.uniform(0.5, 1.5, 40), rng.uniform(4.0, 6.0, 50)]
    X = S * (rho / R)[:, None]
    # the feet are compared with the exact radial ones: next to the pole, on the
    # concave side, OCCT's own foot points are up to 2e-3 mm off (its distances
    # are right to 3e-10 mm)
    r = _check(face, surf, X, expect_outside=np.zeros(n, dtype=bool), exact_feet=S)
    assert_allclose(np.abs(r.distance), np.abs(rho - 5.0), atol=1e-9, rtol=0)


def test_random_rational_high_curvature_surface():
    surf = random_surface(np.random.default_rng(63), nu=8, nv=8, pu=3, pv=3, rational=True)
    face = Part.Face(surface_to_part(surf))
    rng = np.random.default_rng(64)
    n = 80
    u, v = rng.uniform(0, 1, n), rng.uniform(-1, 2, n)
    X = _offset_points(surf, u, v, rng.uniform(-1, 1, n))
    X[60:] += rng.normal(scale=3.0, size=(20, 3))  # arbitrary points around the face
    _check(face, surf, X)
