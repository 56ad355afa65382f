# SPDX-License-Identifier: LGPL-2.1-or-later
"""The CAD reader's child as a fork of this process (:mod:`surfcomp.app.cadread`).

A fresh ``python3`` reading one STEP file starts Python, FreeCAD and Part again before it
reads: for the example nominal that is about as much CPU as the whole FreeCAD job of
reading and writing the file. A fork of this process, once FreeCAD and Part are imported,
only reads. It is still a separate process: OpenCASCADE crashing on a damaged file ends
the child, and the parent says so.

A fork is taken only where it is safe: ``os.fork`` exists, the process has one thread
(a fork copies only the calling thread; a lock another thread held would never be
released in the child) and the FreeCAD GUI is not loaded (its display connection and event
loop are not the child's to share). :func:`usable` imports FreeCAD and Part first (the
caller needs them anyway) and then looks. Elsewhere the reader is a fresh ``python3``.

:class:`Forked` has the parts of :class:`subprocess.Popen` the reader uses: ``poll``,
``kill``, ``communicate(timeout)`` (stderr text) and ``returncode`` (negative: the signal
that ended it).
"""

import os
import select
import signal
import subprocess
import sys
import time

from ..io import forks

#: a crash ends a reader child with its signal (FreeCAD's own SIGSEGV handler exits with
#: code 1 and no message, which the parent could not tell from a reader error)
FATAL_SIGNALS = ("SIGSEGV", "SIGBUS", "SIGFPE", "SIGILL", "SIGABRT")
#: signals the forked child takes with the system's default action: the crashes, and Ctrl-C
#: and termination end it at once (the parent's handlers are the parent's)
DEFAULT_SIGNALS = FATAL_SIGNALS + ("SIGINT", "SIGTERM", "SIGHUP")


def default_signals(names=DEFAULT_SIGNALS):
    """Give the signals ``names`` their default action (in a reader child)."""
    for name in names:
        sig = getattr(signal, name, None)
        if sig is not None:
            signal.signal(sig, signal.SIG_DFL)


def usable():
    """Whether the reader may be a fork of this process; imports FreeCAD and Part first
    (False when they cannot be imported: the fresh ``python3`` then says why)."""
    if not hasattr(os, "fork") or "FreeCADGui" in sys.modules:
        return False
    from . import fcenv

    try:
        fcenv.import_freecad()
        import Part  # noqa: F401  (imported before the fork, so the child need not)
    except ImportError:
        return False
    return forks.threads() == 1


class Forked:
    """``work()`` (returning an exit code) run in a fork of this process, in folder ``cwd``,
    with standard input and output on the null device and standard error on a pipe the
    parent reads."""

    def __init__(self, work, cwd):
        read_end, write_end = os.pipe()
        forks.flush_streams()
        pid = os.fork()
        if pid == 0:                                # the child: never returns
            os.close(read_end)
            _child(work, cwd, write_end)
        os.close(write_end)
        self.pid, self._fd, self._err = pid, read_end, []
        self.returncode = None

    def poll(self):
        """The exit code when the child has ended, else None."""
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def kill(self):
        if self.returncode is None:
            os.kill(self.pid, signal.SIGKILL)

    def communicate(self, timeout=None):
        """``(None, stderr)`` once the child has ended.

        Raises
        ------
        subprocess.TimeoutExpired
            The child still runs (and holds its standard error open) after ``timeout``
            seconds; it is left running (:meth:`kill` it).
        """
        end = None if timeout is None else time.monotonic() + timeout
        while self._fd is not None:
            left = None if end is None else max(0.0, end - time.monotonic())
            ready = select.select([self._fd], [], [], left)[0]
            if not ready:
                raise subprocess.TimeoutExpired("reader child", timeout)
            chunk = os.read(self._fd, 65536)
            if chunk:
                self._err.append(chunk)
            else:
                os.close(self._fd)
                self._fd = None
        if self.returncode is None:
            self.returncode = os.waitstatus_to_exitcode(os.waitpid(self.pid, 0)[1])
        return None, b"".join(self._err).decode("utf-8", "replace")


def _child(work, cwd, err_fd):
    """The forked child: its signals, folder and standard streams, then ``work``; it ends
    with ``os._exit`` (no exit handlers and buffers of the parent's run a second time)."""
    code = 1
    try:
        default_signals()
        os.chdir(cwd)
        null = os.open(os.devnull, os.O_RDWR)
        os.dup2(null, 0)
        os.dup2(null, 1)
        os.dup2(err_fd, 2)
        # Python's streams on the new descriptors (a caller may have replaced sys.stderr
        # by an object of its own, e.g. a test's capture, which the parent never reads)
        sys.stdout = open(1, "w", closefd=False)
        sys.stderr = open(2, "w", closefd=False, errors="backslashreplace")
        code = work()
    except BaseException as exc:     # anything: the parent reads the reason, code 1
        try:
            os.write(2, ("%s: %s\n" % (type(exc).__name__, exc)).encode("utf-8", "replace"))
        except OSError:
            pass
    finally:
        try:
            sys.stderr.flush()
        except (AttributeError, OSError, ValueError):
            pass
        os._exit(code if isinstance(code, int) else 1)
