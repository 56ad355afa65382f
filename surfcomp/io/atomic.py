"""Atomic file output: write to a temporary file in the target folder, then rename.

A failed or interrupted run never leaves a partial output file behind.
"""

import contextlib
import os
import tempfile


def _mkstemp(path, suffix):
    """A temporary file next to ``path`` with the permissions a plain ``open`` would give."""
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=suffix,
                               dir=os.path.dirname(path))
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    return tmp


@contextlib.contextmanager
def atomic_path(path, suffix=None):
    """Yield a temporary path next to ``path``; on success rename it to ``path``.

    ``suffix`` (default: the extension of ``path``) matters to writers that choose
    the format from the extension (OCCT's STEP/IGES/BREP writers).
    """
    path = os.path.abspath(path)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    suffix = os.path.splitext(path)[1] if suffix is None else suffix
    tmp = _mkstemp(path, suffix)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_text(path, text, encoding="utf-8"):
    """Write ``text`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding=encoding, newline="\n") as fh:
            fh.write(text)


class Transaction:
    """Several output files that appear together or not at all.

    Files are staged as temporary files; :meth:`commit` renames them all, and
    leaving the ``with`` block without committing removes them.
    """

    def __init__(self):
        self._staged = []

    def __enter__(self):
        return self

    def stage(self, path, suffix=None):
        """Return a temporary path to write; it becomes ``path`` on commit."""
        path = os.path.abspath(path)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        suffix = os.path.splitext(path)[1] if suffix is None else suffix
        tmp = _mkstemp(path, suffix)
        self._staged.append((tmp, path))
        return tmp

    def stage_text(self, path, text):
        tmp = self.stage(path)
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)

    def commit(self):
        for tmp, path in self._staged:
            os.replace(tmp, path)
        self._staged = []

    def __exit__(self, *exc):
        for tmp, _ in self._staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
        self._staged = []
        return False
