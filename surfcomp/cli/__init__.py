# SPDX-License-Identifier: LGPL-2.1-or-later
"""Command-line front end: ``python3 -m surfcomp <command> ...``.

Each subcommand lives in its own module of this package with two functions,
``add_parser(subparsers)`` and ``run(args) -> int``; the options naming files are in
:mod:`surfcomp.cli.registry`, and every output is checked against every input and every
other output (:func:`surfcomp.io.atomic.check_outputs`) before the command starts. Exit
codes (:mod:`surfcomp.cli.runner`): 0 ok (the outputs are complete), 2 bad input (stderr
says why, nothing written), 1 internal error, 130 interrupted (Ctrl-C), 143 terminated
(SIGTERM), 129 hung up (SIGHUP). An interrupted command removes its temporary files and
writes nothing; a signal after the outputs were committed exits 0 and names them.
"""

import argparse
import importlib
import sys

from .. import __version__
from ..io import atomic
from . import registry, runner
from .runner import Terminated  # noqa: F401  (the signal exception, for callers)

#: subcommand modules, in the order ``--help`` lists them
COMMANDS = ("compensate", "inspect", "simulate", "gcode", "plan")
#: each command's line in ``--help`` (here, so that the list needs no command module:
#: they import the numerics)
SUMMARIES = {
    "compensate": "build the corrected face that pre-compensates the systematic error",
    "inspect": "deviations and statistics only (nothing is built)",
    "simulate": "virtual machining: predict what each compensation method achieves",
    "gcode": "compensate a G-code program for the machine's axis errors",
    "plan": "place the measurement points on the nominal face for on-machine probing",
}


def build_parser(only=None):
    """The argument parser; with ``only`` (a command name) just that command's subparser,
    so a run imports one command module (and its dependencies), not all of them; with
    ``only=False`` the commands' names and summaries alone (for ``--help`` and a missing
    or unknown command: no command module, so no numerics, is imported)."""
    parser = argparse.ArgumentParser(
        prog="python3 -m surfcomp",
        description="Compensate machining errors of free-form B-spline surfaces "
                    "from measurements (Werner 2022; mirror method; axis error model).")
    parser.add_argument("--version", action="version", version="surfcomp " + __version__)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    if only is False:
        for name in COMMANDS:
            subparsers.add_parser(name, help=SUMMARIES[name])
        return parser
    for name in (only,) if only in COMMANDS else COMMANDS:
        module = importlib.import_module("." + name, __name__)
        registry.add_plain_options(module.add_parser(subparsers), name)
    return parser


def main(argv=None):
    """Run the command line; return the process exit code (:mod:`surfcomp.cli.runner`)."""
    args = sys.argv[1:] if argv is None else list(argv)
    if args and args[0] in COMMANDS:
        only = args[0]
    else:       # a leading option or no command: every parser only if a command is named
        only = None if any(a in COMMANDS for a in args) else False
    parser = build_parser(only)
    args = parser.parse_args(args)

    def body():
        atomic.check_outputs(*registry.declared(args))
        return args.run(args)

    return runner.run(body, data_to_stdout=registry.wants_stdout(args))
