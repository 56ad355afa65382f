# SPDX-License-Identifier: LGPL-2.1-or-later
"""Hostile job files of the ``freecadcmd`` route (issue 25, items 6 and 7): values of the
wrong type for known keys, nesting that would exhaust the JSON parser, UTF-16 and UTF-32,
a FIFO, a device, a folder, an oversized file. Each is refused with the job file's name and
what was expected, before anything is read or written; a UTF-8 byte-order mark is fine.

Most cases call :func:`surfcomp.app.file_route.load_job_file` (what the macro calls
first); two run the macro in ``freecadcmd`` to see the exit code and that nothing hangs.
"""

import json
import os
import signal
import subprocess

import pytest

from surfcomp.errors import InputError
from surfcomp.io.jobfile import MAX_BYTES, MAX_DEPTH, check_values, read_job_file

from .harness import EXAMPLE_CSV, ROOT

BASE = {"command": "inspect", "nominal": "n.step", "measurements": "m.csv"}


def _job(**changes):
    data = dict(BASE)
    data.update(changes)
    return json.dumps(data)


WRONG_VALUES = [
    ("nominal-number", _job(nominal=5), "job key 'nominal' is 5 (expected a file name"),
    ("measurements-list", _job(measurements=["m.csv"]),
     "job key 'measurements' is a JSON list (expected a file name"),
    ("output-empty", _job(command="compensate", output=""),
     "job key 'output' is \"\" (expected a file name"),
    ("report-object", _job(report={"path": "r.json"}), "job key 'report' is a JSON object"),
    ("weights-empty-object", _job(weights={}), "job key 'weights' is a JSON object"),
    ("weights-empty-list", _job(weights=[]), "job key 'weights' is a JSON list"),
    ("weights-ragged", _job(weights=[[1, 2, 1], [2, 4]]), "job key 'weights' is a JSON list"),
    ("weights-true", _job(weights=True), "job key 'weights' is true"),
    ("mask-size-true", _job(mask_size=True), "job key 'mask_size' is true (expected a whole"),
    ("mask-size-float", _job(mask_size=5.0), "job key 'mask_size' is 5.0 (expected a whole"),
    ("mask-size-text", _job(mask_size="5"), "job key 'mask_size' is \"5\""),
    ("refine-null", _job(refine=None), "job key 'refine' is null"),
    ("max-offset-nan", _job(max_offset=float("nan")), "job key 'max_offset' is NaN"),
    ("tip-radius-infinity", _job(tip_radius=float("-inf")), "job key 'tip_radius' is -Infinity"),
    ("stock-text", _job(stock="0.2 mm"), "job key 'stock' is \"0.2 mm\" (expected a finite"),
    ("face-only-yes", _job(face_only="yes"), "job key 'face_only' is \"yes\" (expected true or"),
    ("flip-normals-one", _job(flip_normals=1), "job key 'flip_normals' is 1 (expected true"),
    ("method-number", _job(method=2), "job key 'method' is 2 (expected a non-empty string)"),
    ("command-blank", _job(command="  "), "job key 'command' is \"  \""),
]


def _deep(depth, open_="[", close="]"):
    return '{"nominal": "n.step", "measurements": "m.csv", "x": %s%s}' % (
        open_ * depth, close * depth)


BAD_FILES = [
    ("deep-100k-lists", _deep(100_000).encode(), "nests brackets deeper than %d" % MAX_DEPTH),
    ("deep-objects", ('{"a":' * 5000 + "1" + "}" * 5000).encode(), "deeper than"),
    ("deep-unclosed", ("[" * 300_000).encode(), "deeper than"),
    ("utf16-le-bom", _job().encode("utf-16"), "UTF-16 or UTF-32 (expected UTF-8"),
    ("utf16-be-no-bom", _job().encode("utf-16-be"), "NUL bytes"),
    ("utf32-le", _job().encode("utf-32-le"), "NUL bytes"),
    ("latin1", '{"nominal": "n\u00e9.step", "measurements": "m.csv"}'.encode("latin-1"),
     "not UTF-8 text (byte 0xe9"),
    ("top-level-list", b"[1, 2]", "must hold a JSON object (it holds a JSON list)"),
    ("top-level-string", b'"n.step"', "must hold a JSON object"),
    ("oversized", b'{"nominal": "' + b"n" * (MAX_BYTES + 10) + b'"}', "bytes (expected a JSON"),
    ("empty", b"", "not valid JSON"),
]


@pytest.mark.parametrize("name, text, says", WRONG_VALUES, ids=[c[0] for c in WRONG_VALUES])
def test_wrong_value_of_a_known_key(name, text, says, tmp_path):
    from surfcomp.app.file_route import load_job_file

    path = tmp_path / "job.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as err:
        load_job_file(str(path))
    assert str(err.value).startswith(str(path) + ": ")
    assert says in str(err.value), str(err.value)


@pytest.mark.parametrize("name, data, says", BAD_FILES, ids=[c[0] for c in BAD_FILES])
def test_job_file_that_cannot_be_a_job(name, data, says, tmp_path):
    path = tmp_path / "job.json"
    path.write_bytes(data)
    with pytest.raises(InputError) as err:
        read_job_file(str(path))
    assert str(err.value).startswith(str(path))
    assert says in str(err.value), str(err.value)
    assert len(str(err.value)) < 400


def test_byte_order_mark_and_nulls_are_accepted(tmp_path):
    """A UTF-8 byte-order mark (Windows editors write one) and null for optional keys."""
    path = tmp_path / "job.json"
    path.write_bytes(b"\xef\xbb\xbf" + _job(report=None, weights=[[1, 2, 1], [2, 4, 2],
                                                                   [1, 2, 1]]).encode())
    data = read_job_file(str(path))
    assert data["nominal"] == "n.step" and data["report"] is None
    assert data["weights"][1] == [2, 4, 2]


@pytest.mark.parametrize("kind", ["fifo", "folder", "device"])
def test_job_file_that_is_not_a_regular_file(kind, tmp_path):
    """A FIFO without a writer would block the reader forever; a device never ends."""
    path = {"device": "/dev/zero"}.get(kind, str(tmp_path / "job.json"))
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "folder":
        os.mkdir(path)
    with pytest.raises(InputError) as err:
        read_job_file(path)
    assert "not a regular file" in str(err.value)


def test_unknown_keys_are_left_to_the_caller():
    assert check_values({"colour": {}, "nominal": "n.step"}) == {"colour": {},
                                                               "nominal": "n.step"}


def _reset_signals():
    for sig in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)


def _macro(job, cwd):
    return subprocess.run(["freecadcmd", os.path.join(ROOT, "macros", "surfcomp_job.py")],
                          env=dict(os.environ, SURFCOMP_JOB=str(job)), cwd=str(cwd),
                          capture_output=True, text=True, timeout=120, restore_signals=True,
                          preexec_fn=_reset_signals)


@pytest.mark.parametrize("kind", ["fifo", "deep", "nominal-5"])
def test_freecadcmd_refuses_with_exit_2(kind, tmp_path):
    """Through ``freecadcmd``: exit 2, the job file named, no traceback, no hang, nothing
    written (the FIFO has no writer: reading it would block for ever)."""
    job = tmp_path / "job.json"
    if kind == "fifo":
        os.mkfifo(job)
    elif kind == "deep":
        job.write_text(_deep(100_000))
    else:
        job.write_text(json.dumps({"command": "compensate", "nominal": 5,
                                   "measurements": EXAMPLE_CSV, "report": "r.json"}))
    before = sorted(os.listdir(tmp_path))
    out = _macro(job, tmp_path)
    assert out.returncode == 2, out.stdout + out.stderr
    assert "Traceback" not in out.stderr
    assert "surfcomp: error: %s: " % job in out.stderr
    assert sorted(os.listdir(tmp_path)) == before


def test_every_key_a_job_takes_has_a_type():
    """The job's keys (its fields and the options a user sets) and the value table agree, so
    a key added to the job is type-checked without further code; ``context`` (who reads the
    messages) is no job key."""
    from surfcomp.app.file_route import job_keys
    from surfcomp.io.jobfile import KEY_TYPES

    known, options = job_keys()
    assert known | options == set(KEY_TYPES)
    assert "context" not in known | options


@pytest.mark.parametrize("key, value, says", [
    ("accept_stock", "yes", "expected true or false"),
    ("deviation_units", 5, "expected a non-empty string")])
def test_keys_added_later_are_checked_too(key, value, says):
    with pytest.raises(InputError) as info:
        check_values({"command": "compensate", "nominal": "n.step", "measurements": "m.csv",
                      key: value}, "job.json")
    assert "job key '%s'" % key in str(info.value) and says in str(info.value), info.value
