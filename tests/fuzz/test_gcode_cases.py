# SPDX-License-Identifier: LGPL-2.1-or-later
"""``gcode IN.ngc --axis-errors E.csv -o OUT.ngc`` on bad input (no FreeCAD needed)."""

import pytest

from . import inputs as I
from .harness import Case, run_case

PROG = I.put("in.ngc", I.SMALL_PROGRAM)
ERR = I.put("e.csv", I.AXIS_CSV)
BASE = I.setup(PROG, ERR)


def gc(name, *extra, setup=BASE, program="in.ngc", errors="e.csv", out=("-o", "out.ngc"),
       **kw):
    return Case(name, ("gcode", program, "--axis-errors", errors) + tuple(out) + tuple(extra),
                setup=setup, **kw)


def prog(name, text, line=None, says=(), **kw):
    """``text`` as the program (refused at ``line`` unless rc=0)."""
    return gc(name, setup=I.setup(ERR, I.put("in.ngc", text)),
              file=None if kw.get("rc") == 0 else "in.ngc", line=line, says=says, **kw)


def errors(name, text, line=None, says=(), **kw):
    return gc(name, setup=I.setup(PROG, I.put("e.csv", text)), file="e.csv", line=line,
              says=says, **kw)


LINKED = I.setup(I.folder("v"), I.put("v/in.ngc", I.SMALL_PROGRAM), I.put("v/e.csv", I.AXIS_CSV),
                 I.link("vlink", "v"))

OVERWRITE = [
    gc("o-is-the-program", out=("-o", "in.ngc"), file="in.ngc",
       says=("-o would overwrite the input IN.ngc",)),
    gc("o-is-the-axis-errors", out=("-o", "e.csv"), file="e.csv",
       says=("-o would overwrite the input --axis-errors",)),
    gc("o-through-symlinked-folder-onto-the-program", setup=LINKED, program="v/in.ngc",
       errors="v/e.csv", out=("-o", "vlink/in.ngc"), file="vlink/in.ngc",
       says=("would overwrite the input IN.ngc", "through a link")),
    gc("o-hard-link-of-the-program", setup=I.setup(BASE, I.hardlink("h.ngc", "in.ngc")),
       out=("-o", "h.ngc"), file="h.ngc", says=("would overwrite the input IN.ngc",)),
    gc("report-symlink-to-the-axis-errors", "--report", "r.json",
       setup=I.setup(BASE, I.link("r.json", "e.csv")), file="r.json",
       says=("--report would overwrite the input --axis-errors",)),
]

CLOBBER = [
    gc("report-equals-o", "--report", "out.ngc", file="out.ngc",
       says=("-o and --report name the same file",)),
    gc("report-hard-link-of-o", "--report", "r.json",
       setup=I.setup(BASE, I.put("out.ngc", "old"), I.hardlink("r.json", "out.ngc")),
       file="r.json", says=("-o and --report name the same file",)),
]

ALL_OR_NOTHING = [
    gc("report-is-an-existing-folder", "--report", "rdir", setup=I.setup(BASE, I.folder("rdir")),
       file="rdir", says=("--report is a folder",)),
    gc("o-in-proc", out=("-o", "/proc/out.ngc"), file="/proc/out.ngc"),
    gc("o-under-a-file", out=("-o", "e.csv/out.ngc"), file="e.csv/out.ngc"),
    # a folder that does not exist is an error before any work, as for open()
    gc("report-in-a-folder-that-does-not-exist", "--report", "new/b/r.json",
       out=("-o", "out.ngc"), file="new/b/r.json", says=("cannot be written: its folder",)),
]

OPTIONS = [gc("%s=%s" % (o.lstrip("-"), v), "%s=%s" % (o, v), says=(o,)) for o, v in (
    ("--segment-length", "1e-9"), ("--segment-length", "0"), ("--segment-length", "nan"),
    ("--segment-length", "-inf"), ("--tolerance", "0"), ("--tolerance", "nan"),
    ("--arc-tolerance", "-1"), ("--arc-tolerance", "inf"), ("--max-error", "nan"),
    ("--max-error", "-1"), ("--max-error", "0"), ("--decimals", "-1"), ("--decimals", "10"),
    ("--reference", "nan,0,0"), ("--reference", "1,2"), ("--reference", "a,b,c"),
    ("--work-offset", "inf,0,0"), ("--start", "1e999,0,0"), ("--reference", "1e300,0,0"),
    ("--work-offset", "0,1e300,0"), ("--start", "1e7,0,0"))]
OPTIONS += [
    gc("segment-length-1um-on-a-1km-move", "--segment-length", "0.001",
       setup=I.setup(ERR, I.put("in.ngc", "G21 G90\nG0 X0 Y0 Z0\nG1 X999999 F100\nM2\n")),
       file="in.ngc", says=("--segment-length 0.001 mm", "more than the 10000000")),
    gc("arc-of-a-million-turns", setup=I.setup(ERR, I.put(
        "in.ngc", "G21 G90 G17\nG0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 P1000000\nM2\n")),
       file="in.ngc", says=("more than the 10000000",)),
    gc("smallest-segment-length", "--segment-length", "0.001", rc=0, writes=("out.ngc",)),
    gc("decimals-9-and-max-error-1e3", "--decimals", "9", "--max-error", "1000", rc=0,
       writes=("out.ngc",)),
]

AXIS_VALUES = [
    errors("axis-error-1e308", I.AXIS_CSV.replace("X,100,0.01", "X,100,1e308"), 3,
           ("larger than --max-error 1 mm",)),
    errors("axis-error-5000mm", I.AXIS_CSV.replace("X,100,0.01", "X,100,5000"), 3,
           ("5000 mm is larger than --max-error 1 mm",)),
    errors("axis-error-1e999", I.AXIS_CSV.replace("X,100,0.01", "X,100,1e999"), 3,
           ("out of range",)),
    errors("axis-error-nan", I.AXIS_CSV.replace("X,100,0.01", "X,100,nan"), 3),
    errors("axis-error-text", I.AXIS_CSV.replace("X,100,0.01", "X,100,abc"), 3, ("abc",)),
    errors("axis-error-huge-field", I.AXIS_CSV.replace("X,100,0.01", "X,100," + "7" * 400 + "x"),
           3, ("(401 characters)",)),
    errors("axis-position-inf", I.AXIS_CSV.replace("X,100,", "X,inf,"), 3),
    errors("axis-errors-wrong-count", I.AXIS_CSV.replace("X,100,0.01,0.002,0", "X,100,0.01"), 3),
    errors("axis-errors-empty", ""),
    errors("axis-errors-header-only", "axis,position,ex,ey,ez\n"),
    errors("axis-errors-binary", bytes(range(256)) * 16),
    errors("axis-errors-utf-16", I.AXIS_CSV.encode("utf-16")),
    errors("axis-errors-duplicate-columns", I.AXIS_CSV.replace("ex,ey,ez", "ex,ex,ez"), 1),
    errors("axis-errors-one-position", "axis,position,ex,ey,ez\nX,0,0,0,0\n"),
    errors("axis-errors-same-position-twice",
           "axis,position,ex,ey,ez\nX,5,0,0,0\nX,5,0.001,0,0\n"),
    errors("axis-errors-unknown-axis", I.AXIS_CSV.replace("Y,0,", "Q,0,"), 4),
    gc("axis-error-1e300-allowed-by-max-error", "--max-error", "1e308", setup=I.setup(PROG, I.put(
        "e.csv", "X EXX EYX EZX\n0 1e300 0 0\n1 0 0 0\n")), file="e.csv",
       says=("beyond 1e+06 mm",)),
    errors("axis-position-1e300", "axis,position,ex,ey,ez\nX,0,0,0,0\nX,1e300,0,0,0\n", 3,
           ("position",)),
    gc("axis-positions-1e300-with-report", "--report", "r.json", setup=I.setup(PROG, I.put(
        "e.csv", "axis,position,ex,ey,ez\nX,0,0,0,0\nX,5e299,0.001,0,0\nX,1e300,0.002,0,0\n"
        "X,2e300,0.001,0,0\nX,3e300,0,0,0\n")), file="e.csv", line=3, says=("position",)),
    errors("axis-table-position-1e300", "X EXX EYX EZX\n0 0 0 0\n1e300 0.001 0 0\n", 3,
           ("X",)),
    gc("axis-errors-missing", errors="gone.csv", file="gone.csv"),
]

MALFORMED = [
    prog("empty-program", "", says=("the program is empty",)),
    prog("comments-only", "(nothing)\n; here\n%\n", says=("the program is empty",)),
    prog("binary-garbage", bytes(range(256)) * 16, 1),
    prog("utf-16", I.SMALL_PROGRAM.encode("utf-16"), 1),
    prog("canned-cycle", "G21 G90\nG0 X0 Y0 Z5\nG81 X1 Y1 Z-1 R1 F100\nM2\n", 3, ("G81",)),
    prog("huge-number", "G21 G90\nG0 X0 Y0 Z0\nG1 X%s F100\nM2\n" % ("9" * 400), 3,
         ("out of range",)),
    prog("beyond-one-km", "G21 G90\nG0 X0 Y0 Z0\nG1 X1000001 F100\nM2\n", 3),
    prog("huge-malformed-number", "G21 G90\nG0 X0 Y0 Z0\nG1 X" + "1" * (1 << 20) + ".5.5\nM2\n",
         3, ("malformed number",)),
    prog("huge-position-text", "G21 G90\nG0 X0 Y0 Z0\nG1 X1000001." + "0" * (1 << 20)
         + " F100\nM2\n", 3, ("beyond any machine's travel",)),
    prog("huge-o-word", "G21 G90\nO" + "1" * (1 << 20) + " sub\nM2\n", 2, ("O word",)),
    prog("exponent-is-not-g-code", "G21 G90\nG0 X0 Y0 Z0\nG1 X1e400 F100\nM2\n", 3),
    prog("nan-word", "G21 G90\nG0 X0 Y0 Z0\nG1 XNaN F100\nM2\n", 3, ("without a number",)),
    prog("inf-word", "G21 G90\nG0 X0 Y0 Z0\nG1 X-inf F100\nM2\n", 3),
    prog("unclosed-comment", "G21 G90\nG0 X0 Y0 Z0 (open\nM2\n", 2, ("not closed",)),
    prog("comment-closed-only", "G21 G90\nG0 X0 Y0 Z0 close)\nM2\n", 2),
    prog("nested-comment", "G21 G90\n(a (b) c)\nM2\n", 2, ("nested",)),
    prog("parameter", "G21 G90\n#1=5\nG0 X#1\nM2\n", 2, ("parameter",)),
    prog("o-word", "G21 G90\nO100 sub\nM2\n", 2, ("O word",)),
    prog("m98", "G21 G90\nM98 P100\nM2\n", 2, ("M98",)),
    prog("cutter-compensation", "G21 G90\nG0 X0 Y0 Z0\nG41 D1\nG1 X5 F100\nM2\n", 3),
    prog("g92", "G21 G90\nG0 X0 Y0 Z0\nG92 X5\nM2\n", 3),
    prog("fourth-axis", "G21 G90\nG0 X0 Y0 Z0 A90\nM2\n", 2),
    prog("arc-end-off-the-circle", "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X10 Y0 I3 J0 F100\nM2\n", 3),
    prog("arc-of-radius-zero", "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X0 Y0 I0 J0 F100\nM2\n", 3),
    prog("arc-r-tiny", "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X1 Y0 R1e-300 F100\nM2\n", 3),
    prog("incremental-unknown-position", "G21 G91\nG1 X1 F100\nM2\n", 2),
    prog("huge-comment-line", "G21 G90\nG0 X0 Y0 Z0\n(" + "x" * (8 << 20) + ")\nG1 X5 F100\nM2\n",
         rc=0, writes=("out.ngc",)),
    prog("cr-only-line-ends", I.SMALL_PROGRAM.replace("\n", "\r")),
    prog("nul-in-a-line", "G21 G90\nG0 X0\0 Y0 Z0\nM2\n", 2),
    gc("program-missing", program="gone.ngc", file="gone.ngc"),
    gc("program-is-a-folder", setup=I.setup(ERR, I.folder("p.ngc")), program="p.ngc",
       file="p.ngc"),
    gc("wave-gcode", setup=I.setup(ERR, I.put("in.ngc", I.wave)), rc=0, writes=("out.ngc",)),
]

CASES = OVERWRITE + CLOBBER + ALL_OR_NOTHING + OPTIONS + AXIS_VALUES + MALFORMED


@pytest.mark.parametrize("case", CASES, ids=str)
def test_case(case, tmp_path):
    run_case(case, tmp_path / "case")
