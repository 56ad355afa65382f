# SPDX-License-Identifier: LGPL-2.1-or-later
"""Addon Manager install: ``git clone`` of the repository into a fresh user's Mod folder
makes the workbench appear and work in the FreeCAD GUI, and a document saved with it
reopens after a restart. ``package.xml`` is read with FreeCAD's own parser.

The repository cloned is this checkout as it would be committed: a temporary repository
made from HEAD plus the working tree's tracked and untracked (not ignored) files, so the
test checks the code under review, not only the last commit.
"""

import os
import shutil
import subprocess
import xml.etree.ElementTree as ET

import pytest

from tests.conftest import ROOT
from tests.gui.harness import make_home, run_gui

GIT = ["git", "-c", "user.name=surfcomp-test", "-c", "user.email=test@example.invalid",
       "-c", "init.defaultBranch=main", "-c", "advice.detachedHead=false"]


def _git(*args, cwd=None):
    return subprocess.run(GIT + list(args), cwd=cwd, check=True, capture_output=True,
                          text=True).stdout


def _repository_as_committed(dst):
    """A repository whose HEAD is this checkout's working tree (HEAD + changes)."""
    _git("clone", "-q", "--no-hardlinks", ROOT, str(dst))
    files = _git("ls-files", "-co", "--exclude-standard", "-z", cwd=ROOT).split("\0")
    deleted = set(_git("ls-files", "-d", "-z", cwd=ROOT).split("\0"))
    for rel in files:
        if not rel or rel in deleted:
            continue
        src = os.path.join(ROOT, rel)
        if os.path.isfile(src):
            os.makedirs(os.path.dirname(os.path.join(dst, rel)), exist_ok=True)
            shutil.copy2(src, os.path.join(dst, rel))
    for rel in deleted:
        if rel and os.path.exists(os.path.join(dst, rel)):
            os.remove(os.path.join(dst, rel))
    _git("add", "-A", cwd=dst)
    _git("commit", "-q", "--allow-empty", "-m", "working tree under test", cwd=dst)


FIRST_START = r'''
import surfcomp
from surfcomp.gui import dialogs
Gui = FreeCADGui
clone = os.path.join(FreeCAD.getUserAppDataDir(), "Mod", "surfcomp")
RESULTS["clone"] = clone
RESULTS["surfcomp_file"] = surfcomp.__file__
RESULTS["version"] = surfcomp.__version__
md = FreeCAD.Metadata(os.path.join(clone, "package.xml"))
def _get(name):
    try:
        return getattr(md, name)
    except Exception as exc:          # an attribute this FreeCAD does not have
        return "n/a: %s" % exc
RESULTS["metadata"] = {k: _get(k) for k in ("Name", "Version", "Description", "Maintainer",
                                           "License", "Urls", "Icon", "FreeCADMin", "Depend")}
wbs = md.Content.get("workbench", [])
RESULTS["workbench_meta"] = [{"Name": w.Name, "Classname": w.Classname,
                              "Subdirectory": w.Subdirectory, "Icon": w.Icon} for w in wbs]
RESULTS["workbenches"] = sorted(Gui.listWorkbenches())
Gui.activateWorkbench("SurfCompWorkbench")
RESULTS["commands"] = sorted(c for c in Gui.listCommands() if c.startswith("SurfComp_"))
files = [os.path.join(clone, "examples", "nominal.step"),
         os.path.join(clone, "examples", "measurements.csv")]
dialogs.ask_open_file = lambda *a: files.pop(0)
dialogs.run_dialog = lambda dlg: True
errors = []
dialogs.show_error = lambda t, m: errors.append(m)
doc = FreeCAD.newDocument("Addon")
Gui.runCommand("SurfComp_LoadNominal")
Gui.runCommand("SurfComp_ImportMeasurements")
Gui.Selection.addSelection(doc.Name, "Nominal", "Face1")
Gui.Selection.addSelection(doc.Name, "Measurement")
Gui.runCommand("SurfComp_DeviationMap")
comp = doc.getObject("Compensation")
RESULTS["dialog_errors"] = errors
RESULTS["state"] = list(comp.State)
RESULTS["vertices"] = comp.ViewObject.Proxy.scene.surface_coords.point.getNum()
doc.saveAs(os.path.join(os.environ["SURFCOMP_TMP"], "addon.FCStd"))
'''

SECOND_START = r'''
import surfcomp
RESULTS["surfcomp_file"] = surfcomp.__file__
doc = FreeCAD.openDocument(os.path.join(os.environ["SURFCOMP_TMP"], "addon.FCStd"))
FreeCADGui.updateGui()
comp = doc.getObject("Compensation")
RESULTS["proxies"] = [type(comp.Proxy).__module__, type(comp.ViewObject.Proxy).__module__]
RESULTS["vertices"] = comp.ViewObject.Proxy.scene.surface_coords.point.getNum()
comp.touch()
doc.recompute()
RESULTS["state"] = list(comp.State)
'''


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("addon")
    repo = tmp / "repo"
    _repository_as_committed(repo)
    home = make_home(tmp, link_checkout=False)
    # what the Addon Manager does for a git-hosted workbench
    _git("clone", "-q", str(repo), str(home / "Mod" / "surfcomp"))
    first, out1 = run_gui(FIRST_START, tmp, home=home)
    second, out2 = run_gui(SECOND_START, tmp, home=home)
    return {"home": str(home), "first": first, "second": second}


def test_package_xml_parses_with_freecad_and_matches_the_package(installed):
    r = installed["first"]
    assert r["errors"] == []
    md = r["metadata"]
    assert md["Name"] == "SurfComp"
    assert md["Version"] == r["version"]
    assert "B-spline" in md["Description"]
    assert md["Maintainer"] and md["Maintainer"][0]["email"]
    assert md["License"][0]["name"] == "LGPL-2.1-or-later"
    assert {u["type"] for u in md["Urls"]} >= {"repository", "bugtracker"}
    assert md["FreeCADMin"] == "0.20.0"
    assert os.path.isfile(os.path.join(r["clone"], md["Icon"]))
    assert {"numpy", "scipy"} <= {d["package"] for d in md["Depend"]}
    # FreeCAD 0.20's parser does not report 'optional': read the attribute from the XML
    xml = ET.parse(os.path.join(r["clone"], "package.xml")).getroot()
    ns = {"p": "https://wiki.freecad.org/Package_Metadata"}
    optional = {d.text: d.get("optional") == "true" for d in xml.findall("p:depend", ns)
                if d.get("type") == "python"}
    assert optional["numpy"] is False and optional["scipy"] is False
    assert optional["matplotlib"] is True
    wb, = r["workbench_meta"]
    assert wb["Classname"] == "SurfCompWorkbench"
    assert wb["Subdirectory"] == "./"
    assert os.path.isfile(os.path.join(r["clone"], wb["Icon"]))


def test_cloned_workbench_appears_and_works(installed):
    r = installed["first"]
    assert r["surfcomp_file"].startswith(os.path.join(installed["home"], "Mod", "surfcomp"))
    assert "SurfCompWorkbench" in r["workbenches"]
    assert len(r["commands"]) == 19         # 18 commands and the map drop-down
    assert r["dialog_errors"] == []
    assert "Up-to-date" in r["state"]
    assert r["vertices"] == 90 * 90
    assert "Traceback" not in r["report_view"]


def test_document_reopens_after_restart(installed):
    r = installed["second"]
    assert r["errors"] == []
    assert r["surfcomp_file"].startswith(os.path.join(installed["home"], "Mod", "surfcomp"))
    assert r["proxies"] == ["surfcomp.app.features", "surfcomp.gui.viewproviders"]
    assert r["vertices"] == 90 * 90
    assert "Up-to-date" in r["state"]
    assert "Traceback" not in r["report_view"]
