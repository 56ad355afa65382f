# SPDX-License-Identifier: LGPL-2.1-or-later
"""Command-line front end: ``python3 -m surfcomp <command> ...``.

Each subcommand lives in its own module of this package with two functions,
``add_parser(subparsers)`` and ``run(args) -> int``. Exit codes: 0 ok, 2 bad input
(stderr says why, nothing written), 1 internal error, 130 interrupted (Ctrl-C), 143
terminated (SIGTERM), 129 hung up (SIGHUP). An interrupted command removes its temporary
files and writes nothing.
"""

import argparse
import importlib
import signal
import sys
import threading
import traceback

from .. import __version__
from ..errors import SurfcompError

#: subcommand modules, in the order ``--help`` lists them
COMMANDS = ("compensate", "inspect", "simulate", "gcode")


def build_parser(only=None):
    """The argument parser; with ``only`` (a command name) just that command's subparser,
    so a run imports one command module (and its dependencies), not all of them."""
    parser = argparse.ArgumentParser(
        prog="python3 -m surfcomp",
        description="Compensate machining errors of free-form B-spline surfaces "
                    "from measurements (Werner 2022; mirror method; axis error model).")
    parser.add_argument("--version", action="version", version="surfcomp " + __version__)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for name in (only,) if only in COMMANDS else COMMANDS:
        module = importlib.import_module("." + name, __name__)
        module.add_parser(subparsers)
    return parser


class ArgumentError(SurfcompError):
    exit_code = 2


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP: unwinds like Ctrl-C (temporary files removed, nothing written)."""

    def __init__(self, signum):
        super().__init__(signum)
        self.exit_code = 128 + signum


def _terminate(signum, _frame):
    raise Terminated(signum)


def _handle_signals():
    if threading.current_thread() is not threading.main_thread():
        return
    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is not None and signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, _terminate)


def main(argv=None):
    """Run the command line; return the process exit code."""
    args = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(args[0] if args else None)
    args = parser.parse_args(args)
    _handle_signals()
    try:
        return int(args.run(args) or 0)
    except SurfcompError as exc:
        print("surfcomp: error: %s" % exc, file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:
        print("surfcomp: %s; nothing was written"
              % ("interrupted" if not isinstance(exc, Terminated) else
                 "terminated by signal %d" % (exc.exit_code - 128)), file=sys.stderr)
        return getattr(exc, "exit_code", 130)
    except Exception:  # an internal error: show the traceback, exit 1
        traceback.print_exc()
        print("surfcomp: internal error (please report it with the traceback above)",
              file=sys.stderr)
        return 1
