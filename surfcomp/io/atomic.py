# SPDX-License-Identifier: LGPL-2.1-or-later
"""Output files that are written together or not at all, and never over an input.

Every command declares its inputs and outputs before it does any work
(:func:`check_outputs`). Each output is resolved once, as the kernel resolves it
(:mod:`surfcomp.io.outpath`): its folder must exist, as for ``open()``. An output that is
an input or another output (compared by real identity, across symbolic and hard links), a
folder, a special file, anything in /dev, /proc or /sys, or a place that cannot be written
is refused with the option's name and the user's path. A :class:`Transaction` then stages
each output as a temporary file next to its resolved destination and
:meth:`Transaction.commit` renames them all, with SIGINT, SIGTERM and SIGHUP held back;
when a rename fails, the ones already made are rolled back (an output that existed before
gets its old content back). An output named ``-`` is staged in a private folder and copied
to standard output after the renames. Leaving the ``with`` block without committing removes
the temporary files. What was committed is recorded in :data:`COMMITTED`. Messages always
name the user's path, never a temporary file.
"""

import contextlib
import os
import shutil
import signal
import sys
import tempfile
import threading

from ..errors import InputError, SurfcompError
from .outpath import STDOUT, identity, name_max, resolve

#: what the outputs committed since :func:`reset_committed` are (the user's paths): a
#: signal or a closed standard output after the commit reports them instead of claiming
#: that nothing was written
COMMITTED = []
#: signals held back while outputs are renamed into place or temporary files removed
HELD_SIGNALS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP")
                     if hasattr(signal, n))
_DATA_STDOUT = []
#: how deep :func:`signals_held` blocks are nested, and what signal handlers deferred
_HOLDING = [0]
_DEFERRED = []


def reset_committed():
    del COMMITTED[:]


@contextlib.contextmanager
def data_stdout(stream):
    """Outputs named ``-`` go to ``stream`` (the real standard output while the command's
    own printing goes to stderr)."""
    _DATA_STDOUT.append(stream)
    try:
        yield
    finally:
        _DATA_STDOUT.pop()


@contextlib.contextmanager
def signals_held():
    """Hold SIGINT, SIGTERM and SIGHUP back (delivered when the block ends), so renames
    and clean-ups are never cut in half.

    The main thread blocks them; a signal the kernel hands to another thread still runs
    the Python handler in the main thread, so handlers call :func:`defer` first (the
    command line's do)."""
    main = threading.current_thread() is threading.main_thread()
    old = None
    if main and hasattr(signal, "pthread_sigmask"):
        old = signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS)
    _HOLDING[0] += 1
    try:
        yield
    finally:
        _HOLDING[0] -= 1
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        if main and not _HOLDING[0]:
            while _DEFERRED:
                _DEFERRED.pop(0)()


def defer(action):
    """Inside :func:`signals_held`, keep ``action`` (a signal handler's work) for the end
    of the block and return True; outside, return False."""
    if not _HOLDING[0]:
        return False
    _DEFERRED.append(action)
    return True


def signal_waiting():
    """Whether a signal waits for the end of a :func:`signals_held` block."""
    pending = signal.sigpending() if hasattr(signal, "sigpending") else ()
    return bool(_DEFERRED) or bool(set(pending) & set(HELD_SIGNALS))


def _mkstemp(path, suffix):
    """A temporary file next to ``path`` with the permissions a plain ``open`` would give;
    its name fits the file system (``path``'s own name may take all of it)."""
    folder = os.path.dirname(path)
    room = name_max(folder) - 10            # "." + name + "." + 8 random characters
    if len(os.fsencode(suffix)) > room - 1:
        suffix = ""
    prefix = os.fsencode("." + os.path.basename(path))[:room - len(os.fsencode(suffix))]
    fd, tmp = tempfile.mkstemp(prefix=prefix.decode("utf-8", "ignore") + ".",
                               suffix=suffix, dir=folder)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    return tmp


def _inputs(inputs):
    """(what, path, identity, options allowed to replace it) of each declared input."""
    out = []
    for entry in inputs:
        what, path = entry[0], entry[1]
        if path and path != STDOUT:
            out.append((what, path, identity(path), tuple(entry[2]) if len(entry) > 2 else ()))
    return out


def check_outputs(outputs, inputs=()):
    """Refuse outputs that would destroy an input, each other, or cannot be written.

    Parameters
    ----------
    outputs : iterable of (option, path)
        What the command writes, with the option that names it (``-o``, ``--report``, or
        a :class:`surfcomp.errors.Note` naming a job key, shown as the flag by the
        command line);
        ``None`` paths are skipped, an empty one is refused; ``-`` is standard output.
    inputs : iterable of (what, path) or (what, path, options)
        What it reads (``NOMINAL``, ``MEASUREMENTS``, ``--axis-errors``, ...); ``options``
        may replace it (``--save`` with ``--overwrite-input``).

    Returns
    -------
    dict
        The user's path -> its :class:`surfcomp.io.outpath.Destination`.

    Raises
    ------
    InputError
        Naming the option and the user's path. Nothing is created or written.
    """
    seen, dests = {}, {}
    ins = _inputs(inputs)
    for option, path in outputs:
        if path is None:
            continue
        dest = resolve(option, path)
        for what, ipath, ikey, allowed in ins:
            if dest.key == ikey and option not in allowed:
                link = "" if os.path.abspath(path) == os.path.abspath(ipath) else \
                    " (the same file through a link)"
                # joined, not formatted: a label that is a Note (an option's name, shown
                # as a flag on the command line) stays one
                raise InputError(option + " would overwrite the input " + what
                                 + " %s%s; nothing was written" % (ipath, link), file=path)
        if dest.key in seen:
            raise InputError(seen[dest.key] + " and " + option
                             + " name the same %s; give each output its own name"
                             % ("standard output" if dest.stdout else "file"), file=path)
        seen[dest.key] = option
        dests[os.fspath(path)] = dest
    return dests


def _rename_error(path, exc):
    return InputError("cannot write the file: %s" % (exc.strerror or exc), file=path)


class Transaction:
    """Several output files that appear together or not at all.

    Parameters
    ----------
    outputs : iterable of (option, path), optional
        Declared outputs, checked (:func:`check_outputs`) against each other and ``inputs``
        when the transaction opens; each is staged where its resolved path is.
    inputs : iterable of (what, path[, options]), optional
    """

    def __init__(self, outputs=(), inputs=()):
        self._staged = []          # (temporary, destination)
        self._private = []         # folders holding what goes to standard output
        self._dests = check_outputs(list(outputs), list(inputs))

    def __enter__(self):
        return self

    def _destination(self, path):
        path = os.fspath(path)
        if path not in self._dests:
            self._dests.update(check_outputs([("output", path)]))
        return self._dests[path]

    def stage(self, path, suffix=None):
        """Return a temporary path to write; it becomes ``path`` on commit."""
        dest = self._destination(path)
        suffix = os.path.splitext(dest.path)[1] if suffix is None else suffix
        try:
            if dest.stdout:
                folder = tempfile.mkdtemp(prefix="surfcomp-stdout-")
                self._private.append(folder)
                tmp = os.path.join(folder, "output" + suffix)
            else:
                tmp = _mkstemp(dest.real, suffix)
        except OSError as exc:
            raise _rename_error(dest.path, exc) from exc
        self._staged.append((tmp, dest))
        return tmp

    def write(self, path, writer, suffix=None):
        """Stage ``path`` and call ``writer(temporary_path)``; errors name ``path``."""
        tmp = self.stage(path, suffix)
        try:
            writer(tmp)
        except SurfcompError as exc:
            if exc.file == tmp:
                exc.file = path
            exc.message = exc.message.replace(tmp, path)
            exc.args = (exc.message,)
            raise
        except OSError as exc:
            raise _rename_error(path, exc) from exc
        return tmp

    def stage_text(self, path, text, encoding="utf-8"):
        def put(tmp):
            with open(tmp, "w", encoding=encoding, newline="\n") as fh:
                fh.write(text)
        return self.write(path, put)

    def commit(self):
        """Rename every staged file to its destination, then copy what goes to standard
        output there; all files or none. Signals wait until it is done."""
        with signals_held():
            done = []              # (destination, backup of its old content or None)
            dest = None
            try:
                for tmp, dest in self._staged:
                    if not dest.stdout:
                        done.append((dest.real, _rename_into_place(tmp, dest.real)))
                for tmp, dest in self._staged:
                    if dest.stdout:
                        _copy_to_stdout(tmp)
            except OSError as exc:
                _roll_back(done)
                raise _rename_error(dest.path, exc) from exc
            except BaseException:
                _roll_back(done)
                raise
            COMMITTED.extend(dest.path for _tmp, dest in self._staged)
            for _path, backup in done:
                if backup is not None:
                    with contextlib.suppress(OSError):
                        os.unlink(backup)
            self._staged = [(tmp, d) for tmp, d in self._staged if d.stdout]

    def __exit__(self, *exc):
        with signals_held():
            for tmp, _ in self._staged:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
            self._staged = []
            for folder in self._private:
                shutil.rmtree(folder, ignore_errors=True)
            self._private = []
        return False


def _rename_into_place(tmp, path):
    """Rename ``tmp`` to ``path``; returns the backup of ``path``'s old content (or None)."""
    backup = None
    if os.path.lexists(path):
        backup = _mkstemp(path, ".old")
        if not _hard_link(path, backup):
            os.replace(path, backup)
    try:
        os.replace(tmp, path)
    except BaseException:
        if backup is not None:
            with contextlib.suppress(OSError):
                os.replace(backup, path)
        raise
    return backup


def _roll_back(done):
    for path, backup in reversed(done):
        with contextlib.suppress(OSError):
            if backup is not None:
                os.replace(backup, path)
            elif os.path.lexists(path):
                os.unlink(path)


def _copy_to_stdout(tmp):
    stream = _DATA_STDOUT[-1] if _DATA_STDOUT else sys.stdout
    stream.flush()
    binary = getattr(stream, "buffer", None)
    with open(tmp, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            if binary is not None:
                binary.write(block)
            else:
                stream.write(block.decode("utf-8", "replace"))
    (binary or stream).flush()


def _hard_link(path, backup):
    """Keep ``path``'s content under ``backup`` while ``path`` stays in place (a hard link
    over the empty placeholder); False when the file system has no hard links."""
    try:
        os.unlink(backup)
        os.link(path, backup)
        return True
    except OSError:
        return False


def write_text(path, text, encoding="utf-8", inputs=(), option="output"):
    """Write ``text`` to ``path`` atomically (never over one of ``inputs``)."""
    with Transaction([(option, path)], inputs) as tx:
        tx.stage_text(path, text, encoding)
        tx.commit()
