# SPDX-License-Identifier: LGPL-2.1-or-later
"""The entry points: ``python3 -m surfcomp`` under a Python without numpy or scipy, and the
``surfcomp`` command that tools/install.sh puts on PATH."""

import os
import re
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


def _launcher():
    """The ``surfcomp`` command on PATH and its text; skips unless this checkout's
    tools/install.sh wrote it (a command installed from another checkout runs that one)."""
    launcher = shutil.which("surfcomp")
    if launcher is None:
        pytest.skip("tools/install.sh has not run")
    text = open(launcher).read()
    written = re.search(r"written by (.*)/tools/install\.sh", text)
    assert written, text
    if os.path.realpath(written.group(1)) != os.path.realpath(ROOT):
        pytest.skip("the surfcomp command runs another checkout (%s); run tools/install.sh "
                    "here" % written.group(1))
    return launcher, text


def test_the_installed_command_runs_debians_python_from_any_folder(tmp_path):
    launcher, text = _launcher()
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


def test_the_installed_command_says_when_its_checkout_is_gone(tmp_path):
    """The command names the checkout it runs; once that is deleted it says so and what to
    run (exit 2, one line), not Python's "No module named surfcomp"."""
    _launcher_path, text = _launcher()
    gone = str(tmp_path / "deleted-checkout")
    moved = tmp_path / "surfcomp"
    moved.write_text(text.replace(os.path.realpath(ROOT), gone).replace(ROOT, gone))
    moved.chmod(0o755)
    out = subprocess.run([str(moved), "--version"], cwd=str(tmp_path), capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.splitlines() == [
        "surfcomp: the checkout this command runs, %s, is gone; run tools/install.sh in a "
        "checkout of surfcomp" % gone]
