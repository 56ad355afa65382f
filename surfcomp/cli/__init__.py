"""Command-line front end: ``python3 -m surfcomp <command> ...``.

Each subcommand lives in its own module of this package with two functions,
``add_parser(subparsers)`` and ``run(args) -> int``. Exit codes: 0 ok, 2 bad input
(stderr says why, nothing written), 1 internal error, 130 interrupted.
"""

import argparse
import importlib
import sys
import traceback

from .. import __version__
from ..errors import SurfcompError

#: subcommand modules, in the order ``--help`` lists them
COMMANDS = ("compensate", "inspect", "simulate", "gcode")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="python3 -m surfcomp",
        description="Compensate machining errors of free-form B-spline surfaces "
                    "from measurements (Werner 2022; mirror method; axis error model).")
    parser.add_argument("--version", action="version", version="surfcomp " + __version__)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for name in COMMANDS:
        module = importlib.import_module("." + name, __name__)
        module.add_parser(subparsers)
    return parser


class ArgumentError(SurfcompError):
    exit_code = 2


def main(argv=None):
    """Run the command line; return the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.run(args) or 0)
    except SurfcompError as exc:
        print("surfcomp: error: %s" % exc, file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("surfcomp: interrupted; nothing was written", file=sys.stderr)
        return 130
    except Exception:  # an internal error: show the traceback, exit 1
        traceback.print_exc()
        print("surfcomp: internal error (please report it with the traceback above)",
              file=sys.stderr)
        return 1
