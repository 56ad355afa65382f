# SPDX-License-Identifier: LGPL-2.1-or-later
"""Best fit of measured points to the example face, beside a point-to-plane ICP baseline.

Run: /usr/bin/python3 bench/bench_align.py [--points N] [--grid G] [--workers W] [--sigma MM]
[--quick]

Data: N points (default 1,000,000) spread over the bundled example face
(:func:`surfcomp.core.simulation.presets.werner_surface`, 45 x 45 mm), 2 um normal noise (``--sigma
0``: exact points), moved by a known rigid transform (3 degrees about a skew axis, 5 mm). Ours: the
whole :func:`surfcomp.core.measurement.align.best_fit` call (projection engines built,
pre-alignment, the fit on a subsample, then on all points, exact point-to-surface distance, Tukey
weights). Baseline in the same run on the same points: point-to-plane ICP (Chen & Medioni 1992)
against a G x G tessellation of the face (vertex normals), nearest vertex by scipy's
cKDTree, least squares, iterated until a step moves no point more than 1e-9 mm (at most
100 iterations). Both are compared with the known transform: rotation error and the
largest error of a point of the face. Beside them (not with ``--quick``): the same fit
projecting every point afresh at every iteration (``warm=False``, the exact reference of
the default, which answers later iterations from each point's last foot), how far the two
fits' answers differ on the face, and the whole process: a fresh interpreter that imports
surfcomp, loads the points from a ``.npy`` file and fits them. Nothing here is a test: it
prints figures.
"""

import argparse
import os
import resource
import subprocess
import sys
import tempfile
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


def timed(call):
    t0, c0 = time.perf_counter(), time.process_time()
    out = call()
    return out, time.perf_counter() - t0, time.process_time() - c0


def whole_process(P, workers):
    """``(matrix, wall s, CPU s, iterations)`` of a fresh interpreter that imports
    surfcomp, loads ``P`` from a .npy file and fits it (the child's own CPU, from the
    operating system)."""
    with tempfile.TemporaryDirectory() as tmp:
        src, out = os.path.join(tmp, "points.npy"), os.path.join(tmp, "fit.npz")
        np.save(src, P)
        cmd = [sys.executable, os.path.abspath(__file__), "--child", src, out]
        if workers:
            cmd += ["--workers", str(workers)]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        with np.load(out) as f:
            return f["matrix"], wall, cpu, int(f["iterations"])


def child(src, out, workers):
    fit, _label = align.best_fit(np.load(src), [align.Reference("Face1", werner_surface())],
                                 workers=workers)
    np.savez(out, matrix=fit.matrix, iterations=fit.iterations)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--grid", type=int, default=400)
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--sigma", type=float, default=2e-3, help="normal noise (mm)")
    ap.add_argument("--quick", action="store_true",
                    help="only ours and the ICP baseline (no reference fit, no process)")
    ap.add_argument("--child", nargs=2, metavar=("POINTS", "OUT"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        return child(*a.child, a.workers)
    surf = werner_surface()
    ref = [align.Reference("Face1", surf)]
    P, T, S = data(surf, a.points, a.sigma)
    (fit, label), t_ours, c_ours = timed(lambda: align.best_fit(P, ref, workers=a.workers))
    (M_icp, it_icp), t_icp, c_icp = timed(lambda: icp(P, surf, a.grid))
    rows = [("ours: exact distance, robust (%s start)" % label, fit.matrix, t_ours, c_ours,
             fit.iterations),
            ("ICP point-to-plane, %dx%d tessellation" % (a.grid, a.grid), M_icp, t_icp, c_icp,
             it_icp)]
    if not a.quick:
        (cold, _), t, c = timed(lambda: align.best_fit(P, ref, workers=a.workers, warm=False))
        rows.append(("ours, every iteration projected afresh", cold.matrix, t, c,
                     cold.iterations))
        rows.append(("ours, whole process (start, import, load)",)
                    + whole_process(P, a.workers))
    sigma_n = a.sigma / np.sqrt(a.points)
    print("best fit of %d points to the example face (%g um noise, moved 3 deg / 5 mm), "
          "%d cores, load average %.1f" % (a.points, a.sigma * 1e3, os.cpu_count(),
                                           os.getloadavg()[0]))
    print("%-44s %8s %8s %6s %12s %12s" % ("", "wall s", "CPU s", "iter", "rot err rad",
                                            "max err um"))
    for name, M, t, cpu, it in rows:
        rot, err = accuracy(M, T, S)
        print("%-44s %8.2f %8.2f %6d %12.3g %12.4f" % (name, t, cpu, it, rot, err * 1e3))
    print("time ratio ICP / ours: %.2f wall, %.2f CPU (above 1: ours is faster)"
          % (t_icp / t_ours, c_icp / c_ours))
    if not a.quick:
        gap = np.abs(align.apply(fit.matrix, S) - align.apply(rows[2][1], S)).max()
        print("ours vs. every iteration afresh: largest difference on the face %.3g um"
              % (gap * 1e3))
    print("noise floor sigma/sqrt(N): %.4f um" % (sigma_n * 1e3))


if __name__ == "__main__":
    main()
