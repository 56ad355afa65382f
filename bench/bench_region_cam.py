# SPDX-License-Identifier: LGPL-2.1-or-later
"""CAM's 3D Surface operation on the corrected blade side against the same operation on the
nominal: the pole budget of a region's faces (issue 30: CAM on the region at most 1.5 times
the time on the nominal).

The 4-face BladeX blade (as `bench/bench_region.py` makes it: 30 um field around the leading
edge, ``--points`` points) is corrected with each pole budget of ``--factors`` (times the
nominal's poles); a Path Job over the nominal blade and one over each corrected blade run a
3D Surface operation (6 mm ball end mill, line pattern, 1 mm sample interval, 50 um mesh
deflection) on the suction side (Face1), turned to face the tool. Printed per face and
budget: the poles, the operation's time (its first recompute, or the best of ``--repeat``
- 1 recomputes; wall and the process's CPU time) and its ratio to the nominal's (target
<= 1.5), and the cutter locations; ``--rounds N`` runs the shapes in turn N times (A B A B)
and prints the load average before and after.

Where the time goes: the operation meshes the Job's whole model (``Shape.tessellate`` with
its ``LinearDeflection``; FreeCAD's tessellation turns the normal by at most 0.1 rad per
triangle) for OpenCamLib, not only the faces it cuts, so the table of every face's
triangles and meshing CPU time (each face alone, a fresh copy) follows the operation's.

    /usr/bin/python3 bench/bench_region_cam.py [--factors 4,8] [--repeat 1] [--points 20000]
        [--sample 1] [--deflection 0.05] [--rounds 1]
"""

import argparse
import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)


def operation_time(FreeCAD, shape, face, repeat, sample, deflection):
    """Seconds of the 3D Surface operation on ``face`` of ``shape``, its cutter locations
    and the face's poles."""
    from bench.bench_path_op import best_recompute
    from surfcomp.app import cam_job

    doc = FreeCAD.newDocument("benchregioncam")
    obj = doc.addObject("Part::Feature", "Blade")
    # a copy without the triangulation an earlier run left on the shape's faces (the
    # operation meshes them only where they hold none fine enough)
    obj.Shape = shape.copy()
    doc.recompute()
    job = cam_job.create_job(doc, [obj])
    tc = cam_job.ball_end_tool_controller(job, 6.0)
    op = cam_job.surface_operation(job, obj, [face], tc, sample_interval=sample,
                                   linear_deflection=deflection)
    t0, c0 = time.perf_counter(), time.process_time()
    doc.recompute()         # the first recompute: the Job, its model and the operation
    t, cpu = time.perf_counter() - t0, time.process_time() - c0
    if repeat > 1:
        cam_job.model_clone(job, obj).touch()   # settle the stock box (test_path_regen)
        doc.recompute()
        c0 = time.process_time()
        t = best_recompute(doc, op, repeat - 1)
        cpu = (time.process_time() - c0) / (repeat - 1)
    cl = len(cam_job.cutter_locations(op))
    s = shape.Faces[int(face[4:]) - 1].Surface
    FreeCAD.closeDocument(doc.Name)
    return t, cpu, cl, "%d x %d" % (s.NbUPoles, s.NbVPoles)


def meshing(shape, deflection):
    """Per face of ``shape``: its poles, the triangles of FreeCAD's tessellation with
    ``deflection`` (what the 3D Surface operation hands OpenCamLib) and its CPU seconds
    (a fresh copy of the face, so no earlier triangulation is reused)."""
    out = []
    for f in shape.Faces:
        c = f.copy()
        c0 = time.process_time()
        _v, tri = c.tessellate(deflection)
        out.append(("%d x %d" % (f.Surface.NbUPoles, f.Surface.NbVPoles), len(tri),
                    time.process_time() - c0))
    return out


def facing_up(FreeCAD, nominal, shape):
    """``shape`` turned so that the nominal's suction side (Face1) faces +z at its middle
    (the blade as read stands on its root: a drop cutter from +z meets its sides edge-on)."""
    face = nominal.Faces[0]
    u0, u1, v0, v1 = face.ParameterRange
    n = face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    rot = FreeCAD.Rotation(n, FreeCAD.Vector(0, 0, 1))
    out = shape.copy()
    out.Placement = FreeCAD.Placement(FreeCAD.Vector(), rot)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factors", default="4,8", help="pole budgets (times the nominal's)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="1: the first recompute; more: the best of repeat - 1 recomputes "
                         "of the operation after two")
    ap.add_argument("--points", type=int, default=20000)
    ap.add_argument("--sample", type=float, default=1.0, help="sample interval (mm)")
    ap.add_argument("--deflection", type=float, default=0.05,
                    help="mesh deflection (mm; 1 um takes over 6 GB on the whole blade)")
    ap.add_argument("--rounds", type=int, default=1,
                    help="run the shapes in turn this many times (A B A B)")
    a = ap.parse_args(argv)

    from bench.bench_region import make_inputs
    from surfcomp.app import cam, fcenv

    FreeCAD = fcenv.import_freecad()
    import Part

    from surfcomp.app.region_route import run_region

    cam.setup_workbench()
    folder = tempfile.mkdtemp(prefix="bench-region-cam-")
    step, csv, _n = make_inputs(folder, a.points)
    shapes = [("nominal", Part.read(step))]
    for f in (float(x) for x in a.factors.split(",")):
        out = os.path.join(folder, "out%g.step" % f)
        run_region(step, csv, "auto", out, max_factor=f, log=lambda s: None)
        shapes.append(("budget %gx" % f, Part.read(out)))
    shapes = [(name, facing_up(FreeCAD, shapes[0][1], s)) for name, s in shapes]
    print("3D Surface operation, BladeX blade, ball end mill 6 mm, sample interval %g mm, "
          "mesh deflection %g mm, %s" % (a.sample, a.deflection, "first recompute"
                                        if a.repeat <= 1 else "best of %d" % (a.repeat - 1)))
    print("load average before: %.2f %.2f %.2f" % os.getloadavg())
    print("%-6s %-14s %10s %9s %7s %9s %7s %10s" % ("face", "shape", "poles", "wall s", "ratio",
                                                   "CPU s", "ratio", "CL points"))
    for _ in range(a.rounds):
        ref = None
        for name, shape in shapes:
            t, cpu, cl, poles = operation_time(FreeCAD, shape, "Face1", a.repeat, a.sample,
                                               a.deflection)
            ref = ref or (t, cpu)
            print("%-6s %-14s %10s %9.2f %7.2f %9.2f %7.2f %10d"
                  % ("Face1", name, poles, t, t / ref[0], cpu, cpu / ref[1], cl), flush=True)
    print("load average after: %.2f %.2f %.2f" % os.getloadavg())
    print("FreeCAD's tessellation of each face with deflection %g mm (what the operation "
          "meshes: the whole model)" % a.deflection)
    print("%-14s %s" % ("shape", "  ".join("Face%d poles / triangles / CPU s" % (i + 1)
                                          for i in range(len(shapes[0][1].Faces)))))
    for name, shape in shapes:
        print("%-14s %s" % (name, "  ".join("%s / %d / %.2f" % m
                                           for m in meshing(shape, a.deflection))))


if __name__ == "__main__":
    main()
