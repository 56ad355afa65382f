# SPDX-License-Identifier: LGPL-2.1-or-later
"""Files that attack the process: a CAD reader that crashes or hangs, documents naming
modules that must not be imported (a module in the working directory, the standard
library's ``this``).

The module cases run ``python3 -m surfcomp`` in a subprocess with the sandbox as working
directory, which ``python3 -m`` puts on ``sys.path`` (a user's situation), and with a fresh
interpreter in which ``this`` has not been imported yet.
"""

import os
import stat

import pytest

from . import inputs as I
from .harness import EXAMPLE_STEP, ZEN, Case, run_case, run_subprocess

NOM = I.copy("nominal.step", EXAMPLE_STEP)
MEAS = I.put("m.csv", I.csv)


def _child(tmp_path, body):
    """An executable that stands in for the CAD reader's Python child."""
    path = tmp_path / "child.sh"
    path.write_text("#!/bin/sh\n" + body + "\n")
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(path)


@pytest.mark.parametrize("body, says", [
    ("kill -SEGV $$", "could not read NOMINAL: the file is damaged (OpenCASCADE crashed while "
                      "reading it)"),
    ("kill -ABRT $$", "the file is damaged (OpenCASCADE crashed while reading it)"),
    ("echo 'cannot read the CAD file: no STEP' >&2; exit 3", "cannot read the CAD file: no STEP"),
    ("exec sleep 30", "OpenCASCADE took more than 1 s"),
], ids=["killed-by-SIGSEGV", "killed-by-SIGABRT", "refused", "hangs"])
def test_cad_reader_child_that_crashes_or_hangs(tmp_path, monkeypatch, body, says):
    """The parent's handling of its reader child: a crash (killed by a signal), a refusal
    and a hang each give exit 2 naming the nominal, nothing written. The child here is the
    fresh ``python3`` (the forked one's cases are in tests/app/test_cadfork.py)."""
    from surfcomp.app import cadfork, cadread

    monkeypatch.setattr(cadfork, "usable", lambda: False)
    child = _child(tmp_path, body)
    monkeypatch.setattr(cadread, "_python", lambda: child)
    if body.startswith("exec sleep"):
        # only the hang waits for the limit; a crash or a refusal is answered whenever the
        # parent looks (the first case of a fresh worker spends over 1 s importing FreeCAD
        # after starting the child, and a 1 s limit then misread the crash as a hang)
        monkeypatch.setattr(cadread, "TIMEOUT", 1.0)
    run_case(Case("child", ("compensate", "nominal.step", "m.csv", "-o", "c.step", "--quiet"),
                  setup=I.setup(NOM, MEAS), file="nominal.step", says=(says,)),
             tmp_path / "case")


DOC_ROUTE = ("compensate", "d.FCStd", "m.csv", "--object", "Nominal", "--replace", "--save",
             "out.FCStd", "--quiet")


def _hostile(module):
    files = [I.put("d.FCStd", lambda: I.rezip(lambda t: I.proxy_module(t, module))), MEAS]
    if module == "x":
        files.append(I.put("x.py", I.MARKER_MODULE))
    return I.setup(*files)


MODULE_CASES = [
    # reading a shape from the document: the proxy is not restored, the shape is
    Case("file-route-module-in-working-directory", ("compensate", "d.FCStd", "m.csv",
                                                    "--object", "Nominal", "-o", "c.step",
                                                    "--quiet"),
         setup=_hostile("x"), rc=0, writes=("c.step",)),
    # updating the document: it would lose the object, so it is refused
    Case("document-route-module-in-working-directory", DOC_ROUTE, setup=_hostile("x"),
         file="d.FCStd", says=("1 object(s) did not restore", "module x not imported",
                               "neither FreeCAD's nor an installed addon's folder")),
    Case("inspect-module-this", ("inspect", "d.FCStd", "m.csv", "--object", "Nominal",
                                 "--quiet"), setup=_hostile("this"), rc=0),
    Case("document-route-module-this", DOC_ROUTE, setup=_hostile("this"), file="d.FCStd",
         says=("did not restore", "module this not imported")),
]


@pytest.mark.parametrize("case", MODULE_CASES, ids=str)
def test_document_naming_a_module(case, tmp_path):
    res = run_case(case, tmp_path / "case", runner=run_subprocess)
    assert not os.path.exists(tmp_path / "case" / "MARKER")
    assert ZEN not in res.out + res.err
