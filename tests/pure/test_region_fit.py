# SPDX-License-Identifier: LGPL-2.1-or-later
"""The region's fit with its boundary curves fitted on their own, and the vertices where a
face collapses (issue 30; no FreeCAD)."""

import numpy as np
import pytest

from surfcomp.core.compensation import region_build, region_edges, region_fit
from surfcomp.core.surface.bspline import Surface, evaluate_grid, fit_grid_lsq
from tests.pure.surfaces import cube_corner_edges


def _knots(spans, degree):
    return np.r_[np.zeros(degree), np.linspace(0.0, 1.0, spans + 1), np.ones(degree)]


def _samples(spans, per=3):
    return np.r_[np.linspace(0.0, 1.0, spans * per + 1)]


def test_a_surface_of_the_spline_space_comes_back():
    rng = np.random.default_rng(4)
    ku, kv = _knots(7, 3), _knots(5, 2)
    poles = rng.normal(size=(10, 7, 3))
    us, vs = _samples(7), _samples(5)
    X = evaluate_grid(Surface(poles, ku, kv, 3, 2), us, vs)
    np.testing.assert_allclose(region_fit.fit_ends_held(us, vs, X, ku, kv, 3, 2), poles,
                               atol=1e-10)
    w = rng.uniform(0.5, 2.0, size=(10, 7))
    X = evaluate_grid(Surface(poles, ku, kv, 3, 2, w), us, vs)
    np.testing.assert_allclose(region_fit.fit_ends_held(us, vs, X, ku, kv, 3, 2, weights=w),
                               poles, atol=1e-9)


def test_the_boundary_curve_depends_on_the_boundary_samples_only():
    """Two faces whose samples agree along their common boundary v = 1 and differ inside,
    on different v knots, get the same boundary curve (their edge closes); the plain
    least-squares fit lets the inside pull the boundary apart."""
    ku = _knots(12, 3)
    us = _samples(12)
    x = np.sin(3.0 * us)[:, None]

    def grid(vs, bump):
        X = np.zeros((len(us), len(vs), 3))
        X[:, :, 0] = us[:, None]
        X[:, :, 1] = vs[None, :]
        X[:, :, 2] = 0.01 * x * vs[None, :] ** 2 + bump * np.cos(40.0 * vs[None, :]) * (
            1.0 - vs[None, :]) * np.sin(9.0 * us)[:, None]
        return X

    va, vb = _samples(4), _samples(9)
    ka, kb = _knots(4, 2), _knots(9, 3)
    qa = region_fit.fit_ends_held(us, va, grid(va, 0.002), ku, ka, 3, 2)
    qb = region_fit.fit_ends_held(us, vb, grid(vb, -0.003), ku, kb, 3, 3)
    np.testing.assert_allclose(qa[:, -1], qb[:, -1], atol=1e-14)
    pa = fit_grid_lsq(us, va, grid(va, 0.002), ku, ka, 3, 2)
    pb = fit_grid_lsq(us, vb, grid(vb, -0.003), ku, kb, 3, 3)
    assert np.max(np.abs(pa[:, -1] - pb[:, -1])) > 5e-6     # 7.9 nm here


def test_a_vertex_where_a_face_collapses_moves_as_one_point():
    """At a cube corner the three faces' normals admit one miter, which keeps each face's
    correction; where a face collapses at the vertex (a cap's end: its normal takes every
    direction of a fan there) the vertex moves by its vector whatever the normal."""
    edges, n = cube_corner_edges()
    args = (*edges, 1.0, region_edges.knife_limit(region_build.MITER_ANGLE), 1e-6)
    o, delta = np.zeros((1, 3)), np.array([0.02])
    fan = [np.array([[0.0, -0.6, -0.8]]), np.array([[-0.8, 0.0, -0.6]])]
    kept = region_edges.SharpEdges(args[0], *region_edges.at_vertices(*args), args[3], band=2.0)
    d = [region_build.displacement(o, m, delta, kept)[0] for m in fan]
    assert np.linalg.norm(d[0] - d[1]) > 1e-3         # the normal components kept
    one = region_edges.SharpEdges(args[0], *region_edges.at_vertices(*args, singular=o),
                                  args[3], band=2.0)
    d = [region_build.displacement(o, m, delta, one)[0] for m in fan]
    np.testing.assert_allclose(d[0], d[1], atol=1e-15)
    np.testing.assert_allclose(d[0], [0.02, 0.02, 0.02], atol=1e-12)
    # beyond the vertex zone (1 mm along each edge) the edges keep their exact miters
    x = np.array([[5.0, 0.0, 0.0]])
    dy = region_build.displacement(x, n["y"][None], delta, one)[0]
    np.testing.assert_allclose(dy @ n["y"], -0.02, atol=1e-15)


def test_a_curved_face_turns_relative_to_its_own_normal_at_the_edge():
    """A 2 deg edge along y between face 0 (normal +z there) and face 1: a point of face 0
    next to the edge whose normal is tilted 30 deg along the edge (a blend curving along
    it) slides along itself by the edge's excess only (0.017 of the correction), not by
    the 30 deg between its normal and the miter (0.5); on the edge both faces move by the
    miter."""
    a = np.radians(2.0)
    na, nb = np.array([0.0, 0.0, 1.0]), np.array([np.sin(a), 0.0, np.cos(a)])
    edge = np.stack([np.zeros(50), np.linspace(0, 10, 50), np.zeros(50)], axis=1)
    K = len(edge)
    m, c = region_build.miters(np.tile(na, (K, 1)), np.tile(nb, (K, 1)),
                               np.tile([-1.0, 0, 0], (K, 1)), np.tile([1.0, 0, 0], (K, 1)))
    sharp = region_edges.SharpEdges(edge, m, c, np.zeros(K, int), 1.0,
                                    np.tile(np.stack([na, nb]), (K, 1, 1)),
                                    np.tile([0, 1], (K, 1)))
    t = np.radians(30.0)
    n = np.array([[0.0, np.sin(t), np.cos(t)]])
    x = np.array([[-0.01, 5.0, 0.0]])
    old = region_build.direction(x, n, sharp)[0]
    new = region_build.direction(x, n, sharp.for_face(0))[0]
    for d in (old, new):
        assert d @ n[0] == pytest.approx(1.0, abs=1e-12)      # the correction is kept
    slide = lambda d: np.linalg.norm(d - (d @ n[0]) * n[0])   # noqa: E731
    assert slide(old) == pytest.approx(0.5, abs=0.01)
    assert slide(new) == pytest.approx(np.linalg.norm(m[0] - na), abs=1e-3)
    assert slide(new) < 0.018
    on = np.array([[0.0, 5.0, 0.0]])
    da = region_build.direction(on, na[None], sharp.for_face(0))[0]
    db = region_build.direction(on, nb[None], sharp.for_face(1))[0]
    np.testing.assert_allclose(da, m[0], atol=1e-12)
    np.testing.assert_allclose(db, m[0], atol=1e-12)


def test_the_edge_vector_between_samples_has_no_kink():
    """Along an edge whose miter turns from sample to sample, the vector at the foot is
    the samples' Catmull-Rom curve: its own values at the samples, and its slope the same
    on both sides of a sample (a linear blend jumps in slope there by the change of the
    miter's step)."""
    K = 21
    s = np.linspace(0.0, 10.0, K)
    edge = np.stack([s, np.zeros(K), np.zeros(K)], axis=1)
    ang = 0.02 * s ** 2
    m = np.stack([np.sin(ang), np.zeros(K), np.cos(ang)], axis=1)
    sharp = region_edges.SharpEdges(edge, m, np.ones(K), np.zeros(K, int), band=2.0)
    at = np.stack([s[5:15], np.zeros(10), np.full(10, 1e-3)], axis=1)
    np.testing.assert_allclose(sharp.nearest(at)[1], m[5:15], atol=1e-12)
    h = 1e-4
    for k in (7, 10, 13):
        x = np.array([[s[k] - 2 * h, 0, 1e-3], [s[k] - h, 0, 1e-3], [s[k], 0, 1e-3],
                      [s[k] + h, 0, 1e-3], [s[k] + 2 * h, 0, 1e-3]])
        v = sharp.nearest(x)[1]
        left, right = (v[2] - v[0]) / (2 * h), (v[4] - v[2]) / (2 * h)
        np.testing.assert_allclose(left, right, atol=1e-3)
        # the linear blend's slopes either side differ by the miter's step change
        lin = (m[k + 1] - m[k]) / 0.5 - (m[k] - m[k - 1]) / 0.5
        assert np.linalg.norm(lin) > 0.02
