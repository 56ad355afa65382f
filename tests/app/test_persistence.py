# SPDX-License-Identifier: LGPL-2.1-or-later
"""Save, close, reopen in a fresh freecadcmd: everything restores and recomputes the same.

The saved document holds a block whose free-form top is compensated in two rounds
(solid output), the second round replacing the nominal under a Path Job with a 3D Surface
operation. The measurement files are deleted before the reopen: the data is in the
document. A fresh ``freecadcmd`` (FreeCAD refuses to restore proxies of modules outside
its Mod folders, so this is the real check) reopens it, recomputes the surfcomp objects and
the operation and reports shapes, tool path and G-code, which must equal the ones before saving.
"""

import json
import os
import subprocess

import FreeCAD
import numpy as np
import pytest

from surfcomp.app import cam, cam_job, documents, features, replace
from surfcomp.app.nominal import nominal_from_face
from tests.app.helpers import grid_on_face, write_cmm_csv
from tests.app.test_features import add_part, block_solid, error_model
from tests.conftest import ROOT

POST_ARGS = "--no-show-editor --no-header --precision=4"

SCRIPT = r"""
import json, os, sys
sys.path.insert(0, os.environ["SURFCOMP_ROOT"])
from surfcomp.app import cam
cam.setup_ocl()                   # before opening: the 3D Surface op imports ocl
import FreeCAD
path = os.environ["SURFCOMP_DOC"]
doc = FreeCAD.openDocument(path)
from surfcomp.app import documents, features, cam_job

def poles(shape, k):
    return [[tuple(p) for p in row] for row in shape.Faces[k].Surface.getPoles()]

out = {"gui": FreeCAD.GuiUp, "problems": documents.restore_failures(doc, path),
       "types": {o.Name: getattr(o.Proxy, "Type", type(o.Proxy).__name__)
                 for o in doc.Objects if "Proxy" in o.PropertiesList},
       "module": features.__name__,
       "saved_poles": poles(doc.getObject("Round2").Shape, 1)}
for name in ("Meas1", "Meas2", "Round1", "Round2", "Surface"):
    doc.getObject(name).touch()
doc.recompute()
job = doc.getObject("Job")
op = doc.getObject("Surface")
out.update({"invalid": [o.Name for o in doc.Objects if "Invalid" in o.State or "Error" in o.State],
            "poles1": poles(doc.getObject("Round1").Shape, 1),
            "poles2": poles(doc.getObject("Round2").Shape, 1),
            "correction2": list(doc.getObject("Round2").Correction),
            "versions": [doc.getObject(n).Version for n in ("Round1", "Round2", "Meas1")],
            "cl": cam_job.cutter_locations(op).tolist(),
            "gcode": cam_job.post_process(job, "linuxcnc", os.environ["SURFCOMP_POST_ARGS"])})
print("RESULT " + json.dumps(out))
sys.stdout.flush()
os._exit(0)
"""


def _poles(shape, k):
    return np.array([[tuple(p) for p in row] for row in shape.Faces[k].Surface.getPoles()])


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("persist")
    cam.setup_workbench()
    doc = FreeCAD.newDocument("persist")
    solid = block_solid()
    nom = add_part(doc, solid, "Block")
    nominal = nominal_from_face(solid.Faces[1], face_name="Face2")
    P, N, _, _ = grid_on_face(nominal, 11, 11, margin=0.0)
    rng = np.random.default_rng(11)
    csv1, csv2 = tmp / "round1.csv", tmp / "round2.csv"
    write_cmm_csv(csv1, P, N, error_model(P) + rng.normal(0, 5e-4, (11, 11)))
    write_cmm_csv(csv2, P, N, 0.2 * error_model(P) + rng.normal(0, 5e-4, (11, 11)))
    m1 = features.make_measurement(doc, str(csv1), name="Meas1")
    m2 = features.make_measurement(doc, str(csv2), name="Meas2")
    c1 = features.make_compensation(doc, nom, "Face2", m1, output="solid", name="Round1")
    c2 = features.make_compensation(doc, nom, "Face2", m2, base=c1, output="solid", name="Round2")
    c1.Refine = c2.Refine = 1
    job = cam_job.create_job(doc, [nom])
    tc = cam_job.ball_end_tool_controller(job, 6.0)
    op = cam_job.surface_operation(job, nom, ["Face2"], tc, step_over=100.0, sample_interval=2.0,
                                   linear_deflection=0.005)
    doc.recompute()
    replace.replace(doc, c2)
    doc.recompute()
    assert [o.Name for o in doc.Objects if "Invalid" in o.State] == []
    path = str(tmp / "shop.FCStd")
    doc.saveAs(path)
    before = {"poles1": _poles(c1.Shape, 1), "poles2": _poles(c2.Shape, 1),
              "correction2": list(c2.Correction), "cl": cam_job.cutter_locations(op),
              "gcode": cam_job.post_process(job, "linuxcnc", POST_ARGS),
              "objects": {o.Name for o in doc.Objects}}
    FreeCAD.closeDocument(doc.Name)
    os.unlink(csv1)
    os.unlink(csv2)              # the measurement files are gone
    return path, before


def test_reopen_in_a_fresh_freecadcmd(saved, tmp_path):
    path, before = saved
    script = tmp_path / "reopen.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, SURFCOMP_DOC=path, SURFCOMP_ROOT=ROOT, SURFCOMP_POST_ARGS=POST_ARGS)
    out = subprocess.run(["freecadcmd", str(script)], capture_output=True, text=True, timeout=300,
                         cwd=str(tmp_path), env=env)
    line = [s for s in out.stdout.replace("\r", "\n").split("\n") if s.startswith("RESULT ")]
    assert line, out.stdout[-3000:] + out.stderr[-3000:]
    r = json.loads(line[-1][len("RESULT "):])
    assert not r["gui"] and r["problems"] == [] and r["invalid"] == []
    assert r["module"] == "surfcomp.app.features"
    types = r["types"]
    assert types["Round1"] == types["Round2"] == "SurfComp_Compensation"
    assert types["Meas1"] == types["Meas2"] == "SurfComp_Measurement"
    assert types["Surface"] == "ObjectSurface"          # Path's proxy restored (ocl found)
    assert r["versions"] == [features.VERSION] * 3
    # the saved shape and the recomputed one are the shape computed before saving
    np.testing.assert_allclose(r["saved_poles"], before["poles2"], atol=0)
    np.testing.assert_allclose(r["poles1"], before["poles1"], atol=1e-12)
    np.testing.assert_allclose(r["poles2"], before["poles2"], atol=1e-12)
    np.testing.assert_allclose(r["correction2"], before["correction2"], atol=1e-15)
    # the same tool path and program
    np.testing.assert_allclose(np.array(r["cl"]), before["cl"], atol=1e-9)
    assert len(before["cl"]) > 50
    # the program is the same but for the fixture block's clearance move, which Path's post
    # list takes from the Job's stock box, restored with another bounding box (Path's
    # StockFromBase keeps its Placement from creation time; not a surfcomp object)
    def program(text):
        lines = text.splitlines()
        k = lines.index("G54 ")
        assert lines[k + 1].startswith("G0 Z")
        return lines[:k + 1] + lines[k + 2:]

    # (a coordinate on a rounding boundary, e.g. 4.95495, may print one unit of the last
    # digit apart when the face differs by 1e-12 mm: numbers agree within that unit)
    got, want = program(r["gcode"]), program(before["gcode"])
    assert len(got) == len(want)
    for a, b in zip(got, want):
        wa, wb = a.split(), b.split()
        assert len(wa) == len(wb) and [w[0] for w in wa] == [w[0] for w in wb], (a, b)
        for x, y in zip(wa, wb):
            if x != y:
                assert abs(float(x[1:]) - float(y[1:])) <= 1.0001e-4, (a, b)
    assert r["gcode"].count("\nG1 ") == before["gcode"].count("\nG1 ") > 50


def test_old_documents_are_migrated(tmp_path):
    import Part

    from surfcomp.app.nominal import load_nominal
    from tests.app.helpers import EXAMPLE_STEP

    doc = FreeCAD.newDocument("olddoc")
    nom = add_part(doc, Part.read(EXAMPLE_STEP))
    nominal = load_nominal(EXAMPLE_STEP)
    P, N, _, _ = grid_on_face(nominal, 9, 9)
    write_cmm_csv(tmp_path / "m.csv", P, N, error_model(P))
    m = features.make_measurement(doc, str(tmp_path / "m.csv"))
    c = features.make_compensation(doc, nom, "Face1", m)
    doc.recompute()
    correction = list(c.Correction)
    # an older property set: no Refine / ReadWarnings / volumes (issue 17), version 0
    c.removeProperty("Refine")
    c.removeProperty("VolChange")
    c.removeProperty("CorrVol")
    c.Version = 0
    m.removeProperty("ReadWarnings")
    m.Version = 0
    path = str(tmp_path / "old.FCStd")
    doc.saveAs(path)
    FreeCAD.closeDocument(doc.Name)
    os.unlink(tmp_path / "m.csv")
    old = FreeCAD.openDocument(path)
    try:
        assert documents.restore_failures(old, path) == []
        c, m = old.getObject("Compensation"), old.getObject("Measurement")
        assert isinstance(c.Proxy, features.CompensationFeature)
        assert c.Version == features.VERSION and m.Version == features.VERSION
        assert c.Refine == 4 and list(m.ReadWarnings) == []
        assert c.VolChange == 0.0 and c.CorrVol == 0.0
        assert c.getEditorMode("VolChange") == ["ReadOnly"]
        c.touch()
        old.recompute()
        assert c.State == ["Up-to-date"]
        # the face output: the correction's integral over the face (mean ~10 um x 2120 mm^2)
        assert 10.0 < c.CorrVol < 40.0 and c.VolChange == 0.0
        np.testing.assert_allclose(c.Correction, correction, atol=1e-15)
    finally:
        FreeCAD.closeDocument(old.Name)
