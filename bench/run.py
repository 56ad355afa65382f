#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Scan scale in one table: every case next to its reference, measured in the same run.

    /usr/bin/python3 bench/run.py [--scattered 250000,1000000] [--grids 1000]
                                  [--turned 1000] [--blade 250000,1000000]
                                  [--offsets 0.1,1.0] [--skip CASES] [--keep DIR]

Rows (each case in a fresh process, so its peak RSS is its own):

* ``inspect`` end to end on N points scattered over the example face, against FreeCAD's
  ``Inspection::Feature`` on the same points (timed on two subsets and extrapolated
  along that line; bench_scale.py).
* ``compensate`` end to end on the same files (corrected face and STEP included).
* the face build of ``compensate`` on an n x n grid along the face's parameter lines and
  on one turned by 20 degrees (bench_pipeline.py's cases): our construction (space,
  residual iteration, checks) against ``Part.BSplineSurface.interpolate`` through the
  same corrected points, in the same process; then the whole job.
* projection onto the BladeX upper face, against OCCT's ``Surface.parameter`` on a
  sample of the same points.
* CAM's 3D Surface operation on the corrected face against the same operation on the
  nominal (bench_path_op.py).

``ratio`` is the reference's time over ours (above 1: we are faster), or for the CAM row
the corrected face's time over the nominal's. Absolute seconds depend on the machine and
on what else runs on it; the ratios much less. ``--skip`` takes a comma list of
``inspect,compensate,grid,project,cam``.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
sys.path.insert(0, HERE)

import bench_pipeline  # noqa: E402
import bench_scale  # noqa: E402

NOMINAL = bench_scale.NOMINAL
ROW = "%-34s %9s %8s %8s %8s  %-30s %9s %8s  %s"


def _ints(text):
    return [int(x) for x in text.split(",") if x]


def _child(*args):
    """``run.py --child ARGS`` in a fresh process: its JSON line, wall and CPU seconds."""
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child"]
                         + [str(a) for a in args], capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError("child %s failed:\n%s" % (args, out.stderr[-3000:]))
    return json.loads(out.stdout.strip().splitlines()[-1])


def face_build(meas):
    """Child: prepare the grid file, then time our face build (``build_surface``) and
    ``Part.BSplineSurface.interpolate`` through the same corrected points."""
    import resource

    from surfcomp.app import fcenv

    fcenv.import_freecad()
    import FreeCAD
    import Part

    from surfcomp.app.nominal import load_nominal
    from surfcomp.core.compensation.pipeline import Options, build_surface, compensate, prepare
    from surfcomp.io.readers import read_any

    nom = load_nominal(NOMINAL)
    opts = Options()
    prepared = prepare(nom.surface, nom.outward, read_any(meas, None, "auto", None), opts)
    comp = compensate(nom.surface, nom.outward, prepared, opts, build=False)
    t, c = time.perf_counter(), time.process_time()
    build_surface(comp, nom.surface, nom.outward, comp.correction.delta)
    ours = time.perf_counter() - t, time.process_time() - c
    grid = prepared.grid
    pts = comp.corrected_points()[grid.index]                      # (n, m, 3)
    rows = [[FreeCAD.Vector(*p) for p in row] for row in pts.tolist()]
    t = time.perf_counter()
    ref = Part.BSplineSurface()
    ref.interpolate(rows)
    ref_s = time.perf_counter() - t
    ch = comp.checks
    ref_poles = ref.NbUPoles, ref.NbVPoles
    del rows, ref
    return {"wall": ours[0], "cpu": ours[1], "ref": ref_s,
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "note": "%d x %d poles (interpolate: %d x %d), %.4f um at the points"
                    % (ch.poles_shape + ref_poles
                       + (ch.max_error_at_points * 1e3,)),
            "step": step_writers(nom, comp.corrected)}


def step_writers(nom, corrected):
    """Seconds and bytes of the corrected face's STEP: ours from the pole net
    (surfcomp.io.step_face) and OpenCASCADE's ``exportStep`` of the same face."""
    from surfcomp.app.shapes import corrected_shape
    from surfcomp.io.step_face import write_natural_face

    out = corrected_shape(nom, corrected, "face")
    folder = tempfile.mkdtemp(prefix="surfcomp-bench-")
    ours, occt = os.path.join(folder, "ours.step"), os.path.join(folder, "occt.step")
    t = time.perf_counter()
    write_natural_face(ours, out.natural, out.shape.Orientation == "Reversed",
                       out.edge_tolerance)
    t_ours = time.perf_counter() - t
    t = time.perf_counter()
    out.shape.exportStep(occt)
    t_occt = time.perf_counter() - t
    sizes = [os.path.getsize(ours), os.path.getsize(occt)]
    shutil.rmtree(folder)
    return {"wall": t_ours, "ref": t_occt, "mb": [b / 1e6 for b in sizes]}


def _run_child(kind, *args):
    if kind == "build":
        out = face_build(args[0])
    else:  # the whole compensate job; poles, error and file size from its summary
        cmd = [sys.executable, "-m", "surfcomp", "compensate", NOMINAL, args[0], "-o",
               os.path.join(args[1], "run.step"), "--quiet"]
        out = bench_scale.timed(cmd)
        text = out.pop("stdout")
        poles = re.search(r"Corrected face: (\d+) x (\d+) poles", text).groups()
        err = re.search(r"measured points: max ([0-9.e+-]+) um", text).group(1)
        size = int(re.search(r"file size (\d+) bytes", text).group(1))
        out["note"] = "%s x %s poles, %s um at the points, STEP %.2f MB" % (
            poles + (err, size / 1e6))
    print(json.dumps(out))


def row(case, n, ours, reference="", ref_s=None, ratio=None, note=""):
    print(ROW % (case, n, "%.2f" % ours["wall"], "%.2f" % ours["cpu"],
                 "%.0f" % ours["peak_mb"], reference, "" if ref_s is None else "%.3g" % ref_s,
                 "" if ratio is None else "%.2fx" % ratio, note or ours.get("note", "")),
          flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scattered", default="250000,1000000", help="scattered point counts")
    ap.add_argument("--grids", default="1000", help="n of n x n grids along parameter lines")
    ap.add_argument("--turned", default="1000", help="n of n x n grids turned by 20 degrees")
    ap.add_argument("--blade", default="250000,1000000", help="blade projection point counts")
    ap.add_argument("--offsets", default="0.1,1.0", help="blade point offsets (mm)")
    ap.add_argument("--fc-points", default="4000,16000",
                    help="the two subsets FreeCAD's Inspection projects")
    ap.add_argument("--occt-points", type=int, default=200, help="OCCT sample size")
    ap.add_argument("--skip", default="", help="comma list: inspect,compensate,grid,project,cam")
    ap.add_argument("--keep", help="keep the generated files in this folder")
    ap.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        return _run_child(*args.child)
    skip = set(args.skip.split(","))
    folder = args.keep or tempfile.mkdtemp(prefix="surfcomp-bench-")
    os.makedirs(folder, exist_ok=True)
    print("%d CPUs, load average %.1f at the start" % (os.cpu_count(), os.getloadavg()[0]))
    print(ROW % ("case", "points", "ours s", "cpu s", "peak MB", "reference", "ref s",
                 "ratio", "result"))
    growth = {}
    _scattered(_ints(args.scattered), folder, skip, args, growth)
    if "grid" not in skip:
        for n, turned in [(n, False) for n in _ints(args.grids)] + \
                         [(n, True) for n in _ints(args.turned)]:
            _grid(n, turned, folder)
    if "project" not in skip:
        for off in [float(x) for x in args.offsets.split(",") if x]:
            _blade(_ints(args.blade), off, args, growth)
    if "cam" not in skip:
        _cam()
    for name, t in growth.items():
        (a, ta), (b, tb) = t[0], t[-1]
        print("growth %s: t(%d) / t(%d) = %.2f for %.0fx the points (wall)"
              % (name, b, a, tb / ta, b / a))


def _scattered(sizes, folder, skip, args, growth):
    fc_n = _ints(args.fc_points)
    for n in sizes:
        X = bench_scale.scattered_points(n)
        meas = bench_scale.write_xyz(X, os.path.join(folder, "scattered_%d.xyz" % n))
        if "inspect" not in skip:
            ours = bench_scale.inspect_case(meas)
            fc_runs = [bench_scale.freecad_inspection(X[:k]) for k in fc_n]
            # FreeCAD's time for n points: the line through the two subsets
            fc = fc_runs[1][0] + (fc_runs[1][0] - fc_runs[0][0]) / (fc_n[1] - fc_n[0]) \
                * (n - fc_n[1])
            row("inspect, scattered", n, ours, "FreeCAD Inspection (extrap.)", fc,
                fc / ours["wall"], "%.0f points/s" % (n / ours["wall"]))
            growth.setdefault("inspect scattered", []).append((n, ours["wall"]))
        if "compensate" not in skip:
            ours = _child("job", meas, folder)
            row("compensate, scattered", n, ours)
            growth.setdefault("compensate scattered", []).append((n, ours["wall"]))


def _grid(n, turned, folder):
    meas = bench_pipeline.make_case(n, folder, rotated=turned)
    name = "%dx%d %s" % (n, n, "turned 20 deg" if turned else "along u, v")
    build = _child("build", meas)
    row("face build, " + name, n * n, build, "Part BSplineSurface.interpolate", build["ref"],
        build["ref"] / build["wall"])
    step = build["step"]
    print(ROW % ("STEP of the face, " + name, "", "%.2f" % step["wall"], "", "",
                 "OCCT exportStep", "%.3g" % step["ref"], "%.2fx" % (step["ref"] / step["wall"]),
                 "%.1f MB (OCCT %.1f MB)" % tuple(step["mb"])), flush=True)
    row("compensate, " + name, n * n, _child("job", meas, folder))


def _blade(sizes, offset, args, growth):
    occt = bench_scale.occt_projection(args.occt_points, offset)
    for n in sizes:
        ours = bench_scale.projection_case(n, offset)
        rate = n / ours["wall"]
        row("projection, blade, %g mm off" % offset, n, ours, "OCCT Surface.parameter",
            occt["parameter_s"] * n, rate * occt["parameter_s"],
            "%.0f points/s; feet = distToShape's within %.1e um"
            % (rate, occt["max_foot_um"]))
        growth.setdefault("projection %g mm" % offset, []).append((n, ours["wall"]))


def _cam():
    out = subprocess.run([sys.executable, os.path.join(HERE, "bench_path_op.py"),
                          "--repeat", "2"], capture_output=True, text=True, cwd=ROOT)
    lines = out.stdout.splitlines()
    if out.returncode or len(lines) < 4:
        print("CAM 3D Surface: failed\n%s" % out.stderr[-2000:])
        return
    nominal, corrected = (line.split() for line in lines[2:4])
    t_nom, t_cor = float(nominal[-2]), float(corrected[-2])
    print(ROW % ("CAM 3D Surface op, corrected face", "", "%.2f" % t_cor, "", "",
                 "the same op on the nominal", "%.3g" % t_nom, "%.2fx" % (t_cor / t_nom),
                 "poles %s vs %s (target <= 1.5x)" % (corrected[1] + corrected[2] + corrected[3],
                                                      nominal[2] + nominal[3] + nominal[4])))


if __name__ == "__main__":
    sys.exit(main())
