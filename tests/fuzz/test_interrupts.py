# SPDX-License-Identifier: LGPL-2.1-or-later
"""SIGTERM, SIGHUP and Ctrl-C while the outputs are being written: exit 143, 129 or 130,
nothing written, no temporary file, an output that existed before keeps its content.

The command runs in a subprocess whose :class:`surfcomp.io.atomic.Transaction` is held at
a fixed point (after the first output's writer has filled its temporary file, or inside
``commit`` after the first output was renamed into place), so the signal lands there
however loaded the machine is.
"""

import signal
import subprocess
import sys

import pytest

from tests.conftest import default_signals

from . import inputs as I
from .harness import EXAMPLE_STEP, check_tree, snapshot, subprocess_env

#: the CLI with the transaction held once at SURFCOMP_FUZZ_HOLD ('write' or 'commit')
HELD_CLI = r"""
import os, sys, time
import surfcomp.io.atomic as atomic
from surfcomp.cli import main

def hold():
    if not getattr(hold, "done", False):
        hold.done = True
        sys.stderr.write("HELD\n")
        sys.stderr.flush()
        time.sleep(120)

if os.environ["SURFCOMP_FUZZ_HOLD"] == "write":
    write = atomic.Transaction.write
    def held_write(self, path, writer, suffix=None):
        def fill(tmp):
            writer(tmp)
            hold()
        return write(self, path, fill, suffix)
    atomic.Transaction.write = held_write
else:
    class HeldOs:
        def __getattr__(self, name):
            return getattr(os, name)
        def replace(self, src, dst):
            os.replace(src, dst)
            hold()
    commit = atomic.Transaction.commit
    def held_commit(self):
        atomic.os = HeldOs()
        try:
            commit(self)
        finally:
            atomic.os = os
    atomic.Transaction.commit = held_commit
sys.exit(main(sys.argv[1:]))
"""

COMPENSATE = ("compensate", "nominal.step", "m.csv", "--quiet", "-o", "out/c.step", "--report",
              "out/r.json")
COMP_FILES = I.setup(I.copy("nominal.step", EXAMPLE_STEP), I.put("m.csv", I.csv))
GCODE = ("gcode", "in.ngc", "--axis-errors", "e.csv", "-o", "out.ngc", "--report", "new/r.json")
GCODE_FILES = I.setup(I.put("in.ngc", I.wave), I.put("e.csv", I.AXIS_CSV))

CASES = [
    ("compensate-writer", COMPENSATE + ("--html", "r.html"), COMP_FILES, "write", "SIGTERM"),
    ("compensate-writer", COMPENSATE, COMP_FILES, "write", "SIGHUP"),
    ("compensate-writer", COMPENSATE, COMP_FILES, "write", "SIGINT"),
    # the first output is renamed into place when the signal comes: it gets its old content
    ("compensate-commit-over-old-outputs", COMPENSATE[:4] + ("-o", "c.step", "--report",
                                                            "r.json"),
     I.setup(COMP_FILES, I.put("c.step", "old face"), I.put("r.json", "old report")),
     "commit", "SIGTERM"),
    ("gcode-writer", GCODE, GCODE_FILES, "write", "SIGTERM"),
    ("gcode-commit", GCODE, GCODE_FILES, "commit", "SIGHUP"),
    ("document-commit", ("compensate", "d.FCStd", "m.csv", "--object", "Nominal", "--replace",
                         "--save", "out/new.FCStd", "--quiet"),
     I.setup(I.put("d.FCStd", I.document_bytes), I.put("m.csv", I.csv)), "commit", "SIGTERM"),
    ("simulate-writer", ("simulate", "nominal.step", "--grid", "5x5", "--replicas", "1",
                         "--methods", "none,raw", "--json", "s.json", "--html", "s.html",
                         "--quiet"),
     I.copy("nominal.step", EXAMPLE_STEP), "write", "SIGINT"),
]
EXIT = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}


@pytest.mark.parametrize("name, argv, setup, where, signame", CASES,
                         ids=["%s-%s" % (c[0], c[4]) for c in CASES])
def test_signal_while_writing(tmp_path, name, argv, setup, where, signame):
    sandbox = tmp_path / "case"
    sandbox.mkdir()
    setup(str(sandbox))
    before = snapshot(sandbox)
    proc = subprocess.Popen([sys.executable, "-c", HELD_CLI] + list(argv),
                            cwd=str(sandbox), stderr=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True, env=subprocess_env({"SURFCOMP_FUZZ_HOLD": where}),
                            preexec_fn=default_signals)
    seen = []
    for line in proc.stderr:
        seen.append(line)
        if line.strip() == "HELD":
            proc.send_signal(getattr(signal, signame))
            break
    out, rest = proc.communicate(timeout=300)
    err = "".join(seen) + rest
    assert "HELD\n" in seen, err
    assert proc.returncode == EXIT[signame], err
    word = "interrupted" if signame == "SIGINT" else "terminated by signal %d" % (
        EXIT[signame] - 128)
    assert "surfcomp: %s; nothing was written" % word in rest, err
    assert "Traceback" not in err and "wrote" not in out
    check_tree(before, snapshot(sandbox))
