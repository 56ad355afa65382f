# SPDX-License-Identifier: LGPL-2.1-or-later
"""The entry points: ``python3 -m surfcomp`` under a Python without numpy or scipy, and the
``surfcomp`` command that tools/install.sh puts on PATH."""

import os
import shutil
import subprocess
import sys

import pytest

from tests.conftest import ROOT


def test_a_python_without_numpy_gets_one_line_and_exit_2():
    # -S: no site-packages, so this Python finds neither numpy nor scipy (as a pyenv or a
    # venv first on PATH would not)
    out = subprocess.run([sys.executable, "-S", "-m", "surfcomp", "compensate", "a.step",
                          "b.csv", "-o", "c.step"], cwd=ROOT, capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 2, out.stderr
    assert out.stdout == ""
    lines = out.stderr.splitlines()
    assert len(lines) == 1, out.stderr
    assert "has no numpy or scipy" in lines[0]
    assert "'/usr/bin/python3 -m surfcomp'" in lines[0] and "'surfcomp'" in lines[0]


@pytest.mark.skipif(shutil.which("surfcomp") is None, reason="tools/install.sh has not run")
def test_the_installed_command_runs_debians_python_from_any_folder(tmp_path):
    launcher = shutil.which("surfcomp")
    text = open(launcher).read()
    assert "exec /usr/bin/python3 -m surfcomp" in text
    # a PATH whose first python3 has no numpy, and a PYTHONPATH of the user's: kept behind
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "python3").write_text("#!/bin/sh\nexit 99\n")
    (fake / "python3").chmod(0o755)
    env = dict(os.environ, PATH="%s:%s" % (fake, os.environ["PATH"]), PYTHONPATH=str(tmp_path))
    out = subprocess.run([launcher, "--version"], cwd=str(tmp_path), capture_output=True,
                         text=True, timeout=60, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().startswith("surfcomp ")
    out = subprocess.run([launcher, "compensate", "missing.step", "m.csv", "-o", "c.step"],
                         cwd=str(tmp_path), capture_output=True, text=True, timeout=120, env=env)
    assert out.returncode == 2 and "missing.step" in out.stderr, out.stderr
    assert sorted(os.listdir(tmp_path)) == ["bin"]
