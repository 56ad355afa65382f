# SPDX-License-Identifier: LGPL-2.1-or-later
"""The CAD reader's child as a fork of the process (surfcomp/app/cadfork.py).

Each case runs in a fresh ``python3`` (a fork is taken only in a process with one thread,
and pytest's has numpy's): the shape read through the fork equals OCCT's own read in the
parent; a child that crashes, hangs, refuses the file or raises gives the reader's
messages, as the ``python3`` child's do (tests/fuzz/test_hostile_files.py); a process with
a second thread starts a fresh ``python3`` instead; and the ``compensate -o`` route on the
example starts no second Python and leaves scipy.interpolate unloaded.
"""

import json
import os
import subprocess
import sys

import pytest

from tests.conftest import ROOT

EXAMPLE = os.path.join(ROOT, "examples", "nominal.step")
MEAS = os.path.join(ROOT, "examples", "measurements.csv")

SCRIPT = r"""
import json, os, signal, sys, threading, time
sys.path.insert(0, sys.argv[1])
from surfcomp.app import cadfork, cadread
from surfcomp.errors import GeometryError
case, path = sys.argv[2], sys.argv[3]
spawned = []
real_popen = cadread.subprocess.Popen
def popen(*args, **kw):
    spawned.append(args[0])
    return real_popen(*args, **kw)
cadread.subprocess.Popen = popen
if case == "thread":
    threading.Thread(target=time.sleep, args=(3,), daemon=True).start()
elif case == "crash":
    cadread._read_to_brep = lambda src, dst: os.kill(os.getpid(), signal.SIGSEGV)
elif case == "hang":
    cadread.TIMEOUT = 1.0
    cadread._read_to_brep = lambda src, dst: time.sleep(30)
elif case == "refuse":
    def refuse(src, dst):
        print("cannot read the CAD file: no STEP here", file=sys.stderr)
        return cadread._REFUSED
    cadread._read_to_brep = refuse
    sys.stderr = open(os.devnull, "w")       # a caller's own stderr object
elif case == "raise":
    def boom(src, dst):
        raise ValueError("a bad day")
    cadread._read_to_brep = boom
out = {"usable": cadfork.usable()}
sys.stdout.write("unflushed ")               # written once, not again by the child
started = time.monotonic()
try:
    shape = cadread.read_cad(path)
    import Part
    ref = Part.read(path)
    box = lambda s: [getattr(s.BoundBox, k) for k in ("XMin", "XMax", "YMin", "YMax",
                                                      "ZMin", "ZMax")]
    out.update(faces=len(shape.Faces), area=shape.Area, ref_area=ref.Area, box=box(shape),
               ref_box=box(ref))
except GeometryError as exc:
    out["error"] = str(exc)
out.update(seconds=time.monotonic() - started, spawned=len(spawned),
           left=sorted(n for n in os.listdir(os.environ.get("TMPDIR", "/tmp"))
                       if n.startswith("surfcomp-read-")))
print("\n" + json.dumps(out))
"""


def run(case, path, tmp_path):
    env = dict(os.environ, TMPDIR=str(tmp_path))
    res = subprocess.run([sys.executable, "-c", SCRIPT, ROOT, case, path], capture_output=True,
                         text=True, timeout=300, env=env, cwd=str(tmp_path))
    assert res.returncode == 0, res.stderr
    first, last = res.stdout.rstrip("\n").rsplit("\n", 1)
    assert first == "unflushed ", res.stdout
    return json.loads(last)


def test_the_fork_reads_what_occt_reads(tmp_path):
    got = run("read", EXAMPLE, tmp_path)
    assert got["usable"] is True and got["spawned"] == 0
    assert got["faces"] == 1
    assert got["area"] == pytest.approx(got["ref_area"], rel=1e-12)
    assert got["box"] == pytest.approx(got["ref_box"], abs=1e-9)
    assert got["left"] == []


def test_a_second_thread_starts_a_fresh_python(tmp_path):
    got = run("thread", EXAMPLE, tmp_path)
    assert got["usable"] is False and got["spawned"] == 1
    assert got["faces"] == 1 and got["area"] == pytest.approx(got["ref_area"], rel=1e-12)


@pytest.mark.parametrize("case, says", [
    ("crash", "could not read NOMINAL: the file is damaged (OpenCASCADE crashed while "
              "reading it)"),
    ("hang", "could not read NOMINAL: OpenCASCADE took more than 1 s"),
    ("refuse", "cannot read the CAD file: no STEP here"),
    ("raise", "could not read NOMINAL: the reader failed (ValueError: a bad day)"),
])
def test_a_forked_child_that_fails(case, says, tmp_path):
    got = run(case, EXAMPLE, tmp_path)
    assert got["usable"] is True and got["spawned"] == 0
    assert says in got["error"]
    assert got["left"] == []                  # the child's folder is removed
    if case == "hang":
        assert 0.9 < got["seconds"] < 20      # killed at the limit, not after its 30 s


def test_a_damaged_step_file(tmp_path):
    """OCCT's own refusal of a file that is not STEP comes through the fork."""
    bad = tmp_path / "bad.step"
    bad.write_text("ISO-10303-21;\nthis is not a STEP file\n")
    got = run("read", str(bad), tmp_path)
    assert got["spawned"] == 0
    assert "error" in got and "surfcomp-read-" not in got["error"]
    assert "cannot read the CAD file" in got["error"] or "contains no faces" in got["error"]


CLI = r"""
import json, runpy, subprocess, sys
sys.path.insert(0, sys.argv[1])
spawned = []
real_popen = subprocess.Popen
class Popen(real_popen):
    def __init__(self, args, *a, **kw):
        spawned.append(args)
        super().__init__(args, *a, **kw)
subprocess.Popen = Popen
sys.argv = ["surfcomp"] + sys.argv[2:]
try:
    runpy.run_module("surfcomp", run_name="__main__", alter_sys=True)
    code = 0
except SystemExit as exc:
    code = exc.code
print(json.dumps({"code": code, "spawned": len(spawned),
                  "unused": sorted(m for m in ("scipy.interpolate", "scipy.optimize")
                                   if m in sys.modules)}), file=sys.__stderr__)
"""


def test_the_file_route_starts_no_second_python(tmp_path):
    """``compensate -o`` on the example starts no other program: the reader is a fork (and
    the C library's ``malloc_trim`` is found without running ldconfig); the modules the
    route does not use (scipy.interpolate, scipy.optimize) are not imported."""
    out = tmp_path / "out.step"
    res = subprocess.run([sys.executable, "-c", CLI, ROOT, "compensate", EXAMPLE, MEAS, "-o",
                          str(out), "--quiet"], capture_output=True, text=True, timeout=300,
                         cwd=str(tmp_path))
    got = json.loads(res.stderr.strip().splitlines()[-1])
    assert got == {"code": 0, "spawned": 0, "unused": []}, res.stderr
    assert out.stat().st_size > 100000
    assert "wrote %s" % out in res.stdout
