# SPDX-License-Identifier: LGPL-2.1-or-later
"""CAM's 3D Surface operation on the corrected face against the same operation on the nominal.

The reference is the operation itself on the nominal face, in the same Job, in the same run:
a 6 mm ball end mill, line pattern, 1 mm sample interval, OpenCamLib's drop cutter. The
compensation of the example (45 x 45 measured points) replaces the nominal, and the operation
is recomputed on the corrected face. Printed: the corrected face's poles, the operation's
time on each face (the best of ``--repeat`` recomputes) and their ratio (target <= 1.5), the
cutter-location points of each, and the peak RSS.

    /usr/bin/python3 bench/bench_path_op.py [--repeat 3] [--step-over 50]
"""

import argparse
import os
import resource
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)


def best_recompute(doc, op, repeat):
    """The shortest of ``repeat`` recomputes of ``op`` alone (seconds)."""
    best = float("inf")
    for _ in range(repeat):
        op.touch()
        t0 = time.perf_counter()
        doc.recompute()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="recomputes per face (best counts)")
    ap.add_argument("--step-over", type=float, default=50.0, help="step over (%% of the tool)")
    args = ap.parse_args(argv)

    from surfcomp.app import fcenv

    FreeCAD = fcenv.import_freecad()
    import Part

    from surfcomp.app import cam, cam_job, features, replace

    cam.setup_workbench()
    doc = FreeCAD.newDocument("benchpath")
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(os.path.join(ROOT, "examples", "nominal.step"))
    doc.recompute()
    job = cam_job.create_job(doc, [nom])
    tc = cam_job.ball_end_tool_controller(job, 6.0)
    op = cam_job.surface_operation(job, nom, ["Face1"], tc, step_over=args.step_over,
                                   sample_interval=1.0)
    meas = features.make_measurement(doc, os.path.join(ROOT, "examples", "measurements.csv"))
    comp = features.make_compensation(doc, nom, "Face1", meas)
    doc.recompute()
    cam_job.model_clone(job, nom).touch()      # settle the stock box (see test_path_regen)
    doc.recompute()
    t_nominal = best_recompute(doc, op, args.repeat)
    cl_nominal = len(cam_job.cutter_locations(op))
    replace.replace(doc, comp)
    doc.recompute()
    t_corrected = best_recompute(doc, op, args.repeat)
    cl_corrected = len(cam_job.cutter_locations(op))
    surface = comp.Shape.Faces[0].Surface
    nominal_surface = nom.Shape.Faces[0].Surface
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0

    print("3D Surface operation, example face, ball end mill 6 mm, best of %d" % args.repeat)
    print("%-28s %12s %10s %10s" % ("face", "poles", "seconds", "CL points"))
    print("%-28s %12s %10.2f %10d" % ("nominal (reference)", "%d x %d" % (
        nominal_surface.NbUPoles, nominal_surface.NbVPoles), t_nominal, cl_nominal))
    print("%-28s %12s %10.2f %10d" % ("corrected", "%d x %d" % (
        surface.NbUPoles, surface.NbVPoles), t_corrected, cl_corrected))
    print("ratio corrected / nominal: %.2f (target <= 1.5); peak RSS %.0f MB"
          % (t_corrected / t_nominal, rss))
    FreeCAD.closeDocument(doc.Name)


if __name__ == "__main__":
    main()
