# SPDX-License-Identifier: LGPL-2.1-or-later
"""Running a command to its exit code: errors, signals and standard output, told truthfully.

Shared by ``python3 -m surfcomp`` and the ``freecadcmd`` job macro. Exit codes: 0 when the
outputs are complete (also when a signal or a closed standard output comes after they were
committed: stderr then names them), 2 bad input (nothing written), 1 internal error, 130
interrupted (SIGINT), 143 terminated (SIGTERM), 129 hung up (SIGHUP) before the commit
(nothing written, no temporary file left). The first of these signals stops the command;
later ones are ignored while it cleans up.
"""

import contextlib
import os
import signal
import sys
import threading
import traceback

from ..errors import SurfcompError
from ..io import atomic
from .option_flags import shown

SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP: unwinds like Ctrl-C (temporary files removed, nothing written)."""

    def __init__(self, signum):
        super().__init__(signum)
        self.exit_code = 128 + signum


class _Stop:
    """The signal handler: the first signal raises, later ones are ignored (the command is
    already stopping and its clean-up must not be cut short)."""

    def __init__(self):
        self.signum = None

    def __call__(self, signum, _frame):
        if self.signum is not None:
            return
        self.signum = signum
        if not atomic.defer(self.stop):
            self.stop()

    def stop(self):
        if self.signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(self.signum)


@contextlib.contextmanager
def signals_handled():
    """Install :class:`_Stop` for SIGINT, SIGTERM and SIGHUP (those not ignored by whoever
    started us, e.g. ``nohup``); restore the previous handlers afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    stop, saved = _Stop(), {}
    for name in SIGNALS:
        sig = getattr(signal, name, None)
        if sig is None:
            continue
        old = signal.getsignal(sig)
        if old is signal.SIG_IGN:
            continue
        saved[sig] = old
        signal.signal(sig, stop)
    try:
        yield
    finally:
        for sig, old in saved.items():
            signal.signal(sig, old if old is not None else signal.SIG_DFL)


def _written():
    return ", ".join("standard output" if p == "-" else p for p in atomic.COMMITTED)


def _interrupted(exc):
    word = "interrupted" if not isinstance(exc, Terminated) else \
        "terminated by signal %d" % (exc.exit_code - 128)
    if atomic.COMMITTED:
        print("surfcomp: %s after the outputs were complete; written: %s"
              % (word, _written()), file=sys.stderr)
        return 0
    print("surfcomp: %s; nothing was written" % word, file=sys.stderr)
    return getattr(exc, "exit_code", 130)


def _stdout_closed(exc, rc):
    """Standard output failed (``| head``, ``> /dev/full``): say so on stderr; the exit code
    stays 0 when the outputs are complete."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())   # the interpreter's own flush at exit
        os.close(devnull)
    why = getattr(exc, "strerror", None) or exc
    if atomic.COMMITTED:
        print("surfcomp: standard output failed (%s) after the outputs were complete; "
              "written: %s" % (why, _written()), file=sys.stderr)
        return rc
    print("surfcomp: standard output failed (%s); nothing was written" % why, file=sys.stderr)
    return rc or 1


def _run(body, flags):
    try:
        return int(body() or 0)
    except SurfcompError as exc:
        print("surfcomp: error: %s" % (shown(exc) if flags else exc), file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:
        return _interrupted(exc)
    except OSError as exc:
        if _is_stdout_error(exc):
            return _stdout_closed(exc, 0)
        raise


def _is_stdout_error(exc):
    import errno

    return isinstance(exc, BrokenPipeError) or exc.errno in (errno.ENOSPC, errno.EIO) and \
        atomic.COMMITTED


def run(body, data_to_stdout=False, flags=True):
    """``body()`` -> its exit code, with the messages and exit codes of this module.

    ``data_to_stdout``: an output goes to standard output, so everything ``body`` prints
    goes to stderr instead. ``flags``: errors name options as the command line's flags
    (``--max-offset``); False keeps their names (``max_offset``, as a job file's keys)."""
    atomic.reset_committed()
    real_stdout = sys.stdout
    try:
        with signals_handled():
            try:
                with atomic.data_stdout(real_stdout), \
                        contextlib.redirect_stdout(sys.stderr if data_to_stdout else sys.stdout):
                    rc = _run(body, flags)
                try:
                    real_stdout.flush()
                except OSError as exc:
                    rc = _stdout_closed(exc, rc)
            except KeyboardInterrupt as exc:       # while an error was being reported
                rc = _interrupted(exc)
    except Exception:  # an internal error: show the traceback, exit 1
        traceback.print_exc()
        print("surfcomp: internal error (please report it with the traceback above)%s"
              % ("; the outputs were complete: " + _written() if atomic.COMMITTED else ""),
              file=sys.stderr)
        return 1
    return rc
