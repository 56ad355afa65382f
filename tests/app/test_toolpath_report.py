# SPDX-License-Identifier: LGPL-2.1-or-later
"""Replace and Restore report only what the recompute did to the tool paths, and a shop
document that FreeCAD opens by itself (surfcomp's ``Init.py`` has run, nothing else of it)
restores its CAM objects: OpenCamLib as ``ocl`` on every version, 0.20's ``PathScripts.*``
modules on 1.x.

``shop_open_script.py`` runs in a fresh ``freecadcmd`` whose user home links this checkout;
it opens ``tests/data/documents/shop-0.20.FCStd`` with ``FreeCAD.openDocument``, restores
``Round2`` (the operation goes back to the block) and replaces again, reporting each step
with :mod:`surfcomp.app.toolpaths`. A second run makes OpenCamLib unimportable while the
document opens, as on a machine without it: the 3D Surface operation loses its Python
object, Restore says it was not regenerated, and Replace refuses.
"""

import json
import os
import shutil
import subprocess
import sys

import FreeCAD
import numpy as np
import pytest

from surfcomp.app import features, replace, toolpaths
from surfcomp.errors import InputError
from tests.app.test_document_job import PROXY_MODULE
from tests.app.test_features import add_part, block_solid
from tests.conftest import ROOT
from tests.toolpath_checks import assert_moved_by_the_correction, shift_check, surface_from_json

DOCS = os.path.join(ROOT, "tests", "data", "documents")
SCRIPT = os.path.join(ROOT, "tests", "app", "shop_open_script.py")
R = 3.0                 # the shop document's ball end mill (6 mm)
DEFLECTION = 0.01       # the Surface operation's LinearDeflection in the shop document (mm)


def run_script(tmp, block=""):
    home = tmp / "fchome"
    (home / "Mod").mkdir(parents=True)
    os.symlink(ROOT, home / "Mod" / "surfcomp")
    path = str(tmp / "shop-0.20.FCStd")
    shutil.copyfile(os.path.join(DOCS, "shop-0.20.FCStd"), path)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(SURFCOMP_DOC=path, FREECAD_USER_HOME=str(home),
               SURFCOMP_BLOCK=block)
    out = subprocess.run(["freecadcmd", SCRIPT], capture_output=True, text=True,
                         timeout=600, cwd=str(tmp), env=env)
    text = out.stdout.replace("\r", "\n")
    line = [s for s in text.split("\n") if s.startswith("RESULT ")]
    assert line, text[-3000:] + out.stderr[-3000:]
    return json.loads(line[-1][len("RESULT "):])


@pytest.fixture(scope="module")
def opened(tmp_path_factory):
    return run_script(tmp_path_factory.mktemp("shop_open"))


@pytest.fixture(scope="module")
def without_ocl(tmp_path_factory):
    return run_script(tmp_path_factory.mktemp("shop_no_ocl"), block="ocl")


@pytest.fixture(scope="module")
def without_cam_modules(tmp_path_factory):
    return run_script(tmp_path_factory.mktemp("shop_no_cam"), block="cam")


def statuses(report):
    return {op["name"]: op["status"] for job in report for op in job["operations"]}


def test_init_resolves_the_names_lazily_and_every_cam_object_restores(opened):
    # Init.py imported nothing of the CAM workbench, OpenCamLib or surfcomp's GUI
    assert opened["loaded_before_open"] == []
    proxies = opened["proxies"]
    assert proxies["Job"] == "ObjectJob" and proxies["Surface"] == "ObjectSurface"
    assert proxies["Stock"] == "StockFromBase" and proxies["SetupSheet"] == "SetupSheet"
    assert proxies["TC__Default_Tool"] == "ToolController" and proxies["BallEnd"] == "ToolBit"
    # 1.x: the Job came from 0.20's module name, resolved to its 1.x home
    expected = "Path.Main.Job" if opened["modules"] == "Path" else "PathScripts.PathJob"
    assert opened["job_module"] == expected
    assert opened["invalid"] == []


def test_restore_and_replace_regenerate_and_say_so(opened):
    n = len(opened["saved"])
    assert n > 90
    for step in ("restore", "replace"):
        (job,) = opened[step]
        assert job["label"] == "Job" and job["lost"] == []
        ops = {op["name"]: op for op in job["operations"]}
        assert statuses(opened[step]) == {"Surface": "regenerated",
                                          "DressupAxisErrors": "regenerated"}
        # the feed moves all moved (the face moved in or out under each sample)
        assert n <= ops["Surface"]["changed"] <= ops["Surface"]["commands"]
        (line,) = opened[step + "_lines"]
        assert "Surface regenerated (%d of %d commands changed)" % (
            ops["Surface"]["changed"], ops["Surface"]["commands"]) in line


def test_the_tool_path_moves_by_what_the_correction_implies(opened):
    s = opened["surfaces"]
    before = np.array(opened["restored"])[:, 1:]
    after = np.array(opened["replaced"])[:, 1:]
    assert before.shape == after.shape
    check = shift_check(surface_from_json(s["nominal"]), surface_from_json(s["corrected"]),
                        s["outward"], before, after, R)
    # paired samples; each path on its surface's exact drop-cutter height within the mesh
    # deflection (measured 6.7 and 3.8 um); at the command where the correction is largest
    # the tip went down by -t/n_z (measured 36.7 um against 37.8 um)
    assert_moved_by_the_correction(check, DEFLECTION)
    # and the replaced path is the one 0.20 computed and saved (within the deflection)
    saved = np.array(opened["saved"])[:, 1:]
    assert saved.shape == after.shape and np.abs(saved - after).max() < DEFLECTION


def test_without_opencamlib_nothing_claims_a_regeneration(without_ocl):
    r = without_ocl
    assert r["loaded_before_open"] == []
    assert r["proxies"]["Surface"] == "NoneType" and r["proxies"]["Job"] == "ObjectJob"
    # Restore puts the links back, but says the tool paths did not follow
    assert statuses(r["restore"]) == {"Surface": "lost", "DressupAxisErrors": "stale"}
    (line,) = r["restore_lines"]
    assert "Surface NOT regenerated: its Python object did not restore" in line
    assert "DressupAxisErrors NOT regenerated: its base operation Surface was not" in line
    assert "regenerated (" not in line
    # Replace refuses with the reason and changes nothing
    assert r["replace_error"].startswith("1 object(s) that use Block lost their Python "
                                         "objects when the document was opened")
    assert "Surface (Path::FeaturePython, label 'Surface')" in r["replace_error"]
    assert "nothing was replaced" in r["replace_error"] and r["replace_record"] == ""
    # the operation kept the tool path it was saved with through both steps
    assert r["saved"] == r["restored"] == r["replaced"]


def test_a_job_that_lost_its_python_objects_is_reported_and_not_replaced(without_cam_modules):
    """As 1.1 opened a 0.20 document before the names resolved: the Job, its stock, setup
    sheet, tool controller and tool bit and the operation lose their Python objects."""
    r = without_cam_modules
    for name in ("Job", "Stock", "SetupSheet", "TC__Default_Tool", "BallEnd", "Surface"):
        assert r["proxies"][name] == "NoneType", name
    (job,) = r["restore"]
    assert job["lost"] == ["Job", "Stock", "SetupSheet", "TC: Ball end 6 mm", "Ball end 6 mm"]
    assert statuses(r["restore"]) == {"Surface": "lost", "DressupAxisErrors": "stale"}
    (line,) = r["restore_lines"]
    assert line.startswith("Path job Job: NOT regenerated: Job, Stock, SetupSheet, TC: Ball "
                           "end 6 mm, Ball end 6 mm did not restore when the document was "
                           "opened; ")
    assert r["replace_error"].startswith("6 object(s) that use Block lost their Python")
    for name in ("Job", "Stock", "SetupSheet", "TC__Default_Tool", "BallEnd", "Surface"):
        assert "%s (" % name in r["replace_error"], name
    assert r["replace_record"] == "" and r["saved"] == r["restored"] == r["replaced"]


def test_replace_refuses_when_a_user_of_the_nominal_lost_its_python_object(tmp_path,
                                                                          monkeypatch):
    """Any user of the nominal, not only CAM objects: its proxy module is gone at open time."""
    mod_dir = tmp_path / "mods"
    mod_dir.mkdir()
    (mod_dir / "surfcomp_test_gone.py").write_text(PROXY_MODULE)
    monkeypatch.syspath_prepend(str(mod_dir))
    import surfcomp_test_gone

    doc = FreeCAD.newDocument("lostuser")
    block = add_part(doc, block_solid(), "Block")
    thing = doc.addObject("App::FeaturePython", "Thing")
    surfcomp_test_gone.Thing(thing)
    thing.addProperty("App::PropertyLink", "Source", "Test", "")
    thing.Source = block
    path = str(tmp_path / "lost.FCStd")
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    del sys.modules["surfcomp_test_gone"]
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p != str(mod_dir)])
    (mod_dir / "surfcomp_test_gone.py").unlink()
    doc = FreeCAD.openDocument(path)
    try:
        thing, block = doc.getObject("Thing"), doc.getObject("Block")
        assert thing.Proxy is None and toolpaths.has_lost_proxy(thing)
        comp = features.make_compensation(doc, block, "Face2", _measurement(doc, block),
                                          output="solid")
        doc.recompute()
        with pytest.raises(InputError, match=r"^1 object\(s\) that use Block lost their "
                                             r"Python objects.*Thing \(App::FeaturePython, "
                                             r"label 'Thing'\)"):
            replace.replace(doc, comp)
        assert thing.Source is block and comp.ReplacedLinks == ""
    finally:
        FreeCAD.closeDocument(doc.Name)


def _measurement(doc, block):
    from surfcomp.app.nominal import nominal_from_face
    from tests.app.helpers import grid_on_face, write_cmm_csv
    from tests.app.test_features import error_model

    nominal = nominal_from_face(block.Shape.Faces[1], face_name="Face2")
    P, N, _, _ = grid_on_face(nominal, 9, 9, margin=0.0)
    write_cmm_csv(doc.TransientDir + "/m.csv", P, N, error_model(P))
    return features.make_measurement(doc, doc.TransientDir + "/m.csv")
