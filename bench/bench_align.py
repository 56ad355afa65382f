# SPDX-License-Identifier: LGPL-2.1-or-later
"""Best fit of measured points to the example face, beside a point-to-plane ICP baseline.

Run: /usr/bin/python3 bench/bench_align.py [--points N] [--grid G] [--workers W] [--sigma MM]

Data: N points (default 1,000,000) spread over the bundled example face
(:func:`surfcomp.core.simulation.presets.werner_surface`, 45 x 45 mm), 2 um normal noise (``--sigma
0``: exact points), moved by a known rigid transform (3 degrees about a skew axis, 5 mm). Ours: the
whole :func:`surfcomp.core.measurement.align.best_fit` call (projection engines built,
pre-alignment, the fit on a subsample, then on all points, exact point-to-surface distance, Tukey
weights). Baseline in the same run on the same points: point-to-plane ICP (Chen & Medioni 1992)
against a G x G tessellation of the face (vertex normals), nearest vertex by scipy's
cKDTree, least squares, iterated until a step moves no point more than 1e-9 mm (at most
100 iterations). Both are compared with the known transform: rotation error and the
largest error of a point of the face. Nothing here is a test: it prints figures.
"""

import argparse
import os
import sys
import time

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.core.measurement import align  # noqa: E402
from surfcomp.core.simulation.presets import werner_surface  # noqa: E402
from surfcomp.core.surface import bspline  # noqa: E402


def data(surf, n, sigma=2e-3, seed=28):
    rng = np.random.default_rng(seed)
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    S = bspline.evaluate(surf, u, v)
    pts = S + bspline.normals(surf, u, v) * rng.normal(0.0, sigma, n)[:, None]
    axis = np.array([1.0, 2.0, 0.5]) / np.linalg.norm([1.0, 2.0, 0.5])
    T = align.rigid(Rotation.from_rotvec(axis * np.radians(3.0)).as_matrix(),
                    [3.0, -4.0, 0.0])
    return align.apply(T, pts), T, S


def icp(P, surf, grid, max_iter=100, tol=1e-9):
    """Point-to-plane ICP on a tessellation; returns (matrix, iterations)."""
    us = np.linspace(*surf.u_range, grid)
    vs = np.linspace(*surf.v_range, grid)
    V = bspline.evaluate_grid(surf, us, vs).reshape(-1, 3)
    U, W = np.meshgrid(us, vs, indexing="ij")
    N = bspline.normals(surf, U.ravel(), W.ravel())
    tree = cKDTree(V)
    M = np.eye(4)
    for it in range(1, max_iter + 1):
        Q = align.apply(M, P)
        _d, k = tree.query(Q, workers=-1)
        n = N[k]
        r = np.einsum("ij,ij->i", Q - V[k], n)
        c = Q.mean(axis=0)
        J = np.hstack([n, np.cross(Q - c, n)])
        x = np.linalg.lstsq(J, -r, rcond=None)[0]
        M = align.step_matrix(x, c) @ M
        reach = np.sqrt(((Q - c) ** 2).sum(axis=1).max())
        if np.linalg.norm(x[:3]) + np.linalg.norm(x[3:]) * reach <= tol:
            return M, it
    return M, max_iter


def accuracy(M, T, S):
    E = M @ T
    rot = np.linalg.norm(Rotation.from_matrix(E[:3, :3]).as_rotvec())
    return rot, np.abs(align.apply(E, S) - S).max()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--grid", type=int, default=400)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--sigma", type=float, default=2e-3, help="normal noise (mm)")
    a = ap.parse_args()
    surf = werner_surface()
    P, T, S = data(surf, a.points, a.sigma)
    t0, c0 = time.perf_counter(), time.process_time()
    fit, label = align.best_fit(P, [align.Reference("Face1", surf)], workers=a.workers)
    t_ours, c_ours = time.perf_counter() - t0, time.process_time() - c0
    t0, c0 = time.perf_counter(), time.process_time()
    M_icp, it_icp = icp(P, surf, a.grid)
    t_icp, c_icp = time.perf_counter() - t0, time.process_time() - c0
    sigma_n = a.sigma / np.sqrt(a.points)
    print("best fit of %d points to the example face (%g um noise, moved 3 deg / 5 mm), "
          "%d cores" % (a.points, a.sigma * 1e3, os.cpu_count()))
    print("%-44s %8s %8s %6s %12s %12s" % ("", "wall s", "CPU s", "iter", "rot err rad",
                                            "max err um"))
    for name, M, t, cpu, it in (("ours: exact distance, robust (%s start)" % label,
                                 fit.matrix, t_ours, c_ours, fit.iterations),
                                ("ICP point-to-plane, %dx%d tessellation" % (a.grid, a.grid),
                                 M_icp, t_icp, c_icp, it_icp)):
        rot, err = accuracy(M, T, S)
        print("%-44s %8.2f %8.2f %6d %12.3g %12.4f" % (name, t, cpu, it, rot, err * 1e3))
    print("time ratio ICP / ours: %.2f wall, %.2f CPU (above 1: ours is faster)"
          % (t_icp / t_ours, c_icp / c_ours))
    print("noise floor sigma/sqrt(N): %.4f um" % (sigma_n * 1e3))


if __name__ == "__main__":
    main()
