# SPDX-License-Identifier: LGPL-2.1-or-later
"""``python3 -m surfcomp compensate|inspect`` gives numpy's BLAS one thread when the user
set none (its worker thread only spun beside those commands' small linear algebra), and
leaves every thread variable the user set, the other commands, and a process that only
runs the module (``runpy``), alone.

The process's environment is read at its exit by a ``sitecustomize`` module put first on
``PYTHONPATH`` (what the command itself saw, not what the test passed)."""

import json
import os
import subprocess
import sys

import pytest

from surfcomp.__main__ import BLAS_THREAD_VARIABLES, one_blas_thread
from tests.conftest import ROOT

SITE = r"""
import atexit, json, os, sys
NAMES = %r
def _report():
    seen = {name: os.environ.get(name) for name in NAMES}
    seen["numpy"] = "numpy" in sys.modules
    sys.__stderr__.write("ENV " + json.dumps(seen) + "\n")
atexit.register(_report)
""" % (BLAS_THREAD_VARIABLES,)


def run(tmp_path, env, argv):
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    (site / "sitecustomize.py").write_text(SITE)
    base = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    base.update(env, PYTHONPATH=os.pathsep.join([str(site), ROOT]))
    out = subprocess.run([sys.executable] + argv, capture_output=True, text=True,
                         timeout=120, cwd=ROOT, env=base)
    lines = [x for x in out.stderr.splitlines() if x.startswith("ENV ")]
    assert lines, out.stderr
    return out, json.loads(lines[-1][4:])


@pytest.mark.parametrize("command", ["compensate", "inspect"])
def test_unset_gets_one_thread(tmp_path, command):
    out, seen = run(tmp_path, {}, ["-m", "surfcomp", command, "--help"])
    assert out.returncode == 0, out.stderr
    assert seen == {"OPENBLAS_NUM_THREADS": "1", "GOTO_NUM_THREADS": None,
                    "OMP_NUM_THREADS": None, "numpy": False}


@pytest.mark.parametrize("argv", [["--version"], ["simulate", "--help"], ["gcode", "--help"]])
def test_other_commands_keep_the_default(tmp_path, argv):
    out, seen = run(tmp_path, {}, ["-m", "surfcomp"] + argv)
    assert out.returncode == 0, out.stderr
    assert {k: seen[k] for k in BLAS_THREAD_VARIABLES} == dict.fromkeys(BLAS_THREAD_VARIABLES)


@pytest.mark.parametrize("name, value", [("OPENBLAS_NUM_THREADS", "2"),
                                         ("OPENBLAS_NUM_THREADS", ""),
                                         ("GOTO_NUM_THREADS", "3"),
                                         ("OMP_NUM_THREADS", "4")])
def test_a_users_setting_is_kept(tmp_path, name, value):
    out, seen = run(tmp_path, {name: value}, ["-m", "surfcomp", "compensate", "--help"])
    assert out.returncode == 0, out.stderr
    expected = dict.fromkeys(BLAS_THREAD_VARIABLES)
    expected[name] = value
    assert {k: seen[k] for k in BLAS_THREAD_VARIABLES} == expected


def test_a_process_that_only_runs_the_module_is_left_alone(tmp_path):
    """``runpy`` in another program's process (which goes on afterwards): no change."""
    code = ("import runpy, sys\nsys.argv = ['surfcomp', 'compensate', '--help']\n"
            "try:\n    runpy.run_module('surfcomp', run_name='__main__', alter_sys=True)\n"
            "except SystemExit:\n    pass\n")
    out, seen = run(tmp_path, {}, ["-c", code])
    assert out.returncode == 0, out.stderr
    assert {k: seen[k] for k in BLAS_THREAD_VARIABLES} == dict.fromkeys(BLAS_THREAD_VARIABLES)


def test_the_rule_on_a_mapping():
    env = {}
    assert one_blas_thread(env, ["simulate", "--preset", "werner2022"]) is False and env == {}
    assert one_blas_thread(env, []) is False and env == {}
    assert one_blas_thread(env, ["compensate", "n.step", "m.csv"]) is True
    assert env == {"OPENBLAS_NUM_THREADS": "1"}
    assert one_blas_thread(env, ["inspect"]) is False and env == {"OPENBLAS_NUM_THREADS": "1"}
    env = {"OMP_NUM_THREADS": "8", "PATH": "/usr/bin"}
    assert one_blas_thread(env, ["compensate"]) is False
    assert env == {"OMP_NUM_THREADS": "8", "PATH": "/usr/bin"}
