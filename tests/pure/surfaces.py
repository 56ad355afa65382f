# SPDX-License-Identifier: LGPL-2.1-or-later
"""Small core surfaces shared by tests (no FreeCAD)."""

import numpy as np

from surfcomp.core.surface import bspline
from surfcomp.core.surface.bspline import Surface


def wavy_patch():
    """A bicubic 30 x 30 mm patch, 5 x 5 poles, z = 2 sin(x/12) cos(y/15), one inner knot."""
    x = np.linspace(0.0, 30.0, 5)
    X, Y = np.meshgrid(x, x, indexing="ij")
    Z = 2.0 * np.sin(X / 12.0) * np.cos(Y / 15.0)
    k = np.array([0, 0, 0, 0, 0.5, 1, 1, 1, 1.0])
    return bspline.Surface(np.stack([X, Y, Z], axis=-1), k, k, 3, 3)


def bezier_knots(p):
    return np.r_[np.zeros(p + 1), np.ones(p + 1)]


def random_surface(rng, nu=7, nv=6, pu=3, pv=2, rational=False, interior_double=True):
    ku = np.r_[np.zeros(pu + 1), np.sort(rng.uniform(0.05, 0.95, nu - pu - 1)), np.ones(pu + 1)]
    if interior_double and nu - pu - 1 >= 2:
        ku[pu + 2] = ku[pu + 1]  # a double interior knot
    kv = np.r_[np.zeros(pv + 1), np.sort(rng.uniform(0.05, 0.95, nv - pv - 1)), np.ones(pv + 1)]
    kv = kv * 3.0 - 1.0  # v domain [-1, 2]
    gu, gv = np.meshgrid(np.linspace(0, 100, nu), np.linspace(0, 60, nv), indexing="ij")
    poles = np.stack([gu, gv, 10 * np.sin(gu / 30) * np.cos(gv / 20)], axis=2)
    poles += rng.normal(scale=3.0, size=poles.shape)
    w = rng.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return Surface(poles, ku, kv, pu, pv, w)


def quarter_cylinder(R=25.0, H=40.0):
    """Rational quadratic x linear quarter cylinder around the z axis."""
    ring = np.array([[R, 0, 0], [R, R, 0], [0, R, 0]], float)
    poles = np.stack([ring, ring + [0, 0, H]], axis=1)  # (3, 2, 3)
    w = np.array([[1, 1], [np.sqrt(0.5)] * 2, [1, 1]])
    return Surface(poles, bezier_knots(2), bezier_knots(1), 2, 1, w)

def sphere_octant(R=10.0):
    """Exact rational octant of a sphere; its u = 0 edge collapses into the pole (0, 0, R)."""
    s = np.sqrt(0.5)
    mer = np.array([[0, R], [R, R], [R, 0]], float)  # (x, z) of the meridian poles
    wm = np.array([1, s, 1])
    rot = lambda x, z: [[x, 0, z], [x, x, z], [0, x, z]]  # noqa: E731
    poles = np.array([rot(x, z) for x, z in mer], float)
    w = wm[:, None] * wm[None, :]
    return Surface(poles, bezier_knots(2), bezier_knots(2), 2, 2, w)


def hairpin(n=60):
    """A hairpin profile (two parallel legs 2 mm apart joined by a 1 mm radius bend),
    interpolated by a cubic and extruded 10 mm along y."""
    k = np.r_[0, 0, 0, np.linspace(0, 1, n - 2), 1, 1, 1]
    g = bspline.greville(k, 3)
    t = g * (40 + np.pi)
    x = np.where(t < 20, 20 - t, np.where(t < 20 + np.pi, -np.sin(t - 20), t - 20 - np.pi))
    z = np.where(t < 20, 0.0, np.where(t < 20 + np.pi, 1 - np.cos(t - 20), 2.0))
    prof = np.stack([x, np.zeros(n), z], 1)
    pts = np.stack([prof, prof + [0, 10.0, 0]], axis=1)
    kv = np.r_[0, 0, 1, 1.0]
    return Surface(bspline.interpolate_grid(g, [0.0, 1.0], pts, k, kv, 3, 1), k, kv, 3, 1)


def cube_corner_edges():
    """The corner of the cube [0, 10]^3 at the origin: three sharp edges (along x, y, z, 101
    samples each) ending at one vertex, each between two of the faces x = 0, y = 0, z = 0.
    Returns ``(points, miters, extents, edge ids, the two faces' normals)`` as
    :func:`surfcomp.core.compensation.region_edges.at_vertices` takes them, and the faces'
    outward normals by axis."""
    from surfcomp.core.compensation import region_build

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
    return tuple(np.concatenate(x) for x in (pts, mit, ex, eid, nrm)), n
