# SPDX-License-Identifier: LGPL-2.1-or-later
"""--align / --transform on the shop-document route (issue 28): the measurement object the
route adds records the alignment, the compensation shows it, the CLI prints it; bad input
exits 2 with nothing saved."""

import hashlib
import json

import FreeCAD
import numpy as np
import pytest
from numpy.testing import assert_allclose

from surfcomp.io.readers import read_any
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP
from tests.app.test_align_cli import MOVE, _points, run_cli


@pytest.fixture(scope="module")
def shop(tmp_path_factory):
    """d.FCStd holding the example face as ``Nominal``; the example's measured points moved
    by MOVE (p.xyz) and the transform back (t.json)."""
    import Part

    tmp = tmp_path_factory.mktemp("alignshop")
    doc = FreeCAD.newDocument("alignshop")
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    doc.recompute()
    doc.saveAs(str(tmp / "d.FCStd"))
    FreeCAD.closeDocument(doc.Name)
    _points(tmp, MOVE)
    (tmp / "still").mkdir()
    _points(tmp / "still", np.eye(4))
    (tmp / "t.json").write_text(json.dumps({"matrix": np.linalg.inv(MOVE).tolist()}))
    return tmp


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _saved(path):
    """(measurement, compensation) objects of a saved document, and the document."""
    doc = FreeCAD.openDocument(str(path))
    meas = next(o for o in doc.Objects if hasattr(o, "AlignMethod"))
    comp = next(o for o in doc.Objects if hasattr(o, "AlignMatrix"))
    return doc, meas, comp


def _compensate(shop, out, *extra):
    return run_cli("compensate", shop / "d.FCStd", shop / "points.xyz", "--object", "Nominal",
                   "--face", "Face1", "--save", out, *extra)


def test_transform_on_the_document_route(shop, tmp_path):
    """The known transform puts the moved points back: the saved compensation's deviations
    are those of the points never moved (0.1 um), the measurement object holds the
    matrix."""
    still = run_cli("compensate", shop / "d.FCStd", shop / "still" / "points.xyz", "--object",
                    "Nominal", "--face", "Face1", "--save", tmp_path / "still.FCStd", "--quiet")
    assert still.returncode == 0 and "Alignment" not in still.stdout, still.stderr
    doc, meas, comp = _saved(tmp_path / "still.FCStd")
    unmoved = np.array(comp.Deviation)
    assert meas.AlignMethod == "none" and meas.AlignTransform == [] and comp.AlignMatrix == []
    FreeCAD.closeDocument(doc.Name)
    out = tmp_path / "out.FCStd"
    run = _compensate(shop, out, "--transform", shop / "t.json", "--quiet")
    assert run.returncode == 0, run.stderr
    assert "Alignment:    none (with the known transform): translation" in run.stdout
    doc, meas, comp = _saved(out)
    try:
        assert meas.AlignMethod == "none"
        assert_allclose(meas.AlignTransform, np.linalg.inv(MOVE).ravel(), atol=1e-12)
        assert_allclose(comp.AlignMatrix, np.linalg.inv(MOVE).ravel(), atol=1e-12)
        assert_allclose(comp.Deviation, unmoved, atol=1e-4)
        assert len(unmoved) == len(read_any(EXAMPLE_CSV).deviation)
        assert comp.Alignment[0].startswith("Alignment:    none (with the known transform)")
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_bestfit_on_the_document_route_reports_what_it_absorbed(shop, tmp_path):
    """A best fit on the compensated face, as on the file route: the same summary, the
    absorbed mean offset warned about and kept in the document, which recomputes to the
    same result after it is opened again."""
    out = tmp_path / "out.FCStd"
    run = _compensate(shop, out, "--transform", shop / "t.json", "--align", "bestfit",
                      "--align-dof", "z,rx,ry", "--quiet")
    assert run.returncode == 0, run.stderr
    assert "Alignment:    bestfit (with the known transform)" in run.stdout
    assert "degrees of freedom z rx ry" in run.stdout and "converged" in run.stdout
    assert "warning: " in run.stderr and "absorbed a mean offset" in run.stderr
    file_route = run_cli("inspect", EXAMPLE_STEP, shop / "points.xyz", "--transform",
                         shop / "t.json", "--align", "bestfit", "--align-dof", "z,rx,ry",
                         "--report", tmp_path / "r.json", "--quiet")
    assert file_route.returncode == 0, file_route.stderr
    rep = json.loads((tmp_path / "r.json").read_text())
    doc, meas, comp = _saved(out)
    try:
        assert (meas.AlignMethod, meas.AlignDof, meas.AlignFaces) == ("bestfit", "z,rx,ry", "")
        # the document's fit is the file route's
        assert_allclose(np.reshape(comp.AlignMatrix, (4, 4)), rep["alignment"]["matrix"],
                        atol=1e-9)
        # the grid's nodes hold the file's points in another order
        assert_allclose(np.sort(comp.Deviation), np.sort(rep["points"]["deviation"]),
                        atol=1e-4)
        absorbed = rep["alignment"]["absorbed"]["mean_offset_um"]
        assert abs(absorbed) > 1.0
        assert "absorbed on the compensated face: mean offset %.3f um" % absorbed \
            in "\n".join(comp.Alignment)
        before = list(comp.AlignMatrix)
        comp.touch()
        doc.recompute()
        assert comp.State == [] or "Invalid" not in comp.State
        assert_allclose(comp.AlignMatrix, before, atol=1e-12)
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_rps_ids_go_to_the_measurement_object(shop, tmp_path):
    """3-2-1 from a JSON file: the ids are kept in the document (not the file's path)."""
    (tmp_path / "rps.json").write_text(json.dumps(
        {"primary": [1, 40, 200], "secondary": [5, 30], "tertiary": [100]}))
    out = tmp_path / "out.FCStd"
    run = _compensate(shop, out, "--transform", shop / "t.json", "--align", "rps",
                      "--rps", tmp_path / "rps.json", "--quiet")
    assert run.returncode == 0, run.stderr
    assert "3-2-1 on Face1" in run.stdout
    doc, meas, comp = _saved(out)
    try:
        assert meas.AlignRps == "1,40,200;5,30;100"
        assert len(comp.AlignMatrix) == 16
    finally:
        FreeCAD.closeDocument(doc.Name)


@pytest.mark.parametrize("case", ["scaled", "collinear", "dof"])
def test_bad_alignment_exits_2_and_saves_nothing(shop, tmp_path, case):
    digest = _sha(shop / "d.FCStd")
    out = tmp_path / "out.FCStd"
    if case == "scaled":
        scaled = np.eye(4)
        scaled[0, 0] = 1.001
        np.savetxt(tmp_path / "t.txt", scaled)
        run = _compensate(shop, out, "--transform", tmp_path / "t.txt", "--quiet")
        expected = "not rigid"
    elif case == "collinear":
        run = _compensate(shop, out, "--transform", shop / "t.json", "--align", "rps",
                          "--rps", "1,2,3;4,5;6", "--quiet")
        expected = "collinear"
    else:
        run = _compensate(shop, out, "--align", "bestfit", "--align-dof", "q", "--quiet")
        expected = "--align-dof 'q'"
    assert run.returncode == 2, (run.stdout, run.stderr)
    assert expected in run.stderr, run.stderr
    assert not out.exists() and _sha(shop / "d.FCStd") == digest
    assert sorted(p.name for p in tmp_path.iterdir()) == (["t.txt"] if case == "scaled" else [])


def test_rps_groups_naming_a_face_are_kept_as_json():
    """A 3-2-1 group naming its face cannot be written inline: the property keeps the JSON
    object, which reads back to the same groups; bad JSON names the property."""
    from surfcomp.app import align_doc
    from surfcomp.errors import InputError

    groups = {"primary": {"points": ["A", "B", "C"], "face": "Face1"},
              "secondary": ["D", "E"], "tertiary": ["F"]}
    text = align_doc.rps_text(groups)
    assert text.startswith("{") and align_doc.rps_groups(text, "M") == groups
    assert align_doc.rps_text({"primary": [1, 2, 3], "secondary": [4, 5],
                               "tertiary": [6]}) == "1,2,3;4,5;6"
    opts = align_doc.options_from("M", "rps", "", "all", text, [])
    assert opts.rps == groups and opts.method == "rps"
    with pytest.raises(InputError, match="M: AlignRps is not valid JSON"):
        align_doc.rps_groups("{primary", "M")
