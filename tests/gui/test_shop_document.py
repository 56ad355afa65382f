# SPDX-License-Identifier: LGPL-2.1-or-later
"""A shop document saved by FreeCAD 0.20, opened in a freshly started FreeCAD GUI before
anything of surfcomp has run (its ``Init.py`` only), keeps its CAM objects; Restore nominal
and Replace in document, run as a user runs them, regenerate the 3D Surface operation, whose
commands move by what the correction implies, and the summaries say so.

Issue 24: on 0.20 the operation lost its Python object ("This operation requires
OpenCamLib"), on 1.1 the Job, stock, tool controller and operation did ("No module named
'PathScripts.PathJob'"), and Replace still reported "Path jobs touched: Job" while the
operation's commands stayed as they were.
"""

import os
import shutil

import numpy as np
import pytest

from tests.conftest import ROOT
from tests.gui.harness import run_gui, with_common
from tests.toolpath_checks import assert_moved_by_the_correction, shift_check, surface_from_json

R = 3.0                 # the shop document's ball end mill (6 mm)
DEFLECTION = 0.01       # the Surface operation's LinearDeflection (mm)

#: what the user does first: File > Open of the shop document in a fresh FreeCAD
OPEN = r'''
LOADED_BEFORE_OPEN = sorted(m for m in sys.modules
                            if m.split(".")[0] in ("PathScripts", "ocl", "opencamlib")
                            or m.startswith(("Path.", "surfcomp.gui")))
SHOP = FreeCAD.openDocument(os.path.join(os.environ["SURFCOMP_TMP"], "shop-0.20.FCStd"))
FreeCADGui.updateGui()
RESULTS["loaded_before_open"] = LOADED_BEFORE_OPEN
RESULTS["proxies"] = {o.Name: type(o.Proxy).__name__ for o in SHOP.Objects
                      if "Proxy" in o.PropertiesList}
RESULTS["report_view_open"] = report_view_text()
'''


#: a machine without OpenCamLib: it cannot be imported while the document opens
WITHOUT_OCL = r'''
import importlib.abc


class NoOpenCamLib(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        if fullname.split(".")[0] in ("ocl", "opencamlib"):
            raise ImportError("no OpenCamLib on this machine (test)")
        return None


sys.meta_path.insert(0, NoOpenCamLib())
'''


def run_shop(tmp, session_name, first=""):
    shutil.copyfile(os.path.join(ROOT, "tests", "data", "documents", "shop-0.20.FCStd"),
                    tmp / "shop-0.20.FCStd")
    with open(os.path.join(ROOT, "tests", "gui", session_name), encoding="utf-8") as f:
        body = f.read()
    results, output = run_gui(first + OPEN + with_common(body), tmp, timeout=600)
    results["output"] = output
    return results


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    return run_shop(tmp_path_factory.mktemp("gui_shop"), "session_shop.py")


@pytest.fixture(scope="module")
def without_ocl(tmp_path_factory):
    return run_shop(tmp_path_factory.mktemp("gui_shop_no_ocl"), "session_shop.py",
                    first=WITHOUT_OCL)


def test_session_ran_without_exceptions(session):
    assert session["errors"] == []


def test_the_cam_objects_restore_when_freecad_opens_the_document(session):
    assert session["loaded_before_open"] == []
    proxies = session["proxies"]
    assert proxies["Job"] == "ObjectJob" and proxies["Surface"] == "ObjectSurface"
    assert proxies["Stock"] == "StockFromBase" and proxies["SetupSheet"] == "SetupSheet"
    assert proxies["TC__Default_Tool"] == "ToolController" and proxies["BallEnd"] == "ToolBit"
    assert proxies["DressupAxisErrors"] == "DressupAxisErrors"
    text = session["report_view_open"]
    assert "OpenCamLib" not in text and "No module named" not in text
    assert session["job_module"] in ("PathScripts.PathJob", "Path.Main.Job")
    assert session["invalid"] == []


def test_restore_and_replace_report_the_regenerated_operation(session):
    for step, verb in (("restore", "Restored"), ("replace", "Rebound")):
        infos, errors = session[step]
        assert errors == []
        (title, text), = infos
        assert text.startswith(verb + " ")
        assert "Path jobs touched" not in text and "NOT regenerated" not in text
        line, = [s for s in text.splitlines() if s.startswith("Path job Job: ")]
        assert "Surface regenerated (" in line and "DressupAxisErrors regenerated" in line
    assert session["after_restore"] == ["Block", ""]
    assert session["after_replace"] == ["Round2", True]


def test_an_operation_that_only_logs_its_failure_is_reported_failed(session):
    """Before: 'Surface: tool path unchanged' (the replaced, now stale path kept)."""
    infos, errors = session["no_tool"]
    assert errors == [] and session["no_tool_kept"] is True
    (_title, text), = infos
    line, = [s for s in text.splitlines() if s.startswith("Path job Job: ")]
    assert ("Surface NOT regenerated, it failed: the CAM workbench reported: No Tool "
            "Controller is selected. We need a tool to build a Path.") in line
    assert "DressupAxisErrors NOT regenerated: its base operation Surface was not" in line
    assert "Surface regenerated" not in line and "tool path unchanged" not in line


def test_the_commands_move_by_what_the_correction_implies(session):
    before = np.array(session["restored"])
    after = np.array(session["replaced"])
    assert before.shape == after.shape and len(before) > 90
    # the same command numbers are the feed moves before and after
    np.testing.assert_array_equal(before[:, 0], after[:, 0])
    s = session["surfaces"]
    check = shift_check(surface_from_json(s["nominal"]), surface_from_json(s["corrected"]),
                        s["outward"], before[:, 1:], after[:, 1:], R)
    # Z went down by -t/n_z, within the mesh deflection
    assert_moved_by_the_correction(check, DEFLECTION)
    # the replaced program is the one 0.20 computed and saved (within the deflection)
    saved = np.array(session["saved"])
    assert np.abs(saved[:, 1:] - after[:, 1:]).max() < DEFLECTION


def test_without_opencamlib_restore_says_so_and_replace_refuses(without_ocl):
    r = without_ocl
    assert r["errors"] == []
    assert r["proxies"]["Surface"] == "NoneType"
    assert "This operation requires OpenCamLib" in r["report_view_open"]
    infos, errors = r["restore"]
    assert errors == []
    (_title, text), = infos
    assert "Surface NOT regenerated: its Python object did not restore" in text
    assert "regenerated (" not in text
    infos, errors = r["replace"]
    assert infos == []
    (title, message), = errors
    assert title.endswith("Replace in document")
    assert message.startswith("1 object(s) that use Block lost their Python objects")
    assert "Surface (Path::FeaturePython, label 'Surface')" in message
    # nothing was replaced and the operation kept its commands
    assert r["after_replace"] == ["Block", False]
    assert r["saved"] == r["restored"] == r["replaced"]
