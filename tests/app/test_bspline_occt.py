# SPDX-License-Identifier: LGPL-2.1-or-later
"""The numeric B-spline engine against OCCT (Part.BSplineSurface) on real and random faces."""

import os

import FreeCAD
import numpy as np
import Part
import pytest
from numpy.testing import assert_allclose

from surfcomp.app.convert import surface_from_part, surface_to_part
from surfcomp.core.surface import bspline as bs
from tests.conftest import REALDATA
from tests.pure.surfaces import quarter_cylinder, random_surface

BLADE = os.path.join(REALDATA, "cad", "BladeX", "upper.iges")
SPHERE = os.path.join(REALDATA, "cad", "axom_data", "boxed_sphere.step")


def _face_surface(path, index):
    face = Part.read(path).Faces[index]
    u0, u1, v0, v1 = face.ParameterRange
    return face.Surface, surface_from_part(face.Surface, (u0, u1), (v0, v1))


@pytest.fixture(scope="module")
def blade():
    return _face_surface(BLADE, 0)


@pytest.fixture(scope="module")
def sphere_half():
    part, surf = _face_surface(SPHERE, -1)
    assert part.isURational() and surf.rational
    return part, surf


def _cases():
    rng = np.random.default_rng(101)
    return {
        "random_poly": random_surface(rng, nu=9, nv=7, pu=3, pv=2),
        "random_rational": random_surface(rng, nu=8, nv=8, pu=3, pv=3, rational=True),
        "quarter_cylinder": quarter_cylinder(),
        "degree5x1": random_surface(rng, nu=8, nv=3, pu=5, pv=1, rational=True),
    }


def _params(surf, n, seed):
    rng = np.random.default_rng(seed)
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    u[:2], v[:2] = surf.u_range, surf.v_range[::-1]
    return u, v


def _occt(part, u, v):
    """OCCT point, first and second derivatives and normal at each (u, v)."""
    vec = lambda x: tuple(x)  # noqa: E731
    rows = []
    for a, b in zip(u.tolist(), v.tolist()):
        rows.append([vec(part.value(a, b)), vec(part.getDN(a, b, 1, 0)),
                     vec(part.getDN(a, b, 0, 1)),
                     vec(part.getDN(a, b, 2, 0)), vec(part.getDN(a, b, 1, 1)),
                     vec(part.getDN(a, b, 0, 2)), vec(part.normal(a, b))])
    return np.array(rows)  # (n, 7, 3)


def _compare(part, surf, n, seed, rtol2=1e-9):
    """Points, normals and first derivatives within 1e-9 (relative to the largest
    value), second derivatives within ``rtol2`` of the largest value."""
    u, v = _params(surf, n, seed)
    ref = _occt(part, u, v)
    ours = bs.derivatives(surf, u, v, order=2)
    for k, arr in enumerate(ours):
        scale = max(1.0, np.abs(ref[:, k]).max())
        tol = 1e-9 if k < 3 else rtol2
        assert_allclose(arr, ref[:, k], atol=tol * scale, err_msg="derivative %d" % k)
    assert_allclose(bs.evaluate(surf, u, v), ref[:, 0], atol=1e-9)
    assert_allclose(bs.normals(surf, u, v), ref[:, 6], atol=1e-9)


@pytest.mark.parametrize("name", sorted(_cases()))
def test_random_surfaces_match_occt(name):
    surf = _cases()[name]
    part = surface_to_part(surf)
    # (OCCT calls weights varying along the u index 'V rational': test either flag)
    assert (part.isURational() or part.isVRational()) == surf.rational
    _compare(part, surf, 200, 7)


def test_blade_face_matches_occt(blade):
    part, surf = blade
    assert surf.shape == (526, 13) and (surf.degree_u, surf.degree_v) == (3, 2)
    # the blade has knot spans down to 1.9e-8: second derivatives there are
    # ill-conditioned (basis second derivatives ~1e12); OCCT, scipy's de Boor and
    # this engine agree to ~1e-8 of the largest Suu only, so that is the bound
    assert np.diff(np.unique(surf.knots_u)).min() < 1e-7
    _compare(part, surf, 300, 8, rtol2=5e-8)


def test_rational_sphere_half_matches_occt(sphere_half):
    part, surf = sphere_half
    _compare(part, surf, 200, 9)
    # all points on the sphere of radius 5 around the origin (a real rational face)
    u, v = _params(surf, 500, 10)
    assert_allclose(np.linalg.norm(bs.evaluate(surf, u, v), axis=1), 5.0, atol=1e-9)


def test_normals_at_sphere_poles_match_occt(sphere_half):
    # the u-boundaries of this face collapse into the sphere's poles: Su = 0 there
    part, surf = sphere_half
    (u0, u1), (v0, v1) = surf.u_range, surf.v_range
    u = np.array([u0, u0, u0, u1, u1, u1, 0.5 * (u0 + u1)])
    v = np.array([v0, 0.0, v1, v0, 0.3 * v1, v1, v0])
    _, Su, Sv = bs.derivatives(surf, u, v)
    deg = bs._degenerate(np.cross(Su, Sv), Su, Sv, *bs._derivative_scales(surf))
    assert deg.sum() >= 4
    ref = np.array([tuple(part.normal(a, b)) for a, b in zip(u.tolist(), v.tolist())])
    assert_allclose(bs.normals(surf, u, v), ref, atol=1e-9)


def test_evaluate_grid_matches_occt(blade):
    part, surf = blade
    us = np.linspace(*surf.u_range, 31)
    vs = np.linspace(*surf.v_range, 9)
    S, Su, Sv = bs.evaluate_grid(surf, us, vs, order=1)
    for i in range(0, 31, 5):
        for j in range(9):
            assert_allclose(S[i, j], tuple(part.value(us[i], vs[j])), atol=1e-9)
            assert_allclose(Su[i, j], tuple(part.getDN(us[i], vs[j], 1, 0)),
                            atol=1e-9 * np.abs(Su).max())
            assert_allclose(Sv[i, j], tuple(part.getDN(us[i], vs[j], 0, 1)),
                            atol=1e-9 * np.abs(Sv).max())


@pytest.mark.parametrize("rational", [False, True])
def test_insert_knots_matches_occt(rational):
    surf = random_surface(np.random.default_rng(55), nu=8, nv=6, rational=rational)
    new_u, new_v = [0.2, 0.61, 0.61], [-0.25, 1.3]
    ours = bs.insert_knots(surf, new_u, new_v)
    part = surface_to_part(surf)
    for t in sorted(set(new_u)):
        part.insertUKnot(t, new_u.count(t), 1e-12)
    for t in new_v:
        part.insertVKnot(t, 1, 1e-12)
    ref = surface_from_part(part)
    assert_allclose(ours.knots_u, ref.knots_u, atol=1e-15)
    assert_allclose(ours.knots_v, ref.knots_v, atol=1e-15)
    assert_allclose(ours.poles, ref.poles, atol=1e-9)
    if rational:
        assert_allclose(ours.weights, ref.weights, atol=1e-12)


def test_interpolated_blade_refit_is_the_blade(blade):
    # zero-displacement refit of the real face in its own knot space
    part, surf = blade
    gu, gv = bs.greville(surf.knots_u, 3), bs.greville(surf.knots_v, 2)
    X = bs.evaluate_grid(surf, gu, gv)
    P = bs.interpolate_grid(gu, gv, X, surf.knots_u, surf.knots_v, 3, 2)
    assert_allclose(P, surf.poles, atol=1e-9)
    refit = surface_to_part(bs.Surface(P, surf.knots_u, surf.knots_v, 3, 2))
    for a, b in [(0.1, 0.2), (0.77, 0.9), (0.5, 0.5)]:
        assert (refit.value(a, b) - part.value(a, b)).Length < 1e-9
    assert isinstance(FreeCAD.Vector(*P[0, 0]), FreeCAD.Vector)


def test_conversion_pauses_the_garbage_collector_and_restores_it():
    """The pole-net conversions run without cyclic collections (a 1008 x 1008 net is a
    million new lists, and each collection they trigger walks every object of the
    process) and leave the collector as it was, also after an error inside."""
    import gc

    from surfcomp.core.memory import collector_paused as gc_paused

    rng = np.random.default_rng(3)
    knots = np.r_[0, 0, 0, np.linspace(0, 1, 298), 1, 1, 1]
    surf = bs.Surface(rng.normal(size=(300, 300, 3)), knots, knots, 3, 3)
    seen = []
    gc.callbacks.append(lambda phase, info: seen.append(phase))
    try:
        gc.collect()
        seen.clear()
        back = surface_from_part(surface_to_part(surf))   # 180 000 new lists
        # (without the pause: about 260 collections)
        assert seen.count("start") <= 5 and gc.isenabled()
        assert_allclose(back.poles, surf.poles, rtol=0, atol=0)
    finally:
        gc.callbacks.pop()
    with pytest.raises(ZeroDivisionError):
        with gc_paused():
            assert not gc.isenabled()
            raise ZeroDivisionError
    assert gc.isenabled()
    gc.disable()
    try:
        with gc_paused():
            pass
        assert not gc.isenabled()      # the caller's choice stays
    finally:
        gc.enable()
