# SPDX-License-Identifier: LGPL-2.1-or-later
"""SIGTERM, SIGHUP and Ctrl-C while the outputs are being written: exit 143, 129 or 130,
nothing written, no temporary file, an output that existed before keeps its content; on the
command line and on the freecadcmd route alike (issues 12 and 25).

The command runs in a subprocess whose :class:`surfcomp.io.atomic.Transaction` is held at
a fixed point, so the signal lands there however loaded the machine is:

- ``write``: after the first output's writer has filled its temporary file: the command
  stops, nothing is written;
- ``commit``: inside ``commit`` after the first output was renamed into place, until the
  signal is pending: the commit holds signals back, completes, and the command exits 0
  naming the outputs (they are complete);
- ``after``: just after the commit: exit 0, the outputs named, never "nothing was written";
- ``cleanup``: a first signal while writing, a second one while the temporary files are
  removed: the second is ignored, nothing is left behind.

The children start with SIGINT, SIGTERM and SIGHUP at their defaults (:func:`harness.
default_signals`), also when the test runner has them ignored (``nohup``, a background job).
"""

import hashlib
import json
import os
import signal
import subprocess
import sys

import pytest

from . import inputs as I
from .harness import EXAMPLE_STEP, ROOT, check_tree, default_signals, snapshot, subprocess_env

#: holds the transaction once at SURFCOMP_FUZZ_HOLD (write, commit, after or cleanup)
HOLD = r"""
import os, signal, sys, time
import surfcomp.io.atomic as atomic

def hold(until_pending=False):
    if not getattr(hold, "done", False):
        hold.done = True
        sys.stderr.write("HELD\n")
        sys.stderr.flush()
        end = time.monotonic() + 120
        while time.monotonic() < end:
            if until_pending and atomic.signal_waiting():
                return
            time.sleep(0.01)

mode = os.environ["SURFCOMP_FUZZ_HOLD"]
if mode in ("write", "cleanup"):
    write = atomic.Transaction.write
    def held_write(self, path, writer, suffix=None):
        def fill(tmp):
            writer(tmp)
            hold()
        return write(self, path, fill, suffix)
    atomic.Transaction.write = held_write
if mode == "cleanup":
    leave = atomic.Transaction.__exit__
    def held_exit(self, *exc):
        sys.stderr.write("CLEANUP\n")
        sys.stderr.flush()
        time.sleep(1.0)
        return leave(self, *exc)
    atomic.Transaction.__exit__ = held_exit
if mode == "commit":
    class HeldOs:
        def __getattr__(self, name):
            return getattr(os, name)
        def replace(self, src, dst):
            os.replace(src, dst)
            if not os.path.basename(dst).startswith("."):
                hold(until_pending=True)
    commit = atomic.Transaction.commit
    def held_commit(self):
        atomic.os = HeldOs()
        try:
            commit(self)
        finally:
            atomic.os = os
    atomic.Transaction.commit = held_commit
if mode == "after":
    commit = atomic.Transaction.commit
    def held_commit(self):
        commit(self)
        hold()
    atomic.Transaction.commit = held_commit
"""
#: the command line with the transaction held
HELD_CLI = HOLD + r"""
from surfcomp.cli import main
sys.exit(main(sys.argv[1:]))
"""
#: the freecadcmd job macro with the transaction held (run by freecadcmd)
HELD_MACRO = "import sys\nsys.path.insert(0, %r)\n" % ROOT + HOLD + r"""
macro = os.path.join(%r, "macros", "surfcomp_job.py")
exec(compile(open(macro).read(), macro, "exec"), {"__file__": macro, "__name__": "__main__"})
""" % ROOT

COMPENSATE = ("compensate", "nominal.step", "m.csv", "--quiet", "-o", "out/c.step", "--report",
              "out/r.json")
COMP_FILES = I.setup(I.copy("nominal.step", EXAMPLE_STEP), I.put("m.csv", I.csv), I.folder("out"))
COMP_WRITES = ("out/c.step", "out/r.json")
GCODE = ("gcode", "in.ngc", "--axis-errors", "e.csv", "-o", "out.ngc", "--report", "new/r.json")
GCODE_FILES = I.setup(I.put("in.ngc", I.wave), I.put("e.csv", I.AXIS_CSV), I.folder("new"))
JOB = {"command": "compensate", "nominal": "nominal.step", "measurements": "m.csv",
       "output": "out/c.step", "report": "out/r.json"}
JOB_FILES = I.setup(COMP_FILES, I.put("job.json", json.dumps(JOB)))
OLD = I.setup(COMP_FILES, I.put("c.step", "old face"), I.put("r.json", "old report"))
OLD_HASHES = {hashlib.sha256(b).hexdigest() for b in (b"old face", b"old report")}

#: (name, argv (None: the freecadcmd job), setup, hold, signals, what is written at the end)
CASES = [
    ("compensate-writer", COMPENSATE + ("--html", "r.html"), COMP_FILES, "write", "SIGTERM", ()),
    ("compensate-writer", COMPENSATE, COMP_FILES, "write", "SIGHUP", ()),
    # outputs in a sub-folder: the staged files there go again, the folder stays
    ("compensate-writer-in-sub-folders", COMPENSATE[:4] + ("-o", "nd/a/c.step", "--report",
                                                          "nd/r.json"),
     I.setup(I.copy("nominal.step", EXAMPLE_STEP), I.put("m.csv", I.csv), I.folder("nd/a")),
     "write", "SIGTERM", ()),
    ("compensate-writer", COMPENSATE, COMP_FILES, "write", "SIGINT", ()),
    # the signal waits until the commit is complete: the outputs are there, exit 0
    ("compensate-commit-over-old-outputs", COMPENSATE[:4] + ("-o", "c.step", "--report",
                                                            "r.json"),
     OLD, "commit", "SIGTERM", ("c.step", "r.json")),
    ("compensate-after-commit", COMPENSATE, COMP_FILES, "after", "SIGINT", COMP_WRITES),
    ("compensate-after-commit", COMPENSATE, COMP_FILES, "after", "SIGTERM", COMP_WRITES),
    ("compensate-second-signal-in-cleanup", COMPENSATE, COMP_FILES, "cleanup",
     "SIGINT,SIGINT", ()),
    ("compensate-second-signal-in-cleanup", COMPENSATE, COMP_FILES, "cleanup",
     "SIGTERM,SIGTERM", ()),
    ("gcode-writer", GCODE, GCODE_FILES, "write", "SIGTERM", ()),
    ("gcode-commit", GCODE, GCODE_FILES, "commit", "SIGHUP", ("out.ngc", "new/r.json")),
    ("gcode-after-commit", GCODE, GCODE_FILES, "after", "SIGTERM", ("out.ngc", "new/r.json")),
    ("document-commit", ("compensate", "d.FCStd", "m.csv", "--object", "Nominal", "--replace",
                         "--save", "out/new.FCStd", "--quiet"),
     I.setup(I.put("d.FCStd", I.document_bytes), I.put("m.csv", I.csv), I.folder("out")),
     "commit", "SIGTERM", ("out/new.FCStd",)),
    ("simulate-writer", ("simulate", "nominal.step", "--grid", "5x5", "--replicas", "1",
                         "--methods", "none,raw", "--json", "s.json", "--html", "s.html",
                         "--quiet"),
     I.copy("nominal.step", EXAMPLE_STEP), "write", "SIGINT", ()),
    # the freecadcmd route handles signals like the command line
    ("freecadcmd-writer", None, JOB_FILES, "write", "SIGINT", ()),
    ("freecadcmd-writer", None, JOB_FILES, "write", "SIGTERM", ()),
    ("freecadcmd-second-signal-in-cleanup", None, JOB_FILES, "cleanup", "SIGINT,SIGTERM", ()),
    ("freecadcmd-commit", None, JOB_FILES, "commit", "SIGTERM", COMP_WRITES),
    ("freecadcmd-after-commit", None, JOB_FILES, "after", "SIGINT", COMP_WRITES),
]
EXIT = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}


def _start(argv, sandbox, hold):
    env = subprocess_env({"SURFCOMP_FUZZ_HOLD": hold})
    if argv is None:
        script = os.path.join(sandbox, ".held_macro.py")
        with open(script, "w") as fh:
            fh.write(HELD_MACRO)
        cmd = ["freecadcmd", script]
        env["SURFCOMP_JOB"] = os.path.join(sandbox, "job.json")
    else:
        cmd = [sys.executable, "-c", HELD_CLI] + list(argv)
    return subprocess.Popen(cmd, cwd=sandbox, stderr=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True, env=env, preexec_fn=default_signals)


def check_complete(before, after, writes):
    """``after`` is ``before`` with exactly ``writes`` new or replaced (no temporary file)."""
    changed = {k for k in before if after.get(k) != before[k]}
    new = set(after) - set(before)
    assert changed | new == set(writes), "changed %s, new %s, expected %s" % (
        sorted(changed), sorted(new), sorted(writes))
    for w in writes:
        assert after[w][0] == "file" and after[w][1] not in OLD_HASHES, w


@pytest.mark.parametrize("name, argv, setup, hold, signames, writes", CASES,
                         ids=["%s-%s" % (c[0], c[4].replace(",", "-")) for c in CASES])
def test_signal_while_writing(tmp_path, name, argv, setup, hold, signames, writes):
    sandbox = tmp_path / "case"
    sandbox.mkdir()
    setup(str(sandbox))
    before = snapshot(sandbox)
    signames = signames.split(",")
    proc = _start(argv, str(sandbox), hold)
    seen = []
    for line in proc.stderr:
        seen.append(line)
        if line.strip() == "HELD":
            proc.send_signal(getattr(signal, signames[0]))
            if len(signames) == 1:
                break
        if line.strip() == "CLEANUP":
            proc.send_signal(getattr(signal, signames[1]))
            break
    out, rest = proc.communicate(timeout=300)
    err = "".join(seen) + rest
    assert "HELD\n" in seen, err
    assert "Traceback" not in err, err
    after = snapshot(sandbox)
    after.pop(".held_macro.py", None)
    word = "interrupted" if signames[0] == "SIGINT" else "terminated by signal %d" % (
        EXIT[signames[0]] - 128)
    if writes:
        assert proc.returncode == 0, err
        assert "surfcomp: %s after the outputs were complete; written: " % word in rest, err
        assert "nothing was written" not in err
        check_complete(before, after, writes)
    else:
        assert proc.returncode == EXIT[signames[0]], err
        assert "surfcomp: %s; nothing was written" % word in rest, err
        assert "wrote" not in out
        check_tree(before, after)
