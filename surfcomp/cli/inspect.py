"""``python3 -m surfcomp inspect``: deviations and statistics only."""

from ..app.job import Job, run_job
from .common import ProgressLine, add_input_options, options_from_args, print_summary


def add_parser(subparsers):
    p = subparsers.add_parser(
        "inspect", help="deviations and statistics only (nothing is built)",
        description="Compute deviations along the nominal normal, the 5x5 filtered (determined) "
                    "and random components, and the papers' statistics.")
    add_input_options(p)
    p.add_argument("--mask", type=int, default=5, metavar="N",
                   help="mask size of the filter used to split determined/random (default 5)")
    p.add_argument("--weights", metavar="W", help="custom mask weights (see compensate)")
    p.set_defaults(run=run)
    return p


def run(args):
    job = Job(nominal=args.nominal, measurements=args.measurements, command="inspect",
              report=args.report, face=args.face, object=args.object, units=args.units,
              options=options_from_args(args))
    comp, rep = run_job(job, progress=ProgressLine(args.quiet))
    print_summary(comp, rep)
    if args.report:
        print("wrote %s" % args.report)
    return 0
