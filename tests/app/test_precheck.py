# SPDX-License-Identifier: LGPL-2.1-or-later
"""The import preview's check of the points against the nominal face (surfcomp.app.precheck):
the deviation map's own location checks, before the measurement enters the document."""

import FreeCAD
import Part

from surfcomp.app import features, precheck
from surfcomp.io.readers import read_any
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP


def test_points_on_the_face_and_off_it(fresh_doc):
    doc = fresh_doc
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    assert precheck.nominal_candidate(doc) == (nom, "Face1")
    assert precheck.check_on_face(nom, None, read_any(EXAMPLE_CSV)) == ([], [])
    # the coordinates read in um: 1000 x smaller, all near one corner (5 beyond the border),
    # and on the face once multiplied by 1000
    errors, _ = precheck.check_on_face(nom, "Face1", read_any(EXAMPLE_CSV, units="um"))
    assert errors == ["%s: the 2025 points span 0.06177 mm where the face spans 64.27 mm, and "
                      "multiplied by 1000 they lie on it: the file's coordinates are in mm, not "
                      "um (give the unit: units mm, or a column name like 'x_nom [mm]')"
                      % EXAMPLE_CSV]
    # the nominal moved: the points (in document coordinates) are 5 mm above the face
    nom.Placement = FreeCAD.Placement(FreeCAD.Vector(0, 0, -5), FreeCAD.Rotation())
    errors, _ = precheck.check_on_face(nom, "Face1", read_any(EXAMPLE_CSV))
    assert len(errors) == 1 and "is 4.9999 mm from the face" in errors[0]  # along the normal


def test_the_candidate_is_the_only_plain_object_with_a_bspline_face(fresh_doc):
    doc = fresh_doc
    nom = doc.addObject("Part::Feature", "Nominal")
    nom.Shape = Part.read(EXAMPLE_STEP)
    meas = features.make_measurement(doc, EXAMPLE_CSV)
    comp = features.make_compensation(doc, nom, "Face1", meas)
    doc.recompute()
    assert not comp.Shape.isNull()
    assert precheck.nominal_candidate(doc) == (nom, "Face1")   # the compensation left out
    box = doc.addObject("Part::Feature", "Box")
    box.Shape = Part.makeBox(1, 1, 1)                           # no B-spline face
    assert precheck.nominal_candidate(doc) == (nom, "Face1")
    other = doc.addObject("Part::Feature", "Other")
    other.Shape = Part.read(EXAMPLE_STEP)
    assert precheck.nominal_candidate(doc) is None              # two: the user selects one
