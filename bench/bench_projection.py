# SPDX-License-Identifier: LGPL-2.1-or-later
"""Throughput of surfcomp's point projection against FreeCAD's Inspection feature.

Run: /usr/bin/python3 bench/bench_projection.py [--points N] [--fc-points M] [--workers W]

Face: a 7 x 7 pole bicubic B-spline (100 x 60 mm, wavy, seeded), points up to
1 mm off it. Prints points/s and peak memory for 1,000,000 points (ours), then
ours and FreeCAD's ``Inspection::Feature`` (Actual = Points object, Nominals = the
face) on the same 100,000 points; FreeCAD is timed on a subset and extrapolated
(printed as such). Nothing here is a test: it prints figures.
"""

import argparse
import os
import resource
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.core.surface import bspline  # noqa: E402
from surfcomp.core.surface.projection import Projector  # noqa: E402


def bench_face():
    """7 x 7 poles, bicubic, clamped uniform knots, a smooth wavy 100 x 60 mm patch."""
    rng = np.random.default_rng(2024)
    n, p = 7, 3
    knots = np.r_[np.zeros(p + 1), np.linspace(0, 1, n - p + 1)[1:-1], np.ones(p + 1)]
    gx, gy = np.meshgrid(np.linspace(0, 100, n), np.linspace(0, 60, n), indexing="ij")
    gz = 8 * np.sin(gx / 25) * np.cos(gy / 30) + rng.normal(scale=1.0, size=gx.shape)
    return bspline.Surface(np.stack([gx, gy, gz], axis=2), knots, knots, p, p)


def bench_points(surf, n, seed=7):
    rng = np.random.default_rng(seed)
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    d = rng.uniform(-1.0, 1.0, n)
    S = bspline.evaluate(surf, u, v)
    return S + d[:, None] * bspline.normals(surf, u, v), S, d


def maxrss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def time_ours(surf, X, workers, repeat=2):
    best, res = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = Projector(surf, workers=workers).project(X)
        best = min(best, time.perf_counter() - t0)
    return best, res


def time_freecad(surf, X):
    """Inspection::Feature distances of the points X to the face: (wall seconds,
    distances, CPU seconds) of the recompute."""
    from surfcomp.app import fcenv
    fcenv.import_freecad()
    import FreeCAD
    import Inspection  # noqa: F401  (registers Inspection::Feature)
    import Part
    import Points

    from surfcomp.app.convert import surface_to_part

    doc = FreeCAD.newDocument("bench_projection")
    try:
        face = Part.Face(surface_to_part(surf))
        nominal = doc.addObject("Part::Feature", "Nominal")
        nominal.Shape = face
        actual = doc.addObject("Points::Feature", "Actual")
        actual.Points = Points.Points([FreeCAD.Vector(*p) for p in X.tolist()])
        insp = doc.addObject("Inspection::Feature", "Inspection")
        insp.Actual = actual
        insp.Nominals = [nominal]
        insp.SearchRadius = 5.0
        t0, c0 = time.perf_counter(), time.process_time()
        doc.recompute()
        elapsed, cpu = time.perf_counter() - t0, time.process_time() - c0
        dist = np.array(insp.Distances, dtype=float)
    finally:
        FreeCAD.closeDocument(doc.Name)
    return elapsed, dist, cpu


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--compare", type=int, default=100_000,
                    help="points of the FreeCAD comparison set")
    ap.add_argument("--fc-points", type=int, default=5000,
                    help="subset of the comparison set FreeCAD really projects")
    ap.add_argument("--workers", type=int, default=None, help="threads (default: all CPUs)")
    args = ap.parse_args(argv)

    surf = bench_face()
    print("face: %d x %d poles, degree %d x %d; CPUs: %d"
          % (surf.shape[0], surf.shape[1], surf.degree_u, surf.degree_v, os.cpu_count()))

    X, S, d = bench_points(surf, args.points)
    base = maxrss_mb()
    t, r = time_ours(surf, X, args.workers)
    peak = maxrss_mb()
    print("ours    : %9d points in %.3f s = %10.0f points/s  (setup included, best of 2)"
          % (args.points, t, args.points / t))
    print("          peak RSS %.0f MB, %.0f MB above the input arrays (%.0f MB per million points)"
          % (peak, peak - base, (peak - base) / (args.points / 1e6)))
    print("          max |d - d_true| = %.2e mm, max |foot - foot_true| = %.2e mm, "
          "converged %d / %d" % (np.abs(r.distance - d).max(), np.abs(r.foot - S).max(),
                                 r.converged.sum(), args.points))

    Xc, Sc, dc = bench_points(surf, args.compare, seed=8)
    tc, rc = time_ours(surf, Xc, args.workers)
    print("ours    : %9d points in %.3f s = %10.0f points/s"
          % (args.compare, tc, args.compare / tc))
    sub = Xc[: args.fc_points]
    tf, df, _ = time_freecad(surf, sub)
    rate_fc = sub.shape[0] / tf
    print("FreeCAD : Inspection::Feature on the first %d of them: %.3f s = %.0f points/s"
          % (sub.shape[0], tf, rate_fc))
    print("          extrapolated to %d points: %.0f s (linear extrapolation, not measured)"
          % (args.compare, args.compare / rate_fc))
    print("ratio   : ours / FreeCAD = %.0f x faster" % ((args.compare / tc) / rate_fc))
    ok = np.isfinite(df)
    print("check   : |ours| vs Inspection distances on the subset: max diff %.2e mm "
          "(Inspection stores float32), %d of %d within its search radius"
          % (np.abs(np.abs(rc.distance[: sub.shape[0]][ok]) - np.abs(df[ok])).max(),
             ok.sum(), sub.shape[0]))


if __name__ == "__main__":
    main()
