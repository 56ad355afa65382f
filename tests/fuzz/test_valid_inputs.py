# SPDX-License-Identifier: LGPL-2.1-or-later
"""Valid inputs that were refused (issue 25, item 8): a UTF-8 byte-order mark at the start
of any text input, and a measurement file that can be read only once (``/dev/stdin``, a
FIFO, a pipe's ``/dev/fd/N``), which the format detection and the reader used to read
twice ("the file is empty")."""

import os
import signal
import subprocess
import sys
import threading

import pytest

from . import inputs as I
from .harness import EXAMPLE_STEP, Case, run_case, subprocess_env

BOM = b"\xef\xbb\xbf"
ERR = I.put("e.csv", I.AXIS_CSV)


def _bom(text):
    return BOM + text.encode("utf-8")


@pytest.mark.parametrize("name, text", [
    ("small", I.SMALL_PROGRAM),
    ("crlf-percent", "%\r\n" + I.SMALL_PROGRAM.replace("\n", "\r\n") + "%\r\n"),
    ("comment-first", "(bom then a comment)\nG21 G90 G0 X1 Y2 Z3\nG1 X40 Y3 F300\nM2\n"),
])
def test_gcode_with_a_byte_order_mark(name, text, tmp_path):
    """The program with a mark gives the program without it, the mark kept in front."""
    for sub, data in (("plain", text.encode("utf-8")), ("bom", _bom(text))):
        run_case(Case(sub, ("gcode", "in.ngc", "--axis-errors", "e.csv", "-o", "out.ngc"),
                      I.setup(ERR, I.put("in.ngc", data)), rc=0, writes=("out.ngc",)),
                 tmp_path / sub)
    plain = (tmp_path / "plain" / "out.ngc").read_bytes()
    marked = (tmp_path / "bom" / "out.ngc").read_bytes()
    assert plain != text.encode("utf-8")          # the errors moved points
    assert marked == BOM + plain


def test_gcode_with_a_byte_order_mark_under_a_zero_model():
    """No error: the output is the input, byte for byte, mark included."""
    from surfcomp.core.axis.axis_errors import AxisErrorModel
    from surfcomp.io.gcode import compensate_gcode

    for text in (I.SMALL_PROGRAM, I.SMALL_PROGRAM.replace("\n", "\r\n")):
        data = _bom(text)
        assert compensate_gcode(data, AxisErrorModel.zero()).data == data


@pytest.mark.parametrize("what", ["table", "xyz", "axis-errors"])
def test_other_text_inputs_with_a_byte_order_mark(what, tmp_path):
    if what == "axis-errors":
        case = Case(what, ("gcode", "in.ngc", "--axis-errors", "e.csv", "-o", "out.ngc"),
                    I.setup(I.put("in.ngc", I.SMALL_PROGRAM), I.put("e.csv", _bom(I.AXIS_CSV))),
                    rc=0, writes=("out.ngc",))
    else:
        table = I.csv() if what == "table" else "\n".join(
            " ".join(r[1:4]) for r in I.rows()) + "\n"
        case = Case(what, ("inspect", "n.step", "m.txt", "--report", "r.json", "--quiet"),
                    I.setup(I.copy("n.step", EXAMPLE_STEP), I.put("m.txt", _bom(table))),
                    rc=0, writes=("r.json",))
    run_case(case, tmp_path)


def _reset_signals():
    for sig in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)


def _inspect(meas, cwd, **kw):
    return subprocess.run([sys.executable, "-m", "surfcomp", "inspect", EXAMPLE_STEP, meas,
                           "--quiet"], cwd=str(cwd), env=subprocess_env(), capture_output=True,
                          timeout=300, restore_signals=True, preexec_fn=_reset_signals, **kw)


def _feed(path, data):
    def run():
        with open(path, "wb") as fh:
            fh.write(data)
    t = threading.Thread(target=run, daemon=True)
    t.start()
    return t


@pytest.mark.parametrize("how", ["dev-stdin", "fifo", "dev-fd"])
def test_measurements_that_can_be_read_once(how, tmp_path):
    """The measurements through ``/dev/stdin``, a FIFO and a pipe's ``/dev/fd/N``: the same
    table as from the regular file."""
    data = I.csv().encode("utf-8")
    (tmp_path / "m.csv").write_bytes(data)
    ref = _inspect(str(tmp_path / "m.csv"), tmp_path)
    assert ref.returncode == 0, ref.stderr
    if how == "dev-stdin":
        with open(tmp_path / "m.csv", "rb") as fh:      # stdin a pipe, not the file
            out = _inspect("/dev/stdin", tmp_path, input=fh.read())
    elif how == "fifo":
        fifo = tmp_path / "m.fifo"
        os.mkfifo(fifo)
        writer = _feed(fifo, data)
        out = _inspect(str(fifo), tmp_path)
        writer.join(10)
    else:
        r, w = os.pipe()
        writer = _feed(w, data)
        out = _inspect("/dev/fd/%d" % r, tmp_path, pass_fds=(r,))
        writer.join(10)
        os.close(r)
    assert out.returncode == 0, out.stderr
    table = [t for t in out.stdout.decode().splitlines() if "Standard deviation" in t]
    assert table and table == [t for t in ref.stdout.decode().splitlines()
                               if "Standard deviation" in t]


def test_table_with_many_extra_columns(tmp_path):
    """30 000 unknown columns: ten named warnings and one that counts the rest; the report
    names the first 100 and counts them all (a million columns gave a million warning lines
    and a 100 MB report)."""
    extra = 30_000
    header = I.HEADER + "," + ",".join("extra%d" % k for k in range(extra))
    body = "".join(",".join(r) + ",0" * extra + "\n" for r in I.rows(9))
    res = run_case(Case("wide", ("inspect", "n.step", "m.csv", "--report", "r.json", "--quiet",
                                 "--layout", "scattered"),
                        I.setup(I.copy("n.step", EXAMPLE_STEP),
                                I.put("m.csv", header + "\n" + body)),
                        rc=0, writes=("r.json",)), tmp_path)
    warnings = [t for t in res.err.splitlines() if t.startswith("warning: m.csv:1:")]
    assert len(warnings) == 11
    assert warnings[9].endswith("column 18 'extra9' is ignored (not a known column name)")
    assert warnings[10].endswith("%d more columns are ignored (columns 19 to %d: not known "
                                 "column names)" % (extra - 10, extra + 8))
    import json

    rep = json.loads((tmp_path / "r.json").read_text(encoding="utf-8"))
    info = rep["inputs"]["measurements"]
    assert info["ignored_column_count"] == extra and len(info["ignored_columns"]) == 100
    assert (tmp_path / "r.json").stat().st_size < 200_000
