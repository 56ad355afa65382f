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

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from examples.make_example import example_surface  # noqa: E402
from surfcomp.core import simulate as sm  # noqa: E402


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
