# SPDX-License-Identifier: LGPL-2.1-or-later
"""The B-spline collocation matrix: scipy's ``BSpline.design_matrix`` (what
``surfcomp.core.surface.bspline_basis.basis_matrix`` uses from ``SCIPY_FROM`` parameters on where
the installed scipy has it with extrapolation, 1.10 and later) beside the hand-written
basis (NURBS book A2.2), in the same run.

    /usr/bin/python3 bench/bench_basis.py [--points 1000,100000,1000000] [--degree 3]
        [--spans 200] [--repeat 3]

Prints per size the best of ``--repeat`` times of each, their ratio (hand-written over
scipy: above 1, scipy is faster) and the largest difference between the two matrices.
Then, where the installed scipy has ``NdBSpline`` (1.12 and later), surface points,
first and second derivatives of the example face by it beside the hand-written evaluation
(``surfcomp.core.surface.bspline.evaluate`` uses it for points,
:mod:`surfcomp.core.surface.bspline_nd`), wall and CPU seconds (the hand-written path runs on the
chunk threads), and the largest difference relative to the face's size.
"""

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.core.surface import bspline_basis as bb  # noqa: E402


def best(fn, repeat):
    out, times = None, []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def surface_rows(args):
    """Points and derivatives of the example face by scipy's NdBSpline and by hand."""
    from surfcomp.core.simulation.presets import werner_surface
    from surfcomp.core.surface import bspline, bspline_nd
    if bspline_nd.ndbspline() is None:
        print("scipy.interpolate.NdBSpline: missing (points evaluated by hand)")
        return
    s = werner_surface()
    nd = bspline_nd.ndbspline()((s.knots_u, s.knots_v), s.poles, (s.degree_u, s.degree_v))
    print("%10s %6s %17s %17s %7s %10s" % ("points", "order", "hand wall (CPU) s",
                                           "NdBSpline wall s", "ratio", "max diff"))
    rng = np.random.default_rng(0)
    for m in (int(x) for x in args.points.split(",")):
        u, v = rng.uniform(*s.u_range, m), rng.uniform(*s.v_range, m)
        xi = np.stack([u, v], axis=1)
        for order in (0, 1, 2):
            def hand(order=order, u=u, v=v):
                chosen, bspline.point_evaluator = bspline.point_evaluator, lambda *a: None
                c0 = time.process_time()
                try:
                    return bspline._all_ders(s, u, v, order)
                finally:
                    hand.cpu = time.process_time() - c0
                    bspline.point_evaluator = chosen

            def scipy_nd(order=order, u=u, v=v, xi=xi):
                if order == 0:                      # what surfcomp runs
                    return bspline._all_ders(s, u, v, 0)
                return [nd(xi, nu=k) for k in bspline._ORDER_KEYS[order]]
            ours, a = best(hand, args.repeat)
            theirs, b = best(scipy_nd, args.repeat)
            diff = max(np.abs(x - y).max() for x, y in zip(a, b)) / np.abs(a[0]).max()
            print("%10d %6d %9.4f (%5.3f) %17.4f %7.2f %10.1e"
                  % (m, order, ours, hand.cpu, theirs, ours / theirs, diff))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", default="1000,100000,1000000")
    ap.add_argument("--degree", type=int, default=3)
    ap.add_argument("--spans", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    import scipy

    p = args.degree
    knots = np.r_[[0.0] * p, np.linspace(0.0, 1.0, args.spans + 1), [1.0] * p]
    n_poles = knots.size - p - 1
    print("scipy %s: BSpline.design_matrix with extrapolate %s" % (
        scipy.__version__, "used from %d points on" % bb.SCIPY_FROM
        if bb.scipy_design_matrix() is not None else "missing"))
    if bb.scipy_design_matrix() is None:
        return 1
    print("%10s %14s %14s %7s %10s" % ("points", "hand-written s", "scipy s", "ratio",
                                         "max diff"))
    rng = np.random.default_rng(0)
    for m in (int(x) for x in args.points.split(",")):
        t = rng.uniform(0.0, 1.0, m)
        ours, a = best(lambda t=t: bb._basis_matrix(knots, p, n_poles, t), args.repeat)
        theirs, b = best(lambda t=t: bb._scipy_basis_matrix(knots, p, t), args.repeat)
        diff = abs(a - b).max() if m else 0.0
        print("%10d %14.4f %14.4f %7.2f %10.1e" % (m, ours, theirs, ours / theirs, diff))
    return 0


if __name__ == "__main__":
    sys.exit(main())
