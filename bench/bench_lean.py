# SPDX-License-Identifier: LGPL-2.1-or-later
"""Whole-process times of the compensate routes beside FreeCAD's own floor, in one run.

Every measurement is a fresh process, alternated with its reference (A B A B ...), and the
medians are compared:

* ``compensate -o`` on the bundled example (the README's first command without the
  reports) against the FreeCAD floor: a Python that imports FreeCAD and Part, reads the
  nominal STEP and writes it again (target: at most 3x);
* ``--doc``: the shop-document route ``compensate shop.FCStd meas.csv --object Block
  --face Face2 --replace --save OUT.FCStd`` on a block whose top is the example face, under
  a CAM Job with a 3D Surface finishing operation, against FreeCAD's own recompute of that
  Job on the same geometry: a process that opens OUT.FCStd (the corrected face in the
  nominal's place), recomputes the Job's objects and saves a copy (target: at most the
  reference plus 1 s). The difference is what the route adds: its imports, the
  compensation (the fit, the face, the solid with re-trimmed neighbours) and the replace.

Wall time and CPU time (user + system, the process and its children) are printed; on a
machine shared with other work the CPU times move less. ``--tree DIR`` also runs the
command from another checkout in the same alternation (e.g. the code before a change).

    /usr/bin/python3 bench/bench_lean.py [--repeat 5] [--doc] [--tree DIR]
        [--step-over 50] [--sample-interval 1.0]
"""

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NOMINAL = os.path.join(ROOT, "examples", "nominal.step")
MEASUREMENTS = os.path.join(ROOT, "examples", "measurements.csv")
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable

FLOOR = r"""
import sys
sys.path.insert(0, sys.argv[1])
from surfcomp.app import fcenv
fcenv.setup_paths()
import FreeCAD, Part
Part.read(sys.argv[2]).exportStep(sys.argv[3])
"""

#: the Job's recompute as FreeCAD does it after its model changed: open (CAM set up first,
#: as surfcomp does), touch the model's clone, recompute (the clone and what uses it: the
#: operation, the stock, the Job), save a copy
JOB_RECOMPUTE = r"""
import sys
sys.path.insert(0, sys.argv[1])
from surfcomp.app import cam, documents, fcenv
fcenv.import_freecad()
cam.setup_workbench()
doc = documents.open_document(sys.argv[2])[0]
clones = [o for o in doc.Objects if o.Name.startswith("Clone")]
assert clones, "no model clone"
for o in clones:
    o.touch()
doc.recompute()
doc.saveCopy(sys.argv[3])
"""

MAKE_SHOP = r"""
import sys
sys.path.insert(0, sys.argv[1])
from surfcomp.app import cam, cam_job, fcenv
FreeCAD = fcenv.import_freecad()
import Part
cam.setup_workbench()
top = Part.read(sys.argv[2]).Faces[0]
ext = top.extrude(FreeCAD.Vector(0, 0, -30))
box = Part.makeBox(100, 100, 20, FreeCAD.Vector(-20, -20, -5))
doc = FreeCAD.newDocument("shop")
block = doc.addObject("Part::Feature", "Block")
block.Shape = ext.common(box).Solids[0]
job = cam_job.create_job(doc, [block])
tc = cam_job.ball_end_tool_controller(job, 6.0)
op = cam_job.surface_operation(job, block, ["Face2"], tc, step_over=float(sys.argv[4]),
                               sample_interval=float(sys.argv[5]))
doc.recompute()
cam_job.model_clone(job, block).touch()
doc.recompute()
print(len(cam_job.cutter_locations(op)))
doc.saveAs(sys.argv[3])
"""


#: the environment of the runs: Python's compiled modules are written and reused, as in an
#: installation (the first, warm-up, run of each case writes them)
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def timed(cmd, cwd):
    """``(wall s, cpu s)`` of one run of ``cmd`` (CPU of the process and its children)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    run = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=ENV)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode != 0:
        raise SystemExit("failed (%d): %s\n%s" % (run.returncode, " ".join(cmd), run.stderr))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def alternate(cases, repeat):
    """Run ``cases`` (name -> (cmd, cwd)) in turn ``repeat`` times; medians by name."""
    got = {name: [] for name in cases}
    for cmd, cwd in cases.values():       # one warm-up each (page cache)
        timed(cmd, cwd)
    for _ in range(repeat):
        for name, (cmd, cwd) in cases.items():
            got[name].append(timed(cmd, cwd))
    return {name: (statistics.median(w for w, _ in runs), statistics.median(c for _, c in runs))
            for name, runs in got.items()}


def report(title, medians, reference, compare):
    print(title)
    ref_wall, ref_cpu = medians[reference]
    print("  %-34s %9s %9s %11s %11s" % ("", "wall s", "cpu s", "wall ratio", "cpu ratio"))
    for name, (wall, cpu) in medians.items():
        print("  %-34s %9.3f %9.3f %11s %11s"
              % (name, wall, cpu, "" if name == reference else compare(wall, ref_wall),
                 "" if name == reference else compare(cpu, ref_cpu)))


def trees(args):
    out = {"this checkout": ROOT}
    if args.tree:
        out[os.path.abspath(args.tree)] = os.path.abspath(args.tree)
    return out


def bench_file_route(args, tmp):
    cases = {"floor: read + write the STEP": (
        [PYTHON, "-c", FLOOR, ROOT, NOMINAL, os.path.join(tmp, "floor.step")], ROOT)}
    for label, tree in trees(args).items():
        cases["compensate -o (%s)" % label] = (
            [PYTHON, "-m", "surfcomp", "compensate", NOMINAL, MEASUREMENTS, "-o",
             os.path.join(tmp, "out.step"), "--quiet"], tree)
    medians = alternate(cases, args.repeat)
    report("compensate -o on the example, median of %d, A B A B (target <= 3x the floor)"
           % args.repeat, medians, "floor: read + write the STEP",
           lambda x, ref: "%.2fx" % (x / ref))


def bench_document_route(args, tmp):
    shop = os.path.join(tmp, "shop.FCStd")
    made = subprocess.run([PYTHON, "-c", MAKE_SHOP, ROOT, NOMINAL, shop, str(args.step_over),
                           str(args.sample_interval)], capture_output=True, text=True)
    if made.returncode != 0:
        raise SystemExit("could not make the shop document:\n" + made.stderr)
    print("shop document: block with the example face, 3D Surface op, %s cutter-location "
          "points" % made.stdout.split()[-1])
    reference = "FreeCAD: open, recompute the Job, save"
    out = os.path.join(tmp, "out.FCStd")
    cases = {}
    for label, tree in trees(args).items():     # the first warm-up run writes OUT.FCStd
        cases["compensate --replace (%s)" % label] = (
            [PYTHON, "-m", "surfcomp", "compensate", shop, MEASUREMENTS, "--object", "Block",
             "--face", "Face2", "--replace", "--save", out, "--quiet"], tree)
    cases[reference] = ([PYTHON, "-c", JOB_RECOMPUTE, ROOT, out,
                         os.path.join(tmp, "ref.FCStd")], ROOT)
    medians = alternate(cases, args.repeat)
    report("document route, median of %d, A B A B (target <= the reference + 1 s)"
           % args.repeat, medians, reference, lambda x, ref: "%+.2f s" % (x - ref))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs of each case (median counts)")
    ap.add_argument("--doc", action="store_true", help="also the shop-document route")
    ap.add_argument("--tree", metavar="DIR", help="also run the commands of this checkout")
    ap.add_argument("--step-over", type=float, default=50.0, help="3D Surface step over, %%")
    ap.add_argument("--sample-interval", type=float, default=1.0,
                    help="3D Surface sample interval, mm")
    args = ap.parse_args(argv)
    print("load average at the start: %.2f %.2f %.2f" % os.getloadavg())
    with tempfile.TemporaryDirectory(prefix="bench-lean-") as tmp:
        bench_file_route(args, tmp)
        if args.doc:
            bench_document_route(args, tmp)
    print("load average at the end: %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main()
