# SPDX-License-Identifier: LGPL-2.1-or-later
"""The B-spline collocation matrix: scipy's ``BSpline.design_matrix`` (what
``surfcomp.core.bspline_basis.basis_matrix`` uses from ``SCIPY_FROM`` parameters on where
the installed scipy has it with extrapolation, 1.10 and later) beside the hand-written
basis (NURBS book A2.2), in the same run.

    /usr/bin/python3 bench/bench_basis.py [--points 1000,100000,1000000] [--degree 3]
        [--spans 200] [--repeat 3]

Prints per size the best of ``--repeat`` times of each, their ratio (hand-written over
scipy: above 1, scipy is faster) and the largest difference between the two matrices.
"""

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.core import bspline_basis as bb  # noqa: E402


def best(fn, repeat):
    out, times = None, []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


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
