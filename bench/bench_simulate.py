"""Virtual machining on the bundled example's face: the papers' table and timings.

    /usr/bin/python3 bench/bench_simulate.py [--grid 45] [--replicas 4] [--sigma 0.0015]

Prints, per case, wall seconds and the before/after table (mean (range) over replicas)
for the default Werner-like model, and the per-replica standard deviations (mirror paper
Tab. 2 form). No FreeCAD needed: the face is rebuilt from examples/make_example.py's poles.
"""

import argparse
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.core import bspline  # noqa: E402
from surfcomp.core import simulate as sm  # noqa: E402

Z = np.array([[0.0, 1.5, 3.0, 3.5, 3.0, 2.0, 1.0],
              [1.0, 3.0, 5.5, 6.0, 5.0, 3.5, 2.0],
              [2.0, 4.5, 8.0, 9.0, 7.5, 5.0, 3.0],
              [2.5, 5.0, 8.5, 10.0, 8.0, 5.5, 3.5],
              [2.0, 4.0, 7.0, 8.0, 7.0, 5.0, 3.0],
              [1.0, 2.5, 4.5, 5.5, 4.5, 3.5, 2.0],
              [0.0, 1.0, 2.5, 3.0, 2.5, 1.5, 1.0]])


def example_surface():
    x = np.linspace(0.0, 45.0, 7)
    P = np.stack(np.meshgrid(x, x, indexing="ij") + [Z], axis=-1)
    k = np.array([0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1.0])
    return bspline.Surface(P, k, k, 3, 3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, nargs="*", default=[23, 45])
    ap.add_argument("--replicas", type=int, default=4)
    ap.add_argument("--sigma", type=float, nargs="*", default=[0.0015, 0.004])
    ap.add_argument("--correlation-length", type=float, default=0.0)
    args = ap.parse_args()
    surf = example_surface()
    for g in args.grid:
        for s in args.sigma:
            model = sm.MachiningModel(sigma=s, correlation_length=args.correlation_length)
            t = time.perf_counter()
            res = sm.simulate(surf, 1, model, grid=(g, g), replicas=args.replicas, seed=2022)
            dt = time.perf_counter() - t
            print("== grid %dx%d, sigma %.1f um, L %.1f mm, %d replicas x %d methods: %.2f s"
                  % (g, g, s * 1e3, args.correlation_length, args.replicas, len(res.labels), dt))
            print(res.table())
            print(res.replica_table("std"))
            print()


if __name__ == "__main__":
    main()
