# SPDX-License-Identifier: LGPL-2.1-or-later
"""The measurement plan as a document object: recompute headless, the same plan as the
command line's, saved and reopened."""

import numpy as np
from numpy.testing import assert_allclose

from surfcomp.app.nominal import load_nominal
from surfcomp.app.plan_feature import make_measurement_plan, plan_file_text
from surfcomp.app.plan_reach import plan_face
from surfcomp.core.measurement.planning import PlanSettings
from surfcomp.io.measurements import parse_measurements
from tests.app.helpers import EXAMPLE_STEP


def test_plan_object_matches_the_command_line_plan(fresh_doc, tmp_path):
    import FreeCAD
    import Part

    nom = fresh_doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    plan_obj = make_measurement_plan(fresh_doc, nom, "Face1", Layout="adaptive", Points=80,
                                     TipRadius=1.5)
    fresh_doc.recompute()
    assert plan_obj.State == [] or "Invalid" not in plan_obj.State
    ref, _ = plan_face(load_nominal(EXAMPLE_STEP), "adaptive", 80, PlanSettings(tip_radius=1.5))
    assert plan_obj.Kept == len(ref) == 80 and plan_obj.Placed == 80
    assert_allclose(np.array([tuple(p) for p in plan_obj.PlanPoints]), ref.points, atol=1e-9)
    assert_allclose(np.array([tuple(n) for n in plan_obj.PlanNormals]), ref.normals,
                    atol=1e-12)
    assert list(plan_obj.PointIds) == ref.ids
    assert plan_obj.Travel == ref.travel and plan_obj.Order == ref.order
    assert len(plan_obj.Shape.Vertexes) == 80
    ms = parse_measurements(plan_file_text(plan_obj), plan=True)
    assert_allclose(ms.nominal, ref.points, atol=1e-6)
    # a tilt limit that drops points is counted per reason; saved and reopened, the
    # results stay and a recompute gives them again
    plan_obj.MaxTilt = 15.0
    plan_obj.Layout = "grid"
    plan_obj.Count = "8x8"
    fresh_doc.recompute()
    assert plan_obj.Placed == 64 and 0 < plan_obj.Kept < 64
    # the option named as the plan's property (the command line says --max-tilt)
    assert plan_obj.Dropped[0].endswith("normal leans more than MaxTilt from +Z")
    assert int(plan_obj.Dropped[0].split()[0]) == 64 - plan_obj.Kept
    path = str(tmp_path / "plan.FCStd")
    fresh_doc.saveCopy(path)
    kept = plan_obj.Kept
    doc2 = FreeCAD.openDocument(path)
    try:
        again = doc2.getObject(plan_obj.Name)
        assert again.Proxy.Type == "SurfComp_MeasurementPlan" and again.Kept == kept
        again.touch()
        doc2.recompute()
        assert again.Kept == kept and len(again.PlanPoints) == kept
    finally:
        FreeCAD.closeDocument(doc2.Name)
