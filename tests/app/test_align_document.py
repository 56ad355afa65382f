# SPDX-License-Identifier: LGPL-2.1-or-later
"""Alignment in the document (issue 28): the measurement object's Align* properties, the
compensation's AlignMatrix and Alignment, recomputed headless."""

import numpy as np
import Part
import pytest
from numpy.testing import assert_allclose

from surfcomp.app.features import make_compensation, make_measurement
from tests.app.helpers import EXAMPLE_STEP
from tests.app.test_align_cli import MOVE, _points


def _doc(doc, tmp_path, move):
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    meas = make_measurement(doc, str(_points(tmp_path, move)))
    comp = make_compensation(doc, nom, "Face1", meas)
    return meas, comp


def test_transform_and_bestfit_properties(tmp_path, fresh_doc):
    doc = fresh_doc
    meas, comp = _doc(doc, tmp_path, np.eye(4))
    doc.recompute()
    assert comp.AlignMatrix == [] and comp.Alignment == []
    unmoved = np.array(comp.Deviation)
    (tmp_path / "moved").mkdir()
    meas2, comp2 = _doc(doc, tmp_path / "moved", MOVE)
    meas2.AlignTransform = [float(x) for x in np.linalg.inv(MOVE).ravel()]
    doc.recompute()
    assert_allclose(comp2.AlignMatrix, np.linalg.inv(MOVE).ravel(), atol=1e-12)
    assert_allclose(np.array(comp2.Deviation), unmoved, atol=1e-4)
    meas2.AlignMethod = "bestfit"
    doc.recompute()
    summary = "\n".join(comp2.Alignment)
    assert "Alignment:    bestfit" in summary and "absorbed on the compensated face" in summary
    assert any("absorbed a mean offset" in w for w in comp2.Warnings)
    assert abs(np.mean(comp2.Deviation)) < abs(np.mean(unmoved))


def test_bad_alignment_properties_name_the_property(tmp_path, fresh_doc):
    doc = fresh_doc
    meas, comp = _doc(doc, tmp_path, np.eye(4))
    meas.AlignTransform = [1.0] * 12
    doc.recompute()
    assert "AlignTransform holds 12 numbers" in " ".join(comp.getStatusString().split())
    meas.AlignTransform = []
    meas.AlignMethod = "rps"
    doc.recompute()
    assert "AlignMethod rps needs AlignRps" in comp.getStatusString()
    meas.AlignMethod = "bestfit"
    meas.AlignDof = "q"
    doc.recompute()
    assert "AlignDof 'q'" in comp.getStatusString()
    with pytest.raises(ValueError):
        meas.AlignMethod = "magic"


def test_face_column_is_stored_with_the_points(tmp_path, fresh_doc, monkeypatch):
    """A point file's face column goes into the measurement object (``PointFaces``) with
    the points: the alignment uses it after the file is gone, never a file of the same name
    in the working folder, and it survives save and reopen."""
    import shutil

    import FreeCAD

    from surfcomp.app import align_doc, features
    from tests.app.test_align_cli import block_points

    top_name, names, _dev, faces, pts = block_points(tmp_path)
    rows = ["x,y,z,face"] + ["%.10f,%.10f,%.10f,%s" % (tuple(p) + (f,))
                             for p, f in zip(pts, faces)]
    rows[5] = rows[5].rsplit(",", 1)[0] + ",Face9"       # no reference face: refused
    (tmp_path / "f.csv").write_text("\n".join(rows) + "\n")
    doc = fresh_doc
    box = doc.addObject("Part::Feature", "Box")
    box.Shape = Part.read(str(tmp_path / "box.step"))
    meas = make_measurement(doc, str(tmp_path / "f.csv"))
    (tmp_path / "f.csv").unlink()
    decoy = tmp_path / "cwd"
    decoy.mkdir()
    (decoy / "f.csv").write_text("\n".join(rows[:5] + rows[6:]) + "\n")
    monkeypatch.chdir(decoy)
    assert list(meas.PointFaces) == faces[:4] + ["Face9"] + faces[5:]
    assert features.measurement_set(meas).faces == list(meas.PointFaces)
    meas.AlignMethod = "bestfit"
    meas.AlignFaces = ",".join(names)
    comp = make_compensation(doc, box, top_name, meas)
    doc.recompute()
    status = " ".join(comp.getStatusString().split())
    assert "f.csv:6: face 'Face9' is not a reference face" in status, status
    doc.saveAs(str(tmp_path / "faces.FCStd"))
    shutil.copy(tmp_path / "faces.FCStd", tmp_path / "reopened.FCStd")
    again = FreeCAD.openDocument(str(tmp_path / "reopened.FCStd"))
    try:
        m2 = again.getObject(meas.Name)
        assert list(m2.PointFaces)[:6] == faces[:4] + ["Face9", faces[5]]
        m2.PointFaces = faces                        # the column without the bad name
        nominal, _placement = features.nominal_of(again.getObject(comp.Name))
        _ms, rec = align_doc.aligned(m2, nominal, features.measurement_set(m2))
        assert rec.as_dict()["points"] == {**{n: 150 for n in names}, top_name: 300}
    finally:
        FreeCAD.closeDocument(again.Name)
