"""``python3 -m surfcomp compensate``: nominal + measurements -> corrected face."""

from ..app.job import Job, run_job
from .common import (ProgressLine, add_input_options, add_method_options, options_from_args,
                     print_summary)


def add_parser(subparsers):
    p = subparsers.add_parser(
        "compensate", help="build the corrected face that pre-compensates the systematic error",
        description="Build a corrected B-spline face from a nominal face and a measurement file "
                    "(Werner 2022 raw/filtered, mirror method, uniform offset).")
    add_input_options(p)
    p.add_argument("-o", "--output", metavar="OUT.step",
                   help="corrected face (STEP; .iges/.brep by extension)")
    add_method_options(p)
    p.add_argument("--points", metavar="OUT.csv", help="also write the corrected points (CSV)")
    p.add_argument("--curves", metavar="OUT.step",
                   help="also write the curve net through the corrected points (Werner Fig. 3b)")
    p.set_defaults(run=run)
    return p


def run(args):
    job = Job(nominal=args.nominal, measurements=args.measurements, command="compensate",
              output=args.output, report=args.report, points=args.points, curves=args.curves,
              face=args.face, object=args.object, units=args.units,
              options=options_from_args(args))
    comp, rep = run_job(job, progress=ProgressLine(args.quiet))
    print_summary(comp, rep)
    for key in ("output", "points", "curves", "report"):
        if getattr(args, key):
            print("wrote %s" % getattr(args, key))
    return 0
