# SPDX-License-Identifier: LGPL-2.1-or-later
"""The command line's parser imports no numerics: ``--help``, a missing or unknown command
and argument errors of ``compensate`` and ``inspect`` answer without numpy, scipy or
FreeCAD (each costs a tenth of a second or more before the first line is printed)."""

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT

#: runs ``python3 -m surfcomp ARGS`` in this process and prints the exit code and which
#: heavy packages it imported
HARNESS = r"""
import json, runpy, sys
sys.path.insert(0, sys.argv[1])
sys.argv = ["surfcomp"] + json.loads(sys.argv[2])
try:
    runpy.run_module("surfcomp", run_name="__main__", alter_sys=True)
    code = 0
except SystemExit as exc:
    code = exc.code
heavy = sorted(m for m in ("numpy", "scipy", "FreeCAD", "Part") if m in sys.modules)
print(json.dumps({"code": code, "heavy": heavy}), file=sys.__stderr__)
"""

HEAVY = ("numpy", "scipy", "FreeCAD", "Part")


def run(args):
    out = subprocess.run([sys.executable, "-c", HARNESS, ROOT, json.dumps(args)],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    return out, json.loads(out.stderr.strip().splitlines()[-1])


@pytest.mark.parametrize("args, code", [
    ([], 2),
    (["--help"], 0),
    (["--version"], 0),
    (["bogus"], 2),
    (["compensate", "--help"], 0),
    (["inspect", "--help"], 0),
    (["compensate"], 2),
    (["compensate", "n.step", "m.csv", "--mask", "five"], 2),
    (["compensate", "n.step", "m.csv", "--method", "magic"], 2),
    (["inspect", "n.step", "m.csv", "--format", "dxf"], 2),
])
def test_the_parser_imports_no_numerics(args, code):
    out, got = run(args)
    assert got["code"] == code, out.stderr
    assert got["heavy"] == [], "%s imported %s" % (" ".join(args) or "(no arguments)",
                                                   ", ".join(got["heavy"]))


def test_the_harness_sees_an_import():
    """The check can fail: ``simulate``'s parser lists the presets of a numeric module."""
    out, got = run(["simulate", "--help"])
    assert got["code"] == 0, out.stderr
    assert "numpy" in got["heavy"]


def test_the_short_list_is_the_full_parsers():
    """``--help`` without the command modules lists what the full parser lists."""
    from surfcomp.cli import build_parser

    assert build_parser(False).format_help() == build_parser(None).format_help()
