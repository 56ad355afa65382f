# SPDX-License-Identifier: LGPL-2.1-or-later
"""Region compensation of the 4-face BladeX blade (issue 30), whole process, beside
FreeCAD's floor of reading and writing the same STEP file.

    /usr/bin/python3 bench/bench_region.py [--points 200000] [--keep DIR [--reuse]]
        [--tree DIR] [--repeat 1]

* the blade (tests/data/real/cad/BladeX: upper, lower, tip, root; a compound of faces, as
  OpenCASCADE does not sew its knife edges) written as STEP, with N points spread over its
  faces by area and a 30 um deviation largest along the leading edge and running around
  it onto both sides;
* ``python3 -m surfcomp compensate blade.step points.csv --faces auto -o out.step
  --report out.json`` in a fresh process, timed whole (start-up, reading, locating the
  points on the four faces, filter, field, four faces, continuity, STEP);
* the reference: a fresh FreeCAD process that reads the same STEP file and writes it
  again (the floor of any tool that reads and writes the part with OpenCASCADE).

Prints both times, their ratio, and the continuity figures (largest gap and normal angle
per shared edge) from the JSON report. Absolute seconds depend on the machine and its
load; the ratio is the figure to compare. ``--tree DIR`` also runs another checkout's
command (e.g. the code before a change) on the same files, alternated with this one's
(A B A B, ``--repeat`` times each), and prints the medians and the load average before
and after.
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

FLOOR = """
import sys
sys.path.insert(0, '/usr/lib/freecad/lib'); sys.path.insert(0, '/usr/lib/freecad-python3/lib')
import FreeCAD, Part
s = Part.read(sys.argv[1])
s.exportStep(sys.argv[2])
"""


def make_inputs(folder, points):
    from surfcomp.app import fcenv

    fcenv.import_freecad()
    import Part

    from tests.app import region_parts as rp

    faces = rp.blade_faces(os.path.join(ROOT, "tests", "data", "real", "cad", "BladeX"))
    step = os.path.join(folder, "blade.step")
    Part.Compound(faces).exportStep(step)
    field = rp.around_edge_field(rp.leading_edge(faces))
    areas = np.array([f.Area for f in faces])
    per = np.maximum((points * areas / areas.sum()).astype(int), 200)
    parts = [rp.sample_faces([f], int(k), field, seed=i) for i, (f, k) in
             enumerate(zip(rp.blade_outward(faces), per))]
    pts, nrm, dev = (np.concatenate([p[j] for p in parts]) for j in range(3))
    csv = os.path.join(folder, "points.csv")
    rp.write_csv(csv, pts, nrm, dev)
    return step, csv, len(pts)


def timed(cmd, cwd=ROOT):
    """Wall seconds, the result, and the child's CPU seconds (user + system, all its
    threads): on a shared machine the wall time follows the load, the CPU time less so."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    r.cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, r


def alternate(folder, step, csv, tree, repeat):
    """Median wall and CPU seconds of this checkout's run and ``tree``'s, alternated;
    the first result of each (exit status, output)."""
    runs = {ROOT: []} if tree is None else {ROOT: [], os.path.abspath(tree): []}
    first = {}
    for _ in range(repeat):
        for i, t in enumerate(runs):
            out = os.path.join(folder, "out%d.step" % i)
            rep = os.path.join(folder, "out%d.json" % i)
            wall, r = timed([sys.executable, "-m", "surfcomp", "compensate", step, csv,
                             "--faces", "auto", "-o", out, "--report", rep, "--quiet"], t)
            if r.returncode:
                print("%s: exit %d\n%s" % (t, r.returncode, r.stdout + r.stderr))
                raise SystemExit(r.returncode)
            runs[t].append((wall, r.cpu))
            first.setdefault(t, (r, rep))
    return {t: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v))
            for t, v in runs.items()}, first


def largest_difference(a, b):
    """Largest relative difference between the numbers of two reports of the same shape
    (inf where their texts or shapes differ; the input paths are not compared)."""
    if isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys():
        return max([largest_difference(a[k], b[k]) for k in a if k != "inputs"], default=0.0)
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return max([largest_difference(x, y) for x, y in zip(a, b)], default=0.0)
    if isinstance(a, float) and isinstance(b, (int, float)):
        return abs(a - b) / max(abs(a), abs(b), 1e-300) if a != b else 0.0
    return 0.0 if a == b else float("inf")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=200000)
    ap.add_argument("--keep", metavar="DIR")
    ap.add_argument("--tree", metavar="DIR", help="also run the command of this checkout")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each, alternated")
    ap.add_argument("--reuse", action="store_true",
                    help="take blade.step and points.csv of --keep DIR as they are")
    a = ap.parse_args(argv)
    if a.reuse and not a.keep:
        ap.error("--reuse takes the files of --keep DIR")
    folder = a.keep or tempfile.mkdtemp(prefix="bench-region-")
    os.makedirs(folder, exist_ok=True)
    if a.reuse:
        step, csv = os.path.join(folder, "blade.step"), os.path.join(folder, "points.csv")
        n = sum(1 for _ in open(csv)) - 1
    else:
        step, csv, n = make_inputs(folder, a.points)
    load = os.getloadavg()
    medians, first = alternate(folder, step, csv, a.tree, max(1, a.repeat))
    (t_region, cpu), (r, rep) = medians[ROOT], first[ROOT]
    r.cpu = cpu
    t_floor, f = timed([sys.executable, "-c", FLOOR, step, os.path.join(folder, "copy.step")])
    if f.returncode:
        print(f.stderr)
        return f.returncode
    if a.tree:
        print("load average before %.2f %.2f %.2f, after %.2f %.2f %.2f"
              % (load + os.getloadavg()))
        for t, (wall, c) in medians.items():
            print("%s: %.2f s wall, %.2f s CPU (median of %d)" % (t, wall, c, a.repeat))
        other = [t for t in medians if t != ROOT][0]
        diff = largest_difference(json.load(open(first[other][1])), json.load(open(rep)))
        print("the two reports: %s" % ("identical" if diff == 0.0 else
                                       "largest relative difference of a figure %.1e" % diff))
    data = json.load(open(rep))
    print("blade, 4 faces, %d points" % n)
    print("surfcomp compensate --faces auto: %.2f s wall, %.2f s CPU (target 15 s)"
          % (t_region, r.cpu))
    print("FreeCAD read + write of the same STEP: %.2f s wall, %.2f s CPU" % (t_floor, f.cpu))
    print("ratio: %.1f wall, %.1f CPU" % (t_region / t_floor, r.cpu / f.cpu))
    for e in data["edges"]:
        print("edge %s-%s: largest gap %.4f um (nominal %.4f um, %.4f um beyond it), largest "
              "normal angle change %.4f deg (%s)"
              % (e["faces"][0], e["faces"][1], e["max_gap_um"], e["nominal_gap_um"],
                 e["max_gap_beyond_nominal_um"], e["max_angle_change_deg"],
                 "G1" if e["g1"] else "sharp"))
    for fc in data["faces"]:
        beyond = fc.get("max_realised_minus_intended_beyond_edge_zones_um")
        print("%s: poles %d x %d (nominal %d x %d), realised - intended %.4f um; %d points "
              "near knife edges and vertices (short by up to %.4f um by design), %d points "
              "where it curls tighter than the correction (short by up to %.4f um by "
              "design), %d points its moved edge slides past (realised - intended up to "
              "%.4f um, up to %.4f um from the edge, slide up to %.4f um), beyond them %s; "
              "largest turn of the normal %.1f deg"
              % (fc["face"], *fc["poles"], *fc["nominal_poles"],
                 fc["max_realised_minus_intended_um"], fc.get("edge_zone_points", 0),
                 fc.get("edge_zone_max_designed_shortfall_um", 0.0), fc.get("curl_points", 0),
                 fc.get("curl_max_shortfall_um", 0.0), fc.get("edge_slide_points", 0),
                 fc.get("edge_slide_max_realised_minus_intended_um", 0.0),
                 fc.get("edge_slide_max_distance_um", 0.0),
                 fc.get("edge_slide_max_slide_um", 0.0),
                 "-" if beyond is None else "%.4f um" % beyond,
                 fc.get("normal_turn", {}).get("largest_normal_turn_deg", float("nan"))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
