# SPDX-License-Identifier: LGPL-2.1-or-later
"""Peak memory of the commands that grow with their input, beside the estimate that
``--max-memory`` is checked against (``surfcomp.core.budget``), each in a fresh process::

    /usr/bin/python3 bench/bench_memory.py [--grids 100,200,400] [--points 250000,1000000]
        [--lines 200000] [--segment-length MM] [--whole] [--keep DIR]

- ``simulate NOMINAL --grid NxN --replicas 1`` (the example face, between 2);
- ``inspect NOMINAL POINTS --report R.json`` on scattered ``x y z`` points (the report
  with every point, written in parts);
- ``gcode PROGRAM`` on a program of random G1 moves, and its peak above the baseline of
  the same command on a 4-line program, per line (``--whole``: beside the reference of
  the whole program compensated at once, as before the block-by-block reading).

Prints one row per run: peak RSS (MB), the estimate (MB), their ratio, wall seconds, and the
peak per grid point, point or line. An estimate below the measured peak is a defect of
the estimate (the ratio column must stay above 1).
"""

import argparse
import os
import random
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "bench"))

from bench_scale import NOMINAL, scattered_points, timed, write_xyz  # noqa: E402

from surfcomp.core import budget  # noqa: E402

AXIS_CSV = "axis,position,ex,ey,ez\nX,0,0,0,0\nX,100,0.01,0.002,0\nY,0,0,0,0\nY,100,0,-0.01,0\n"


def _row(name, run, estimate, items, unit):
    peak = run["peak_mb"]
    est = estimate / 1024 ** 2
    print("%-34s %9.0f %9.0f %6.2f %8.1f %10.0f B/%s" % (
        name, peak, est, est / peak, run["wall"], peak * 1024 ** 2 / items, unit), flush=True)


def simulate_case(n):
    run = timed([sys.executable, "-m", "surfcomp", "simulate", NOMINAL, "--grid",
                 "%dx%d" % (n, n), "--replicas", "1", "--quiet", "--max-memory", "1T"])
    e = (2 * (n - 1) + 1) ** 2
    _row("simulate --grid %dx%d" % (n, n), run, budget.simulate_bytes(e, n * n, 1, 5),
         n * n, "node")


def inspect_case(n, folder):
    meas = write_xyz(scattered_points(n), os.path.join(folder, "points_%d.xyz" % n))
    run = timed([sys.executable, "-m", "surfcomp", "inspect", NOMINAL, meas, "--quiet",
                 "--report", os.path.join(folder, "r_%d.json" % n), "--max-memory", "1T"])
    _row("inspect %d points --report" % n, run, budget.job_bytes(n), n, "point")


#: the whole program at once, as ``gcode`` did before it read blocks (issue 25, item 7):
#: the reference the block-by-block peak is measured beside
WHOLE = """
import sys
from surfcomp.core.axis.axis_errors import fit_axis_errors
from surfcomp.io.axis_csv import read_axis_errors
from surfcomp.io.gcode import compensate_gcode, read_gcode
model = fit_axis_errors(read_axis_errors(sys.argv[2]).data)
res = compensate_gcode(read_gcode(sys.argv[1]), model, max_error=1.0, source=sys.argv[1],
                       segment_length=float(sys.argv[4]))
open(sys.argv[3], "wb").write(res.data)
"""


def _program(lines, folder):
    rng = random.Random(lines)
    prog = os.path.join(folder, "program_%d.ngc" % lines)
    with open(prog, "w", encoding="ascii") as fh:
        fh.write("G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\n")
        for _ in range(lines):
            fh.write("G1 X%.4f Y%.4f Z%.4f\n" % (rng.uniform(0, 100), rng.uniform(0, 100),
                                                 rng.uniform(-1, 0)))
        fh.write("M2\n")
    return prog


def gcode_case(lines, folder, whole=False, segment_length=2.0):
    """``gcode`` on ``lines`` random G1 lines; the peak above the process's baseline (the
    same command on a 4-line program) per line; with ``whole``, the whole-program
    reference beside it."""
    errors = os.path.join(folder, "errors.csv")
    with open(errors, "w", encoding="ascii") as fh:
        fh.write(AXIS_CSV)

    def cli(prog, out):
        return timed([sys.executable, "-m", "surfcomp", "gcode", prog, "--axis-errors",
                      errors, "-o", out, "--max-memory", "1T", "--segment-length",
                      repr(segment_length)])

    base = cli(_program(1, folder), os.path.join(folder, "out_1.ngc"))["peak_mb"]
    prog = _program(lines, folder)
    runs = [("gcode %d lines" % lines, cli(prog, os.path.join(folder, "out_%d.ngc" % lines)))]
    if whole:
        runs.append(("  whole program at once", timed(
            [sys.executable, "-c", WHOLE, prog, errors,
             os.path.join(folder, "whole_%d.ngc" % lines), repr(segment_length)])))
    for name, run in runs:
        _row(name, run, budget.gcode_bytes(lines + 4), lines, "line")
        print("%-34s %9.0f MB above the baseline (%.0f MB): %.0f B/line" % (
            "", run["peak_mb"] - base, base, (run["peak_mb"] - base) * 1024 ** 2 / lines),
            flush=True)
    os.remove(prog)


def _sizes(text):
    return [int(float(t)) for t in text.split(",") if t.strip()]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grids", default="100,200,400")
    ap.add_argument("--points", default="250000,1000000")
    ap.add_argument("--lines", default="200000")
    ap.add_argument("--segment-length", type=float, default=2.0,
                    help="gcode's --segment-length (2 mm: 2 million lines of random moves "
                         "up to 140 mm are more than its 10 million segments; use 20)")
    ap.add_argument("--whole", action="store_true",
                    help="also run gcode's whole-program reference (before the blocks)")
    ap.add_argument("--keep", metavar="DIR", help="keep the generated files here")
    args = ap.parse_args(argv)
    folder = args.keep or tempfile.mkdtemp(prefix="bench-memory-")
    os.makedirs(folder, exist_ok=True)
    print("%-34s %9s %9s %6s %8s %12s" % ("run", "peak MB", "est. MB", "est/pk", "wall s",
                                          "peak per"))
    for n in _sizes(args.grids):
        simulate_case(n)
    for n in _sizes(args.points):
        inspect_case(n, folder)
    for n in _sizes(args.lines):
        gcode_case(n, folder, args.whole, args.segment_length)
    if not args.keep:
        import shutil

        shutil.rmtree(folder)


if __name__ == "__main__":
    main()
