# SPDX-License-Identifier: LGPL-2.1-or-later
"""Direct program compensation, whole process, beside FreeCAD's floor (issue 27).

    /usr/bin/python3 bench/bench_direct.py [--pairs 3] [--keep DIR] [--sizes 250000,1000000]
                                           [--skip finish,large] [--tree DIR]

Rows (each run a fresh process, timed from its start to its exit; CPU = user + system of
the process and of the children it waited for, such as the STEP reader):

* ``finish``: ``compensate examples/nominal.step examples/measurements.csv --program
  FINISH.ngc --tool ball:3 -o OUT.ngc`` on the example's finishing program made by
  FreeCAD's 3D Surface operation (6 mm ball end mill, 10 % step-over, 0.2 mm samples:
  about 17k moves; generated once with OpenCamLib, kept in ``--keep``), against the floor:
  a process that imports FreeCAD, reads the nominal STEP and writes it again. A B A B:
  ``--pairs`` pairs in the same run, alternating; the medians and their ratio are printed.
  Target: at most 3x the floor.
* ``large``: the same command on drop-cutter raster programs of ``--sizes`` moves on the
  example face (exact drop cutter, :func:`tests.toolpath_checks.drop_cutter`, generated
  once), alternating the sizes; prints the times and t(largest) / t(smallest). Targets:
  1M moves within 10 s, t(1M) / t(250k) at most 4.5.

The load averages at the start and the end of each row's runs are printed with it.
Each command runs once before the timed runs (Python's compiled modules written and
reused, as in an installation). ``--tree DIR`` runs another checkout's command in the same
alternation (e.g. the code before a change). Absolute seconds depend on the machine and on
what else runs on it; ratios measured side by side much less. The figures measured, before
and after plain G0/G1 runs were read and written as arrays and before and after the
geometry followed the path (projection from the neighbours' feet, the realised correction
at the projection's feet): docs/benchmarks.md
(bench_direct.py) and docs/direct_program.md (Speed).
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

NOMINAL = os.path.join(ROOT, "examples", "nominal.step")
MEASUREMENTS = os.path.join(ROOT, "examples", "measurements.csv")
R = 3.0

_FINISH = r"""
import sys
from surfcomp.app import fcenv
fcenv.import_freecad()
import FreeCAD, Part
from surfcomp.app import cam, cam_job
cam.setup_workbench()
doc = FreeCAD.newDocument("bench")
nom = doc.addObject("Part::Feature", "Nominal")
nom.Shape = Part.read(sys.argv[1])
doc.recompute()
job = cam_job.create_job(doc, [nom])
tc = cam_job.ball_end_tool_controller(job, 6.0)
cam_job.surface_operation(job, nom, ["Face1"], tc, step_over=10.0, sample_interval=0.2,
                          linear_deflection=0.001)
doc.recompute()
open(sys.argv[2], "w").write(cam_job.post_process(job, "linuxcnc",
                                                  "--no-show-editor --precision=4"))
"""

_FLOOR = r"""
import sys
from surfcomp.app import fcenv
fcenv.import_freecad()
import Part
Part.read(sys.argv[1]).exportStep(sys.argv[2])
"""


#: the environment of the runs: Python's compiled modules are written and reused, as in an
#: installation (as bench_lean.py runs; a warm-up run of each command writes them)
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def timed(cmd, root=ROOT):
    """Wall and CPU seconds of a child process run in the checkout ``root`` (exit status
    checked)."""
    t = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=root, env=dict(ENV, PYTHONPATH=root),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _pid, status, ru = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t
    err = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit("%s failed (%d): %s" % (" ".join(cmd[:4]), proc.returncode, err))
    return wall, ru.ru_utime + ru.ru_stime


def finish_program(keep):
    path = os.path.join(keep, "finish_example.ngc")
    if not os.path.exists(path):
        print("generating the 3D Surface finishing program (OpenCamLib, once) ...", flush=True)
        subprocess.run([sys.executable, "-c", _FINISH, NOMINAL, path], cwd=ROOT, check=True,
                       env=dict(os.environ, PYTHONPATH=ROOT), capture_output=True)
    return path


def raster_program(keep, moves):
    """A drop-cutter raster program of about ``moves`` moves on the example face."""
    import numpy as np

    from surfcomp.core.simulation.presets import werner_surface
    from tests.toolpath_checks import drop_cutter

    path = os.path.join(keep, "raster_%d.ngc" % moves)
    if os.path.exists(path):
        return path
    print("generating a raster program of %d moves (exact drop cutter, once) ..." % moves,
          flush=True)
    rows = int(round(np.sqrt(moves)))
    X, Y = np.meshgrid(np.linspace(0.5, 44.5, rows), np.linspace(0.5, 44.5, rows))
    X[1::2] = X[1::2, ::-1]
    z, _ = drop_cutter(werner_surface(), 1, np.column_stack([X.ravel(), Y.ravel()]),
                       np.full(X.size, 5.0), R, iterations=4)
    Z = z.reshape(rows, rows)
    with open(path + ".part", "w") as fh:
        fh.write("(raster program on the example face, %d moves)\nG21 G90 G17\nM3 S10000\n"
                 "G0 Z20\n" % (rows * (rows + 2)))
        for i in range(rows):
            fh.write("G0 X%.4f Y%.4f\nG1 Z%.4f F1200\n" % (X[i, 0], Y[i, 0], Z[i, 0]))
            fh.write("".join("G1 X%.4f Y%.4f Z%.4f\n" % (X[i, j], Y[i, j], Z[i, j])
                             for j in range(1, rows)))
            fh.write("G0 Z20\n")
        fh.write("M2\n")
    os.replace(path + ".part", path)
    return path


def direct(program, out):
    return [sys.executable, "-m", "surfcomp", "compensate", NOMINAL, MEASUREMENTS,
            "--program", program, "--tool", "ball:%g" % R, "-o", out, "--quiet"]


def moves_of(path):
    with open(path, "rb") as fh:
        return sum(1 for line in fh if line.startswith((b"G0", b"G1", b"G2", b"G3")))


def _roots(tree):
    """``{label: checkout}``: this one, and ``tree`` (another checkout run in the same
    alternation) when given."""
    return dict([("", ROOT)] + ([(" (%s)" % tree, os.path.abspath(tree))] if tree else []))


def load():
    """The load averages (1, 5, 15 minutes), for the figures' record."""
    return "load average %.2f, %.2f, %.2f" % os.getloadavg()


def bench_finish(keep, tmp, pairs, tree=None):
    program = finish_program(keep)
    out = os.path.join(tmp, "out.ngc")
    floor_cmd = [sys.executable, "-c", _FLOOR, NOMINAL, os.path.join(tmp, "copy.step")]
    print("finish: %s (%d move lines)" % (program, moves_of(program)))
    cases = [("floor", floor_cmd, ROOT)] + [("direct" + label, direct(program, out), root)
                                            for label, root in _roots(tree).items()]
    for _name, cmd, root in cases:          # warm-up: compiled modules, page cache
        timed(cmd, root)
    rows = {name: [] for name, _c, _r in cases}
    print("finish: %s at the start" % load(), flush=True)
    for k in range(pairs):
        for name, cmd, root in cases:
            rows[name].append(timed(cmd, root))
            print("  pair %d %-6s wall %6.2f s  cpu %6.2f s" % ((k + 1, name)
                                                               + rows[name][-1]), flush=True)
    print("finish: %s at the end" % load())
    med = {n: [statistics.median(v[i] for v in rows[n]) for i in (0, 1)] for n in rows}
    for name, _c, _r in cases[1:]:
        print("finish: floor (read + write the STEP) wall %.2f s cpu %.2f s; %s wall %.2f s "
              "cpu %.2f s; ratio wall %.2f, cpu %.2f (target <= 3)"
              % (tuple(med["floor"]) + (name,) + tuple(med[name])
                 + (med[name][0] / med["floor"][0], med[name][1] / med["floor"][1])))


def bench_large(keep, tmp, sizes, pairs, tree=None):
    programs = {n: raster_program(keep, n) for n in sizes}
    out = os.path.join(tmp, "out_large.ngc")
    roots = _roots(tree)
    for root in roots.values():             # warm-up: compiled modules
        timed(direct(programs[min(sizes)], out), root)
    rows = {(n, label): [] for n in sizes for label in roots}
    print("large: %s at the start" % load(), flush=True)
    for k in range(pairs):
        for n in sizes:
            for label, root in roots.items():
                rows[n, label].append(timed(direct(programs[n], out), root))
                print("  pair %d %8d moves%s wall %6.2f s  cpu %6.2f s"
                      % ((k + 1, n, label) + rows[n, label][-1]), flush=True)
    print("large: %s at the end" % load())
    med = {key: [statistics.median(v[i] for v in rows[key]) for i in (0, 1)] for key in rows}
    lo, hi = min(sizes), max(sizes)
    for label in roots:
        for n in sizes:
            print("large: %8d moves%s wall %.2f s cpu %.2f s"
                  % ((n, label) + tuple(med[n, label])))
        print("large%s: t(%d) / t(%d) wall %.2f, cpu %.2f (target <= 4.5 for 1M / 250k); %d "
              "moves in %.2f s wall (target <= 10 s for 1M)"
              % (label, hi, lo, med[hi, label][0] / med[lo, label][0],
                 med[hi, label][1] / med[lo, label][1], hi, med[hi, label][0]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--keep", help="folder for the generated programs (default a temporary "
                                   "one)")
    ap.add_argument("--sizes", default="250000,1000000")
    ap.add_argument("--skip", default="", help="comma list of finish,large")
    ap.add_argument("--tree", help="another checkout whose command runs in the same "
                                   "alternation (e.g. the code before a change)")
    a = ap.parse_args(argv)
    skip = set(filter(None, a.skip.split(",")))
    with tempfile.TemporaryDirectory() as tmp:
        keep = a.keep or tmp
        os.makedirs(keep, exist_ok=True)
        if "finish" not in skip:
            bench_finish(keep, tmp, a.pairs, a.tree)
        if "large" not in skip:
            bench_large(keep, tmp, sorted(int(s) for s in a.sizes.split(",")), a.pairs,
                        a.tree)
    return 0


if __name__ == "__main__":
    sys.exit(main())
