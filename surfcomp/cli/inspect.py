# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp inspect``: deviations and statistics only."""

from . import SUMMARIES, registry
from .common import add_job_parser, run_job_command
from .options import add_arguments


def add_parser(subparsers):
    p = add_job_parser(
        subparsers, "inspect", SUMMARIES["inspect"],
        "Compute deviations along the nominal normal, the filtered (determined; a 5x5 box "
        "mask by default) and random components, and the papers' statistics.")
    # the filter's options (the determined component is compensate's), not the method's
    add_arguments(p, ("mask_size", "weights", "mask_kind", "sigma", "edge", "smoothing"))
    registry.add_options(p, "inspect", flags=("--html",))
    p.set_defaults(run=run)
    return p


def run(args):
    return run_job_command(args, "inspect")
