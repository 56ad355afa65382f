# SPDX-License-Identifier: LGPL-2.1-or-later
"""Speed of the G-code axis error compensation on CAMotics' bear.nc (15163 lines).

    /usr/bin/python3 bench/bench_gcode.py [--repeat 3] [--segment-length 2]

Prints lines/s (best of ``--repeat`` runs) for: parsing only, compensation with a zero
model (parse + plan + byte-identical output), and with a model of the size of Dobariya
2015 Table 3 (scale, squareness, quadratic Z, flatness: long moves get split), plus the
lines added and the predicted error before/after.
"""

import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from surfcomp.core.axis.axis_errors import AxisErrorModel  # noqa: E402
from surfcomp.io.gcode import compensate_gcode, parse_gcode, read_gcode  # noqa: E402

BEAR = os.path.join(ROOT, "tests", "data", "real", "gcode", "CAMotics_GPL", "bear.nc")


def best(fn, repeat):
    times = []
    result = None
    for _ in range(repeat):
        t = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t)
    return min(times), result


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--segment-length", type=float, default=2.0)
    ap.add_argument("--program", default=BEAR)
    a = ap.parse_args(argv)
    data = read_gcode(a.program)
    n = data.count(b"\n") + (0 if data.endswith(b"\n") else 1)
    model = AxisErrorModel.from_components(
        scale={"x": 3.58e-3, "y": 4.49e-3}, positional={"z": (1.7e-3, 4.25e-5)},
        straightness={"z(x)": (0.0, 2e-6)}, squareness={"xy": 5e-5, "zx": 1e-4})
    print("program: %s (%d lines, %.0f kB)" % (a.program, n, len(data) / 1024))
    t, _ = best(lambda: parse_gcode(data), a.repeat)
    print("parse only:            %7.3f s  %9.0f lines/s" % (t, n / t))
    t, res = best(lambda: compensate_gcode(data, AxisErrorModel.zero(),
                                           segment_length=a.segment_length), a.repeat)
    assert res.data == data
    print("zero model (identity): %7.3f s  %9.0f lines/s" % (t, n / t))
    t, res = best(lambda: compensate_gcode(data, model, segment_length=a.segment_length),
                  a.repeat)
    st = res.stats
    pred = res.predicted(model)
    print("Table-3-size model:    %7.3f s  %9.0f lines/s  (%d lines changed, %d added, "
          "%d moves split)" % (t, n / t, st["lines_changed"], st["lines_added"],
                               st["moves_split"]))
    print("predicted error at %d points: before max %.1f um, after max %.3f um"
          % (pred["before"]["n"], pred["before"]["max_mm"] * 1e3,
             pred["after"]["max_mm"] * 1e3))
    return 0


if __name__ == "__main__":
    sys.exit(main())
