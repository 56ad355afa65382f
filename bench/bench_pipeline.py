"""End-to-end benchmark of ``compensate``: the bundled example and 45x45, 200x200, 500x500 grids.

    /usr/bin/python3 bench/bench_pipeline.py [--sizes 45,200,500] [--keep DIR]

Each case runs in a fresh subprocess (so peak memory is its own) through the same code
path as ``python3 -m surfcomp compensate ... -o OUT.step --report OUT.json``, and prints
wall seconds per stage, total seconds, peak RSS and the corrected face's check figures.
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


def make_case(n, folder):
    """Write a CMM-style CSV with an n x n grid on the example face; return its path."""
    import numpy as np

    from examples.make_example import deviation_field, nominal_surface
    from surfcomp.app.convert import surface_from_part
    from surfcomp.core.bspline import evaluate_grid

    surf = surface_from_part(nominal_surface())
    t = np.linspace(0.01, 0.99, n)
    S, Su, Sv = evaluate_grid(surf, t, t, order=1)
    nrm = np.cross(Su, Sv)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    rng = np.random.default_rng(n)
    d = deviation_field(S[..., 0], S[..., 1]) + rng.normal(0, 0.0015, S.shape[:2])
    path = os.path.join(folder, "grid%d.csv" % n)
    data = np.concatenate([S.reshape(-1, 3), nrm.reshape(-1, 3), d.reshape(-1, 1)], axis=1)
    np.savetxt(path, data, delimiter=",", fmt="%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.6f",
               header="x_nom,y_nom,z_nom,i,j,k,dev", comments="")
    return path


def run_case(nominal, meas, out_dir):
    """Child process: run the job with stage timings; print one JSON line."""
    from surfcomp.app import fcenv

    fcenv.import_freecad()
    from surfcomp.app import job as jobmod
    from surfcomp.app.nominal import load_nominal
    from surfcomp.core.pipeline import Options, compensate, prepare
    from surfcomp.io.readers import read_any

    times = {}
    t0 = time.perf_counter()
    nom = load_nominal(nominal)
    ms = read_any(meas)
    times["read"] = time.perf_counter() - t0
    t = time.perf_counter()
    prep = prepare(nom.surface, nom.outward, ms, Options())
    times["locate+grid"] = time.perf_counter() - t
    t = time.perf_counter()
    comp = compensate(nom.surface, nom.outward, prep, Options())
    times["filter+surface+checks"] = time.perf_counter() - t
    t = time.perf_counter()
    job = jobmod.Job(nominal=nominal, measurements=meas, output=os.path.join(out_dir, "c.step"),
                     report=os.path.join(out_dir, "r.json"))
    t_job = time.perf_counter()
    jobmod.run_job(job)
    times["whole job (CLI path, incl. writing STEP+JSON)"] = time.perf_counter() - t_job
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(json.dumps({"points": len(ms), "grid": list(prep.grid.shape), "times": times,
                      "peak_mb": peak, "checks": comp.checks.as_dict(),
                      "iterations": comp.iterations}))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="45,200,500")
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
    print("%-9s %8s %8s %8s %9s %9s %8s %10s %10s" % ("case", "points", "read", "locate",
                                                       "surface", "job[s]", "peak MB",
                                                       "err@pts um", "zero um"))
    per_point = []
    for name, meas in cases:
        out = subprocess.run([sys.executable, __file__, "--child", nominal, meas, folder],
                             capture_output=True, text=True, check=True)
        r = json.loads(out.stdout.strip().splitlines()[-1])
        t = r["times"]
        job_s = t["whole job (CLI path, incl. writing STEP+JSON)"]
        print("%-9s %8d %8.2f %8.2f %9.2f %9.2f %8.0f %10.4f %10.2e"
              % (name, r["points"], t["read"], t["locate+grid"], t["filter+surface+checks"], job_s,
                 r["peak_mb"], r["checks"]["max_error_at_points_mm"] * 1e3,
                 r["checks"]["max_deviation_from_nominal_with_zero_correction_mm"] * 1e3))
        per_point.append((name, r["points"], job_s))
    print("\nseconds per 1000 points (whole job):")
    for name, n, s in per_point:
        print("  %-9s %.4f" % (name, 1000 * s / n))
    print("\nreference: the mirror paper's NX program needed about 30 s per compensation.")


if __name__ == "__main__":
    sys.exit(main())
