# SPDX-License-Identifier: LGPL-2.1-or-later
"""A compensation recomputed with the same inputs reuses its result; a changed input
(measurement data, nominal shape, option, the previous round) computes it again."""

import FreeCAD
import numpy as np
import Part
import pytest

from surfcomp.app import features, result_cache
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP
from tests.app.test_document_job import shop  # noqa: F401  (the shop document fixture)
from tests.app.test_features import add_part, block_solid, poles


@pytest.fixture
def doc():
    d = FreeCAD.newDocument("resultcache")
    result_cache.forget()
    yield d
    result_cache.forget()
    FreeCAD.closeDocument(d.Name)


@pytest.fixture
def fits(monkeypatch):
    """Counts the core fits (``compensate``) the features run."""
    calls = []
    real = features.compensate
    monkeypatch.setattr(features, "compensate",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    return calls


def _again(doc, c):
    c.touch()
    doc.recompute()
    assert "Invalid" not in c.State, c.State


def test_same_inputs_reuse_the_fit_and_a_change_redoes_it(doc, fits):
    nom = add_part(doc, Part.read(EXAMPLE_STEP))
    m = features.make_measurement(doc, EXAMPLE_CSV)
    c = features.make_compensation(doc, nom, "Face1", m)
    c.Refine = 1
    doc.recompute()
    assert len(fits) == 1
    face, vol = poles(c.Shape), c.CorrVol
    _again(doc, c)
    features.compensation_result(c)
    assert len(fits) == 1                                   # reused, twice
    np.testing.assert_array_equal(poles(c.Shape), face)
    assert c.CorrVol == vol and abs(vol) > 1.0
    # the measurement's data: 1 um more everywhere, about the face's area in mm^3 more
    m.Deviation = (np.asarray(m.Deviation) + 0.001).tolist()
    doc.recompute()
    assert len(fits) == 2
    assert c.CorrVol - vol == pytest.approx(0.001 * c.Shape.Faces[0].Area, rel=0.02)
    _again(doc, c)
    assert len(fits) == 2
    # an option
    c.MaskSize = 3
    doc.recompute()
    assert len(fits) == 3
    # the nominal: a pole moved by 5 um (the file's nominal points then lie up to a few um
    # off it: reported; a larger change is refused, tests/pure/test_file_points.py)
    shape = nom.Shape.copy()
    surf = shape.Faces[0].Surface.copy()
    p = surf.getPole(4, 4)
    surf.setPole(4, 4, FreeCAD.Vector(p.x, p.y, p.z + 0.005))
    nom.Shape = surf.toShape(*shape.Faces[0].ParameterRange)
    doc.recompute()
    assert len(fits) == 4
    # the same inputs in a new object compute again (the key is per object)
    c2 = features.make_compensation(doc, nom, "Face1", m, name="Other")
    c2.Refine, c2.MaskSize = 1, 3
    doc.recompute()
    assert len(fits) == 5
    np.testing.assert_array_equal(poles(c2.Shape), poles(c.Shape))


def test_solid_output_and_iteration_rounds(doc, fits):
    """A solid output keys on the whole shape; the next round keys on its Base's
    correction, so a recomputed first round with a new result recomputes the second."""
    block = add_part(doc, block_solid(), "Block")
    m = features.make_measurement(doc, EXAMPLE_CSV)
    r1 = features.make_compensation(doc, block, "Face2", m, output="solid", name="Round1")
    r2 = features.make_compensation(doc, block, "Face2", m, output="solid", base=r1,
                                    name="Round2")
    for r in (r1, r2):
        r.Refine = 1
    doc.recompute()
    assert len(fits) == 2
    vol2 = r2.VolChange
    for r in (r1, r2):
        _again(doc, r)
    assert len(fits) == 2 and r2.VolChange == vol2
    assert r2.VolChange == pytest.approx(-r2.CorrVol, rel=0.02)
    # a neighbour face changes (the block 1 mm lower): the solid is another one
    block.Shape = block_solid(zb=-6.0)
    doc.recompute()
    assert len(fits) == 4
    # the first round's method changes: both rounds compute again
    r1.Method = "raw"
    doc.recompute()
    assert len(fits) == 6
    assert r2.VolChange != pytest.approx(vol2, rel=1e-6)


def test_the_document_route_fits_once(shop, tmp_path, fits):  # noqa: F811
    """compensate DOC --replace: the result asked for before the recompute (bad input
    raises with its file and line), the object's recompute and the document's after the
    replace are one fit."""
    from surfcomp.app.document_route import run_document_job
    from surfcomp.core.compensation.pipeline import Options

    result_cache.forget()
    res = run_document_job(shop["doc"], shop["meas"], "Block", face="Face2",
                           save=str(tmp_path / "out.FCStd"), replace=True,
                           options=Options(refine=1))
    assert len(fits) == 1
    assert res.replaced and res.volume_change == pytest.approx(-res.correction_volume,
                                                               rel=0.02)
    result_cache.forget()
