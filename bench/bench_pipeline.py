# SPDX-License-Identifier: LGPL-2.1-or-later
"""End-to-end benchmark of ``compensate``: the bundled example and n x n grids up to 1000 x 1000.

    /usr/bin/python3 bench/bench_pipeline.py [--sizes 45,200,500,1000] [--rotated 500,1000]
                                             [--keep DIR]

Each case runs in a fresh subprocess (so peak memory is its own) through the same code
path as ``python3 -m surfcomp compensate NOMINAL MEAS -o OUT.step`` and prints wall
seconds per stage (read, locate + grid, filter + corrected surface + checks, STEP),
the whole job, peak RSS of that job, the corrected face's poles and check figures, and
the time of an ``inspect --report OUT.json`` run (the JSON with every point). Grids run
along the face's parameter lines (dense ones get knots on the node lines, one span per
grid step) or are turned by 20 degrees ("turn": rows found from the file order; the
construction across parameter lines needs more than one span per grid step).
The synthetic cases use the example's face and a Werner-like deviation field with noise.
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)


def make_case(n, folder, rotated=False):
    """Write a CMM-style CSV with an n x n grid on the example face; return its path.

    The grid runs along the face's parameter lines, or (``rotated``) turned by 20 degrees
    in the parameter plane, so its rows cross the parameter lines (the general case).
    """
    import numpy as np

    from examples.make_example import deviation_field, nominal_surface
    from surfcomp.app.convert import surface_from_part
    from surfcomp.core.surface.bspline import derivatives

    surf = surface_from_part(nominal_surface())
    t = np.linspace(0.01, 0.99, n)
    U, V = np.meshgrid(t, t, indexing="ij")
    if rotated:
        a, c = np.radians(20.0), 0.5
        U, V = (c + 0.68 * ((U - c) * np.cos(a) - (V - c) * np.sin(a)),
                c + 0.68 * ((U - c) * np.sin(a) + (V - c) * np.cos(a)))
    S, Su, Sv = derivatives(surf, U, V, order=1)
    nrm = np.cross(Su, Sv)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    rng = np.random.default_rng(n)
    d = deviation_field(S[..., 0], S[..., 1]) + rng.normal(0, 0.0015, S.shape[:2])
    path = os.path.join(folder, "grid%d%s.csv" % (n, "r" if rotated else ""))
    data = np.concatenate([S.reshape(-1, 3), nrm.reshape(-1, 3), d.reshape(-1, 1)], axis=1)
    np.savetxt(path, data, delimiter=",", fmt="%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.6f",
               header="x_nom,y_nom,z_nom,i,j,k,dev", comments="")
    return path


def run_case(nominal, meas, out_dir):
    """Child process: the CLI's job once (read, locate, filter, corrected face, STEP);
    stage times from the progress callback; print one JSON line."""
    from surfcomp.app import fcenv

    fcenv.import_freecad()
    from surfcomp.app import file_route

    marks = {}

    def progress(fraction, message=""):
        marks.setdefault("read", time.perf_counter())          # first call: file read
        if fraction >= 0.3:
            marks.setdefault("located", time.perf_counter())   # prepare done (job: 0..0.3)
        if fraction >= 0.9:                                     # compensate ends at 0.9
            marks.setdefault("computed", time.perf_counter())

    job = file_route.Job(nominal=nominal, measurements=meas, output=os.path.join(out_dir, "c.step"))
    t0 = time.perf_counter()
    comp, _ = file_route.run_job(job, progress=progress)
    t_end = time.perf_counter()
    times = {"read": marks["read"] - t0, "locate+grid": marks["located"] - marks["read"],
             "filter+surface+checks": marks["computed"] - marks["located"],
             "write STEP": t_end - marks["computed"], "whole job": t_end - t0}
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    t = time.perf_counter()
    file_route.run_job(file_route.Job(nominal=nominal, measurements=meas,
                              report=os.path.join(out_dir, "r.json"), command="inspect"))
    times["inspect + JSON report"] = time.perf_counter() - t
    print(json.dumps({"points": int(comp.prepared.u.size), "grid": list(comp.prepared.grid.shape),
                      "times": times, "peak_mb": peak, "checks": comp.checks.as_dict(),
                      "iterations": comp.iterations}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="45,200,500,1000",
                    help="grids along the face's parameter lines")
    ap.add_argument("--rotated", default="500,1000",
                    help="grids turned by 20 degrees to the parameter lines (rows found from "
                         "the file order; the construction across parameter lines)")
    ap.add_argument("--keep", help="keep generated files in this folder")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return run_case(*args.child)
    folder = args.keep or tempfile.mkdtemp(prefix="surfcomp-bench-")
    os.makedirs(folder, exist_ok=True)
    nominal = os.path.join(ROOT, "examples", "nominal.step")
    cases = [("example", os.path.join(ROOT, "examples", "measurements.csv"))]
    for n in [int(x) for x in args.sizes.split(",") if x]:
        cases.append(("%dx%d" % (n, n), make_case(n, folder)))
    for n in [int(x) for x in args.rotated.split(",") if x]:
        cases.append(("%dx%d turn" % (n, n), make_case(n, folder, rotated=True)))
    print("%-12s %8s %6s %7s %8s %6s %8s %8s %7s %9s %10s %9s" % (
        "case", "points", "read", "locate", "surface", "STEP", "job[s]", "peak MB", "poles",
        "err@pts", "zero", "+JSON[s]"))
    print("%-12s %8s %6s %7s %8s %6s %8s %8s %7s %9s %10s %9s" % (
        "", "", "s", "s", "s", "s", "", "", "", "um", "um", ""))
    per_point = []
    for name, meas in cases:
        out = subprocess.run([sys.executable, __file__, "--child", nominal, meas, folder],
                             capture_output=True, text=True, check=True)
        r = json.loads(out.stdout.strip().splitlines()[-1])
        t = r["times"]
        print("%-12s %8d %6.2f %7.2f %8.2f %6.2f %8.2f %8.0f %7d %9.4f %10.2e %9.2f"
              % (name, r["points"], t["read"], t["locate+grid"], t["filter+surface+checks"],
                 t["write STEP"], t["whole job"], r["peak_mb"], r["checks"]["poles"][0],
                 r["checks"]["max_error_at_points_mm"] * 1e3,
                 r["checks"]["max_deviation_from_nominal_with_zero_correction_mm"] * 1e3,
                 t["inspect + JSON report"]), flush=True)
        per_point.append((name, r["points"], t["whole job"]))
    print("\nseconds per 1000 points (whole job):")
    for name, n, sec in per_point:
        print("  %-12s %.4f" % (name, 1000 * sec / n))
    whole = {name: sec for name, _, sec in per_point}
    for a, b in (("1000x1000", "500x500"), ("1000x1000 turn", "500x500 turn")):
        if a in whole and b in whole:
            print("time(%s) / time(%s) = %.2f (4x the points)" % (a, b, whole[a] / whole[b]))
    print("\nreference: the mirror paper's NX program needed about 30 s per compensation.")


if __name__ == "__main__":
    sys.exit(main())
