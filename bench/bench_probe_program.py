# SPDX-License-Identifier: LGPL-2.1-or-later
"""Speed of writing the probing program of a plan (LinuxCNC and Fanuc), beside a reference.

    /usr/bin/python3 bench/bench_probe_program.py [--points 10000] [--repeat 3]

Prints the best of ``--repeat`` runs for the program of ``--points`` points on a dome
(checks, moves, text, atomic write, travel summary), one and two touches per point, and
as the reference ``numpy.savetxt`` writing the same tip-centre positions (three per point
with 4 decimals, no program around them): the ratio says what the program's layout costs
beyond writing its numbers.
"""

import argparse
import os
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.io.probe_program import ProbeSettings, write_probe_program  # noqa: E402


def best(fn, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def dome(n, seed=1):
    rng = np.random.default_rng(seed)
    theta = np.radians(rng.uniform(0, 40, n))
    phi = rng.uniform(0, 2 * np.pi, n)
    u = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], 1)
    return ["P%d" % k for k in range(n)], np.array([0, 0, -50.0]) + 60 * u, u


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=10000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    ids, P, N = dome(args.points)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "probe.ngc")
        ref = best(lambda: np.savetxt(out, np.concatenate([P + N, P + 3 * N, P], 1).reshape(
            -1, 3), fmt="%.4f"), args.repeat)
        print("%d points; reference numpy.savetxt of 3 positions per point: %.3f s"
              % (args.points, ref))
        for dialect in ("linuxcnc", "fanuc"):
            for second in (False, True):
                s = ProbeSettings(dialect=dialect, tip_radius=1.0, safe_z=10.0,
                                  second_touch=second)
                t = best(lambda s=s: write_probe_program(out, ids, P, N, s), args.repeat)
                print("  %-8s %s: %.3f s (%.1f x the reference), %d bytes"
                      % (dialect, "two touches" if second else "one touch  ", t, t / ref,
                         os.path.getsize(out)))


if __name__ == "__main__":
    main()
