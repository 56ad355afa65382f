# SPDX-License-Identifier: LGPL-2.1-or-later
"""Output files that are written together or not at all, and never over an input.

Every command declares its inputs and outputs before it does any work
(:func:`check_outputs`): an output that is an input or another output (compared by real
identity, across symbolic and hard links), a folder, a special file or a place that cannot be
written is refused with the option's name and the user's path. A :class:`Transaction` then
stages each output as a temporary file next to its destination and :meth:`Transaction.commit`
renames them all; when a rename fails, the ones already made are rolled back (an output that
existed before gets its old content back). Leaving the ``with`` block without committing
removes the temporary files and the folders the transaction created. Messages always name
the user's path, never a temporary file.
"""

import contextlib
import os
import tempfile

from ..errors import InputError, SurfcompError


def _mkstemp(path, suffix):
    """A temporary file next to ``path`` with the permissions a plain ``open`` would give."""
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=suffix,
                               dir=os.path.dirname(path))
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    return tmp


def _identity(path):
    """What makes two paths the same file: (device, inode) of an existing file, else the
    real path (symbolic links in the folders resolved)."""
    try:
        st = os.stat(path)
    except OSError:
        return ("path", os.path.join(os.path.realpath(os.path.dirname(os.path.abspath(path))),
                                     os.path.basename(path)))
    return ("inode", st.st_dev, st.st_ino)


def _existing_ancestor(folder):
    while not os.path.lexists(folder):
        parent = os.path.dirname(folder)
        if parent == folder:
            break
        folder = parent
    return folder


def _check_destination(option, path):
    if os.path.isdir(path):
        raise InputError("%s is a folder (expected a file name)" % option, file=path)
    if os.path.lexists(path) and not os.path.isfile(path):
        raise InputError("%s exists and is not a regular file (a device, pipe or broken "
                         "link); refusing to replace it" % option, file=path)
    folder = os.path.dirname(os.path.abspath(path))
    anc = _existing_ancestor(folder)
    if not os.path.isdir(anc):
        raise InputError("%s: cannot create the folder %s because %s is not a folder"
                         % (option, folder, anc), file=path)
    if not os.access(anc, os.W_OK | os.X_OK):
        raise InputError("%s: no permission to write in %s" % (option, anc), file=path)


def check_outputs(outputs, inputs=()):
    """Refuse outputs that would destroy an input, each other, or cannot be written.

    Parameters
    ----------
    outputs : iterable of (option, path)
        What the command writes, with the option that names it (``-o``, ``--report``);
        ``None`` paths are skipped.
    inputs : iterable of (what, path)
        What it reads (``NOMINAL``, ``MEASUREMENTS``, ``--axis-errors``, ...).

    Raises
    ------
    InputError
        Naming the option and the user's path. Nothing is created or written.
    """
    seen = {}
    ins = [(what, path, _identity(path)) for what, path in inputs if path]
    for option, path in outputs:
        if not path:
            continue
        _check_destination(option, path)
        key = _identity(path)
        for what, ipath, ikey in ins:
            if key == ikey:
                link = "" if os.path.abspath(path) == os.path.abspath(ipath) else \
                    " (the same file through a link)"
                raise InputError("%s would overwrite the input %s %s%s; nothing was written"
                                 % (option, what, ipath, link), file=path)
        if key in seen:
            raise InputError("%s and %s name the same file; give each output its own name"
                             % (seen[key], option), file=path)
        seen[key] = option


def _rename_error(path, exc):
    return InputError("cannot write the file: %s" % (exc.strerror or exc), file=path)


class Transaction:
    """Several output files that appear together or not at all.

    Parameters
    ----------
    outputs : iterable of (option, path), optional
        Declared outputs, checked (:func:`check_outputs`) against each other and ``inputs``
        when the transaction opens.
    inputs : iterable of (what, path), optional
    """

    def __init__(self, outputs=(), inputs=()):
        self._staged = []          # (temporary, destination)
        self._created = []         # folders made by this transaction, outermost first
        check_outputs(list(outputs), list(inputs))

    def __enter__(self):
        return self

    def _make_folders(self, folder):
        missing = []
        while not os.path.isdir(folder):
            missing.append(folder)
            folder = os.path.dirname(folder)
        for f in reversed(missing):
            os.mkdir(f)
            self._created.append(f)

    def stage(self, path, suffix=None):
        """Return a temporary path to write; it becomes ``path`` on commit."""
        path = os.path.abspath(path)
        suffix = os.path.splitext(path)[1] if suffix is None else suffix
        try:
            self._make_folders(os.path.dirname(path))
            tmp = _mkstemp(path, suffix)
        except OSError as exc:
            raise _rename_error(path, exc) from exc
        self._staged.append((tmp, path))
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

    def stage_bytes(self, path, data):
        def put(tmp):
            with open(tmp, "wb") as fh:
                fh.write(data)
        return self.write(path, put)

    def commit(self):
        """Rename every staged file to its destination; all or nothing."""
        done = []                  # (destination, backup of its old content or None)
        try:
            for tmp, path in self._staged:
                backup = None
                if os.path.lexists(path):
                    backup = _mkstemp(path, ".old")
                    if not _hard_link(path, backup):
                        os.replace(path, backup)
                done.append((path, backup))
                os.replace(tmp, path)
        except BaseException as exc:
            for path, backup in reversed(done):
                with contextlib.suppress(OSError):
                    if backup is not None:
                        os.replace(backup, path)
                    elif os.path.lexists(path):
                        os.unlink(path)
            if isinstance(exc, OSError):
                raise _rename_error(path, exc) from exc
            raise
        for _path, backup in done:
            if backup is not None:
                with contextlib.suppress(OSError):
                    os.unlink(backup)
        self._staged = []
        self._created = []

    def __exit__(self, *exc):
        for tmp, _ in self._staged:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        self._staged = []
        for folder in reversed(self._created):
            with contextlib.suppress(OSError):
                os.rmdir(folder)       # only empty ones: never something a user put there
        self._created = []
        return False


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
