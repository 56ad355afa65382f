# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp inspect``: deviations and statistics only."""

from . import SUMMARIES, registry
from .common import add_job_parser, run_job_command


def add_parser(subparsers):
    p = add_job_parser(
        subparsers, "inspect", SUMMARIES["inspect"],
        "Compute deviations along the nominal normal, the 5x5 filtered (determined) and random "
        "components, and the papers' statistics.")
    p.add_argument("--mask", type=int, default=5, metavar="N",
                   help="mask size of the filter used to split determined/random (default 5)")
    p.add_argument("--weights", metavar="W", help="custom mask weights (see compensate)")
    p.add_argument("--smoothing", type=float, metavar="MM",
                   help="scattered layouts: smoothing length of the fit (default: GCV)")
    registry.add_options(p, "inspect", flags=("--html",))
    p.set_defaults(run=run)
    return p


def run(args):
    return run_job_command(args, "inspect")
