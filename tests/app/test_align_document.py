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
