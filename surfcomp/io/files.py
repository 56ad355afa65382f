# SPDX-License-Identifier: LGPL-2.1-or-later
"""Reading input files: the one place that turns an unreadable file into the project's error."""

import contextlib

from ..errors import MeasurementFileError

#: bytes of the files being read once (:func:`read_once`), by path
_ONCE = {}

#: largest input file read (a 1M-point measurement file is about 100 MB)
MAX_INPUT_BYTES = 4 * 1024 ** 3


def clip(text, limit=40):
    """``text`` for a message: at most ``limit`` characters, with the full length when cut
    (a field of a damaged file may be megabytes long)."""
    text = str(text)
    if len(text) <= limit:
        return text
    return "%s... (%d characters)" % (text[:limit - 8], len(text))


def read_bytes(path, what="the file", error=MeasurementFileError, limit=None):
    """The bytes of ``path`` (at most ``limit`` of them when given).

    Raises
    ------
    error (default MeasurementFileError)
        The file cannot be read (missing, a folder, no permission) or is larger than
        :data:`MAX_INPUT_BYTES`; the message names the file.
    """
    source = str(path)
    if source in _ONCE:
        data = _ONCE[source]
        return data if limit is None else data[:limit]
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_INPUT_BYTES + 1 if limit is None else limit)
    except OSError as exc:
        raise error("cannot read %s: %s" % (what, exc.strerror or exc), file=source) from exc
    if limit is None and len(data) > MAX_INPUT_BYTES:
        raise error("%s is larger than %d GB; expected a measurement or program file"
                    % (what, MAX_INPUT_BYTES // 1024 ** 3), file=source)
    return data


@contextlib.contextmanager
def read_once(path, what="the file", error=MeasurementFileError):
    """Inside the block every :func:`read_bytes` of ``path`` returns the same bytes, read
    once at its start: a format detection and the reader that follows see one content, and
    a pipe (``/dev/stdin``, a FIFO, ``<(...)``), which can be read only once, works."""
    source = str(path)
    if source in _ONCE:
        yield
        return
    _ONCE[source] = read_bytes(path, what, error)
    try:
        yield
    finally:
        del _ONCE[source]
