# SPDX-License-Identifier: LGPL-2.1-or-later
"""The JSON job file of the ``freecadcmd`` route: read it safely, check the values of its keys.

:func:`read_job_file` reads the file once, as a regular file of bounded size (a FIFO or a
device would block or never end), in UTF-8 with or without a byte-order mark (UTF-16 and
UTF-32, with or without their marks, are refused by name), with nesting bounded before
the JSON parser sees it (100 000 nested brackets would exhaust the parser's stack).

:func:`check_values` checks the type and range of every known key's value (``"nominal":
5``, ``"weights": {}``, ``"mask_size": true`` are refused with the key, what it holds and
what was expected). Which keys exist, and which commands, is decided by the caller
(:func:`surfcomp.app.file_route.load_job_file`); keys not listed in :data:`KEY_TYPES` are
left to it.
"""

import json
import math
import os
import stat

from ..core.option_tables import ALIGN, INPUTS
from ..core.options import OPTIONS
from ..errors import InputError

#: largest job file, bytes (a job file names files and options: a few hundred bytes)
MAX_BYTES = 1 << 20
#: deepest nesting of brackets accepted (a job file needs 3: the object, ``weights``' rows)
MAX_DEPTH = 32

_PATH = ("a file name (a non-empty string)", lambda v: isinstance(v, str) and v != "")
_NAME = ("a non-empty string", lambda v: isinstance(v, str) and v.strip() != "")
_BOOL = ("true or false", lambda v: isinstance(v, bool))


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _integer(v):
    return isinstance(v, int) and not isinstance(v, bool)


def _weights(v):
    """A weights string (``"1 2 1; 2 4 2; 1 2 1"``) or a square list of lists of numbers."""
    if isinstance(v, str):
        return v.strip() != ""
    return (isinstance(v, list) and len(v) > 0
            and all(isinstance(r, list) and len(r) == len(v) and all(_number(x) for x in r)
                    for r in v))


_NUMBER = ("a finite number", _number)
_OPT_NUMBER = ("a finite number or null", lambda v: v is None or _number(v))
_INTEGER = ("a whole number", _integer)



def _option_type(o, choices=False):
    """What a job file's value of the registry's option ``o`` must be (with ``choices``
    False the choices are left to :meth:`surfcomp.core.compensation.pipeline.Options.validate`
    or the reader)."""
    if choices and o.choices is not None:
        return ("one of %s" % ", ".join('"%s"' % c for c in o.choices),
                lambda v, c=o.choices: v in c)
    if o.type is bool:
        return _BOOL
    if o.type is int:
        return _INTEGER
    if o.type is float:
        return _OPT_NUMBER if o.optional else _NUMBER
    return _NAME


#: known keys: (what is expected, test); paths and the registry's options by their type:
#: the compensation's (:data:`surfcomp.core.options.OPTIONS`), the inputs and the alignment
#: (:data:`surfcomp.core.option_tables.INPUTS`, :data:`~surfcomp.core.option_tables.ALIGN`;
#: the alignment's method checked against its choices here)
KEY_TYPES = {
    "command": _NAME,
    "nominal": _PATH, "measurements": _PATH,
    "output": _PATH, "report": _PATH, "points": _PATH, "curves": _PATH, "html": _PATH,
    "face_only": _BOOL,
    **{name: _option_type(o) for name, o in OPTIONS.items()},
    **{name: _option_type(o) for name, o in INPUTS.items()},
    **{name: _option_type(o, choices=True) for name, o in ALIGN.items()},
    "weights": ("a weights text such as \"1 2 1; 2 4 2; 1 2 1\" or a square list of lists "
                "of numbers, or null", lambda v: v is None or _weights(v)),
    "plan": _PATH, "transform": _PATH,
}
#: keys that may be null (meaning: not given)
NULLABLE = {"output", "report", "points", "curves", "html", "plan"} | {
    name for table in (OPTIONS, INPUTS, ALIGN) for name, o in table.items() if o.optional}


def _describe(value):
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (dict, list)):
        return "a JSON %s" % ("object" if isinstance(value, dict) else "list")
    text = json.dumps(value)
    return text if len(text) <= 40 else text[:37] + "..."


def check_values(data, path=None):
    """Refuse a job dict whose known keys hold values of the wrong type or range.

    Parameters
    ----------
    data : dict
        The job file's object (:func:`read_job_file`).
    path : str, optional
        The job file, for the message.

    Raises
    ------
    InputError
        Naming the first key in file order whose value is wrong, what it holds and what
        was expected.
    """
    for key, value in data.items():
        if key not in KEY_TYPES or (value is None and key in NULLABLE):
            continue
        expected, ok = KEY_TYPES[key]
        if not ok(value):
            raise InputError("job key %r is %s (expected %s)" % (key, _describe(value), expected),
                             file=path)
    return data


def _depth(text):
    """The deepest nesting of ``[``/``{`` outside strings (a linear scan, no recursion)."""
    depth = deepest = 0
    in_string = escaped = False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
    return deepest


def _decode(raw, path):
    if raw[:4] in (b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff") or raw[:2] in (b"\xff\xfe",
                                                                             b"\xfe\xff"):
        raise InputError("the job file is in UTF-16 or UTF-32 (expected UTF-8; save it as "
                         "UTF-8)", file=path)
    if len(raw) >= 2 and (raw[0] == 0 or raw[1] == 0):
        raise InputError("the job file holds NUL bytes, as UTF-16 or UTF-32 text does "
                         "(expected UTF-8; save it as UTF-8)", file=path)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise InputError("not UTF-8 text (byte 0x%02x; expected a UTF-8 JSON file)"
                         % raw[exc.start], file=path, line=line) from None


def _read_error(exc, path):
    return InputError("cannot read the job file: %s" % (exc.strerror or exc), file=path)


def read_job_file(path):
    """The JSON object of the job file ``path`` (a dict), values checked by
    :func:`check_values`.

    Raises
    ------
    InputError
        Not a regular file, larger than :data:`MAX_BYTES`, not UTF-8, nested deeper than
        :data:`MAX_DEPTH`, not JSON, not a JSON object, or a value of the wrong type.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as exc:
        raise _read_error(exc, path) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise InputError("the job file is not a regular file (a FIFO, device or folder; "
                             "expected a JSON file)", file=path)
        if st.st_size > MAX_BYTES:
            raise InputError("the job file has %d bytes (expected a JSON job of at most %d)"
                             % (st.st_size, MAX_BYTES), file=path)
        with os.fdopen(os.dup(fd), "rb") as fh:
            raw = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise _read_error(exc, path) from None
    finally:
        os.close(fd)
    if len(raw) > MAX_BYTES:
        raise InputError("the job file grew beyond %d bytes while read" % MAX_BYTES, file=path)
    text = _decode(raw, path)
    if _depth(text) > MAX_DEPTH:
        raise InputError("the job file nests brackets deeper than %d levels (expected a JSON "
                         "object of file names and options)" % MAX_DEPTH, file=path)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError("not valid JSON: %s (expected a JSON object)" % exc.msg,
                         file=path, line=exc.lineno, column=exc.colno) from None
    except RecursionError:      # not reached after the depth check; kept as a guard
        raise InputError("the job file nests too deeply", file=path) from None
    if not isinstance(data, dict):
        raise InputError("the job file must hold a JSON object (it holds %s)"
                         % _describe(data), file=path)
    return check_values(data, path)
