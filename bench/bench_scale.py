# SPDX-License-Identifier: LGPL-2.1-or-later
"""Scan scale: inspect and compensate on scattered points, projection on a real blade face,
each figure next to its reference measured in the same run.

    /usr/bin/python3 bench/bench_scale.py [--sizes 250000,1000000] [--compensate]
                                          [--fc-points 4000,16000] [--occt-points 200]
                                          [--offsets 0.1,1.0] [--keep DIR]

* ``inspect`` end to end (a fresh ``python3 -m surfcomp inspect`` process: start-up,
  reading, projection, layout, smoothing fit, statistics) on N measured points scattered
  uniformly over the example face (its deviation field plus 1.5 um noise), against
  FreeCAD's ``Inspection::Feature`` on the same points (as in bench_projection.py).
  FreeCAD is timed on two subsets (``--fc-points``) of the same points; its time for N
  points is the straight line through them (printed as extrapolated).
* ``compensate`` (``--compensate``): the same files, corrected face and STEP included.
* projection on the BladeX upper face (tests/data/real/cad/BladeX/upper.iges: 526 x 13
  poles, degree 3 x 2, leading-edge radius down to 0.08 mm), N points (d uniform within
  +-offset of the face), against OCCT's ``Surface.parameter`` and ``Face.distToShape``
  on a sample (``--occt-points``), whose closest points are also the accuracy check.

Every case runs in its own process, so the peak RSS printed is its own. Absolute
seconds depend on the machine (and on what else runs on it); the ratios against the
reference measured in the same run are the figures to compare. Growth is
t(largest N) / t(smallest N). The measuring code is importable: ``inspect_case``,
``freecad_inspection``, ``projection_case``, ``occt_projection``.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

NOMINAL = os.path.join(ROOT, "examples", "nominal.step")
BLADE = os.path.join(ROOT, "tests", "data", "real", "cad", "BladeX", "upper.iges")


# --------------------------------------------------------------------------- data
def scattered_points(n, seed=None):
    """N measured points (mm) scattered uniformly over the example face's (u, v) in
    [0.01, 0.99]^2, each off the face by the example's deviation field plus 1.5 um noise."""
    from examples.make_example import deviation_field, example_surface
    from surfcomp.core.surface import bspline

    surf = example_surface()
    rng = np.random.default_rng(n if seed is None else seed)
    u, v = rng.uniform(0.01, 0.99, n), rng.uniform(0.01, 0.99, n)
    S, N = bspline.evaluate(surf, u, v), bspline.normals(surf, u, v)
    d = deviation_field(S[:, 0], S[:, 1]) + rng.normal(0, 0.0015, n)
    return S + d[:, None] * N


def write_xyz(X, path):
    """A plain ``x y z`` file with a header (the format FreeCAD users export)."""
    np.savetxt(path, X, fmt="%.6f", header="x y z", comments="")
    return path


def blade_face():
    """``(Part.Face, core Surface)`` of the BladeX upper face (needs FreeCAD)."""
    from surfcomp.app import fcenv

    fcenv.import_freecad()
    import Part

    from surfcomp.app.convert import surface_from_part

    face = Part.read(BLADE).Faces[0]
    u0, u1, v0, v1 = face.ParameterRange
    return face, surface_from_part(face.Surface, (u0, u1), (v0, v1))


def blade_points(surf, n, offset, seed=7):
    """N points off the face by a distance uniform in [-offset, offset] mm along the
    normal, at parameters uniform over the face; also the feet and distances."""
    from surfcomp.core.surface import bspline

    rng = np.random.default_rng(seed)
    u = rng.uniform(*surf.u_range, n)
    v = rng.uniform(*surf.v_range, n)
    d = rng.uniform(-offset, offset, n)
    S = bspline.evaluate(surf, u, v)
    return S + d[:, None] * bspline.normals(surf, u, v)


# --------------------------------------------------------------------------- measuring
def _child(args):
    """Run ``bench_scale.py --child ARGS`` in a fresh process: (its JSON line, peak MB)."""
    proc = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--child"] + args,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out, err = proc.communicate()
    if proc.returncode:
        raise RuntimeError("child %s failed:\n%s" % (args, err[-3000:]))
    return json.loads(out.strip().splitlines()[-1])


def inspect_case(meas, command="inspect", out_dir=None):
    """``python3 -m surfcomp inspect NOMINAL MEAS`` (or ``compensate ... -o OUT.step``) in
    a fresh process: wall seconds, CPU seconds, peak RSS (MB), its standard output."""
    cmd = [sys.executable, "-m", "surfcomp", command, NOMINAL, meas, "--quiet"]
    if command == "compensate":
        cmd += ["-o", os.path.join(out_dir or tempfile.gettempdir(), "bench_scale.step")]
    return timed(cmd)


def timed(cmd):
    """Run ``cmd`` in the repository: wall and CPU seconds, peak RSS (MB) and its standard
    output; a failure raises with the end of its standard error."""
    t = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out:
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=out, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t
        err = proc.stderr.read().decode()
        proc.stderr.close()
        out.seek(0)
        text = out.read()
    if status:
        raise RuntimeError("%s failed:\n%s" % (" ".join(cmd), err[-3000:]))
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime,
            "peak_mb": usage.ru_maxrss / 1024, "stdout": text}


def freecad_inspection(X):
    """Wall and CPU seconds of FreeCAD's ``Inspection::Feature`` recompute for points X
    against the example face (bench_projection.time_freecad), in a fresh process."""
    path = os.path.join(tempfile.mkdtemp(prefix="surfcomp-bench-"), "fc.npy")
    np.save(path, X)
    out = _child(["freecad", path])
    return out["seconds"], out["cpu"]


def projection_case(n, offset, workers=None):
    """Ours on the blade in a fresh process: Projector set-up + projection of n points,
    wall and CPU seconds, peak RSS (MB); max |d - d_true| where the true foot is the
    closest point (checked against OCCT separately)."""
    return _child(["project", str(n), str(offset), str(workers or 0)])


def occt_projection(n, offset, seed=11):
    """OCCT on a sample of n blade points: seconds per point of ``Surface.parameter``
    (GeomAPI_ProjectPointOnSurf) and of ``Face.distToShape``, and our distances and
    feet against distToShape's (max abs difference, um)."""
    return _child(["occt", str(n), str(offset), str(seed)])


# --------------------------------------------------------------------------- children
def _run_child(kind, *args):
    import resource

    if kind == "freecad":
        sys.path.insert(0, os.path.join(ROOT, "bench"))
        from bench_projection import time_freecad

        from examples.make_example import example_surface

        seconds, _, cpu = time_freecad(example_surface(), np.load(args[0]))
        out = {"seconds": seconds, "cpu": cpu}
    elif kind == "project":
        n, offset, workers = int(args[0]), float(args[1]), int(args[2]) or None
        _, surf = blade_face()
        X = blade_points(surf, n, offset)
        from surfcomp.core.surface.projection import Projector

        t, c = time.perf_counter(), time.process_time()
        r = Projector(surf, workers=workers, min_samples=n // 16).project(X)
        out = {"wall": time.perf_counter() - t, "cpu": time.process_time() - c,
               "converged": int(r.converged.sum())}
    else:  # occt
        n, offset, seed = int(args[0]), float(args[1]), int(args[2])
        face, surf = blade_face()
        import FreeCAD
        import Part

        from surfcomp.core.surface.projection import project

        X = blade_points(surf, n, offset, seed=seed)
        t, c = time.perf_counter(), time.process_time()
        for p in X.tolist():
            face.Surface.parameter(FreeCAD.Vector(*p))
        t_param, c_param = (time.perf_counter() - t) / n, (time.process_time() - c) / n
        dist, feet = [], []
        t, c = time.perf_counter(), time.process_time()
        for p in X.tolist():
            d, pairs, _ = face.distToShape(Part.Vertex(FreeCAD.Vector(*p)))
            dist.append(d)
            feet.append(tuple(pairs[0][0]))
        t_dist, c_dist = (time.perf_counter() - t) / n, (time.process_time() - c) / n
        r = project(surf, X)
        out = {"parameter_s": t_param, "dist_s": t_dist, "parameter_cpu": c_param,
               "dist_cpu": c_dist,
               "max_dd_um": float(np.max(np.abs(np.abs(r.distance) - np.array(dist)))) * 1e3,
               "max_foot_um": float(np.max(np.linalg.norm(r.foot - np.array(feet), axis=1)))
               * 1e3}
    out["peak_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(out))


# --------------------------------------------------------------------------- report
def _line(text):
    print(text, flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="250000,1000000", help="numbers of points")
    ap.add_argument("--compensate", action="store_true", help="also time compensate")
    ap.add_argument("--fc-points", default="4000,16000",
                    help="the two subsets FreeCAD's Inspection projects")
    ap.add_argument("--occt-points", type=int, default=200, help="OCCT sample size")
    ap.add_argument("--offsets", default="0.1,1.0", help="blade point offsets (mm)")
    ap.add_argument("--keep", help="keep the generated point files in this folder")
    ap.add_argument("--skip", default="", help="comma list of parts to skip: inspect,project")
    ap.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        return _run_child(*args.child)
    sizes = [int(x) for x in args.sizes.split(",") if x]
    skip = set(args.skip.split(","))
    folder = args.keep or tempfile.mkdtemp(prefix="surfcomp-bench-")
    os.makedirs(folder, exist_ok=True)
    _line("machine: %d CPUs, load average %.1f at start (shared machines vary)"
          % (os.cpu_count(), os.getloadavg()[0]))
    if "inspect" not in skip:
        _inspect_table(sizes, folder, args)
    if "project" not in skip:
        _projection_table(sizes, [float(x) for x in args.offsets.split(",")], args)


def _inspect_table(sizes, folder, args):
    _line("\ninspect end to end, N points scattered over the example face, vs FreeCAD "
          "Inspection::Feature on the same points")
    _line("%9s %8s %8s %8s %10s %10s %8s %8s %8s" % (
        "points", "ours s", "cpu s", "peak MB", "FreeCAD s", "FC cpu s", "ratio", "cpu ratio",
        "pts/s"))
    fc_n = [int(x) for x in args.fc_points.split(",")]
    times = {}
    for n in sizes:
        X = scattered_points(n)
        meas = write_xyz(X, os.path.join(folder, "scattered_%d.xyz" % n))
        ours = inspect_case(meas)
        fc_runs = [freecad_inspection(X[:k]) for k in fc_n]
        # FreeCAD's wall and CPU time for n points: the line through the two subsets
        fc = [f[1] + (f[1] - f[0]) / (fc_n[1] - fc_n[0]) * (n - fc_n[1])
              for f in zip(*fc_runs)]
        times[n] = ours["wall"]
        _line("%9d %8.2f %8.2f %8.0f %10.0f %10.0f %7.0fx %7.0fx %8.0f   (FreeCAD: %.2f s for "
              "%d, %.2f s for %d points, extrapolated)" % (
                  n, ours["wall"], ours["cpu"], ours["peak_mb"], fc[0], fc[1],
                  fc[0] / ours["wall"], fc[1] / ours["cpu"], n / ours["wall"], fc_runs[0][0],
                  fc_n[0], fc_runs[1][0], fc_n[1]))
        if args.compensate:
            comp = inspect_case(meas, "compensate", folder)
            times[("compensate", n)] = comp["wall"]
            _line("%9s compensate: %.2f s wall, %.2f s cpu, peak %.0f MB"
                  % ("", comp["wall"], comp["cpu"], comp["peak_mb"]))
    if len(sizes) > 1:
        a, b = sizes[0], sizes[-1]
        _line("growth inspect t(%d) / t(%d) = %.2f for %.0fx the points"
              % (b, a, times[b] / times[a], b / a))
        if args.compensate:
            _line("growth compensate t(%d) / t(%d) = %.2f"
                  % (b, a, times[("compensate", b)] / times[("compensate", a)]))


def _projection_table(sizes, offsets, args):
    _line("\nprojection onto the BladeX upper face (526 x 13 poles, degree 3 x 2), set-up "
          "included, vs OCCT on %d of the points" % args.occt_points)
    _line("%7s %9s %7s %7s %8s %10s %8s %10s %10s %8s %8s" % (
        "offset", "points", "ours s", "cpu s", "pts/s", "pts/cpu-s", "peak MB", "parameter",
        "distToShape", "|dd| um", "foot um"))
    for off in offsets:
        occt = occt_projection(args.occt_points, off)
        walls = {}
        for n in sizes:
            ours = projection_case(n, off)
            walls[n] = ours["wall"]
            rate = n / ours["wall"]
            _line("%7.2f %9d %7.2f %7.2f %8.0f %10.0f %8.0f %9.0fx %9.0fx %8.5f %8.5f" % (
                off, n, ours["wall"], ours["cpu"], rate, n / ours["cpu"], ours["peak_mb"],
                rate * occt["parameter_s"], rate * occt["dist_s"], occt["max_dd_um"],
                occt["max_foot_um"]))
        _line("%7s OCCT on %d points: Surface.parameter %.0f pts/s (%.0f per CPU s), "
              "Face.distToShape %.0f pts/s (%.0f per CPU s)"
              % ("", args.occt_points, 1 / occt["parameter_s"], 1 / occt["parameter_cpu"],
                 1 / occt["dist_s"], 1 / occt["dist_cpu"]))
        if len(sizes) > 1:
            a, b = sizes[0], sizes[-1]
            _line("%7s growth t(%d) / t(%d) = %.2f" % ("", b, a, walls[b] / walls[a]))


if __name__ == "__main__":
    sys.exit(main())
