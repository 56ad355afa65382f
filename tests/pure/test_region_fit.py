# SPDX-License-Identifier: LGPL-2.1-or-later
"""The region's fit with its boundary curves fitted on their own, and the vertices where a
face collapses (issue 30; no FreeCAD)."""

import numpy as np

from surfcomp.core.compensation import region_build, region_edges, region_fit
from surfcomp.core.surface.bspline import Surface, evaluate_grid, fit_grid_lsq


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
    t = np.linspace(0.0, 10.0, 101)
    z = np.zeros_like(t)
    n = {"x": np.array([-1.0, 0, 0]), "y": np.array([0, -1.0, 0]), "z": np.array([0, 0, -1.0])}
    specs = [(np.stack([t, z, z], 1), "y", "z"), (np.stack([z, t, z], 1), "x", "z"),
             (np.stack([z, z, t], 1), "x", "y")]
    pts, mit, ex, eid, nrm = [], [], [], [], []
    for k, (p, a, b) in enumerate(specs):
        na, nb = np.tile(n[a], (len(p), 1)), np.tile(n[b], (len(p), 1))
        m, e = region_build.miters(na, nb, -nb, -na)
        pts.append(p), mit.append(m), ex.append(e), eid.append(np.full(len(p), k))
        nrm.append(np.stack([na, nb], 1))
    args = (np.concatenate(pts), np.concatenate(mit), np.concatenate(ex), np.concatenate(eid),
            np.concatenate(nrm), 1.0, region_edges.knife_limit(region_build.MITER_ANGLE), 1e-6)
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
