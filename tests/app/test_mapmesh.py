# SPDX-License-Identifier: LGPL-2.1-or-later
"""The mesh a colour map is drawn on (surfcomp.app.mapmesh), headless: trimmed to the face
(no triangle in a hole), lifted in front of the face past the largest correction, the
markers further; the nodes outside the trim are those of the compensation's warning; and
the messages of points off the face name what the reader can change (the command line's
option or the compensation's property)."""

import FreeCAD
import numpy as np
import Part
import pytest
from numpy.testing import assert_allclose

from surfcomp.app import features, mapmesh
from surfcomp.core.compensation.pipeline import Options, option_name
from surfcomp.core.surface import bspline
from surfcomp.errors import MeasurementFileError
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP

HOLE = ((0.5, 0.55), 0.1)


def holed_face():
    bs = Part.read(EXAMPLE_STEP).Faces[0].Surface
    face = Part.Face(bs)
    h = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(*HOLE[0]), HOLE[1])
    face.cutHoles([Part.Wire([h.toShape(bs)])])
    face.fix(1e-7, 1e-7, 1e-7)
    assert face.isValid()
    return face


@pytest.fixture(scope="module")
def holed():
    doc = FreeCAD.newDocument("mapmesh")
    nom = doc.addObject("Part::Feature", "Holed")
    nom.Shape = holed_face()
    m = features.make_measurement(doc, EXAMPLE_CSV)
    comp = features.make_compensation(doc, nom, "Face1", m)
    doc.recompute()
    assert "Invalid" not in comp.State
    yield comp
    FreeCAD.closeDocument(doc.Name)


def test_no_triangle_in_the_hole_and_the_rest_kept(holed):
    mesh = mapmesh.map_mesh(holed)
    u, v, tri = mesh["u"], mesh["v"], mesh["triangles"]
    mu, mv = u[tri].mean(axis=1), v[tri].mean(axis=1)
    r = np.hypot(mu - HOLE[0][0], mv - HOLE[0][1])
    assert not (r < HOLE[1] - 0.01).any()
    # the triangles left out are those of the hole: its share of the (u, v) square
    total = 2 * (int(np.sqrt(len(u))) - 1) ** 2
    assert_allclose(mesh["trimmed"] / total, np.pi * HOLE[1] ** 2, rtol=0.1)
    assert len(tri) + mesh["trimmed"] == total


def test_outside_nodes_are_the_warnings_points(holed):
    mesh = mapmesh.map_mesh(holed)
    warning = [w for w in holed.Warnings if "outside its trimmed boundary" in w][0]
    count = int(warning.split(": ", 1)[1].split(" of ")[0])
    assert len(mesh["outside"]) == count > 10
    U = np.array(holed.U)[mesh["outside"]]
    V = np.array(holed.V)[mesh["outside"]]
    assert (np.hypot(U - HOLE[0][0], V - HOLE[0][1]) < HOLE[1] + 1e-9).all()


def test_map_lifted_past_the_largest_correction_markers_further(holed):
    mesh = mapmesh.map_mesh(holed)
    d = mapmesh.map_data(holed, "deviation", mesh=mesh)
    corr = np.abs(np.array(holed.Correction))
    corr = corr[np.isfinite(corr)]
    assert d["lift"] > 1.4 * corr.max() and d["lift"] < 1.6 * corr.max() + 1e-3 * mesh["size"]
    # every vertex moved by the lift along the outward normal of the face
    nominal, _pl = features.nominal_of(holed)
    n = bspline.normals(nominal.surface, mesh["u"], mesh["v"]) * nominal.outward
    assert_allclose(np.einsum("ij,ij->i", d["points"] - mesh["points"], n), d["lift"],
                    atol=1e-9)
    nodes = np.array(holed.Nodes).reshape(-1, 3)
    dev = np.array(holed.Deviation)
    normals = np.array(holed.Normals).reshape(-1, 3)
    up = np.einsum("ij,ij->i", d["markers"] - nodes[np.isfinite(dev)], normals[np.isfinite(dev)])
    assert_allclose(up, d["lift"] + mapmesh.MARKER_LIFT * mesh["size"], atol=1e-9)


def test_option_names_per_reader():
    assert option_name(Options(), "max_offset") == "max_offset"
    assert option_name(Options(context="document"), "max_offset") == \
        "the compensation's MaxOffset"
    assert option_name(Options(context="document"), "flip_normals") == "the compensation's Flip"


def test_points_beyond_a_disc_face_refused_as_beyond_its_border():
    doc = FreeCAD.newDocument("disc")
    try:
        bs = Part.read(EXAMPLE_STEP).Faces[0].Surface
        c = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(0.5, 0.5), 0.35)
        nom = doc.addObject("Part::Feature", "Disc")
        nom.Shape = Part.Face(bs, Part.Wire([c.toShape(bs)]))
        comp = features.make_compensation(doc, nom, "Face1",
                                          features.make_measurement(doc, EXAMPLE_CSV))
        with pytest.raises(MeasurementFileError) as err:
            features._compute(comp)
        text = str(err.value)
        assert "lies beyond the border of the face" in text and "--" not in text
        assert "measurements.csv:" in text
    finally:
        FreeCAD.closeDocument(doc.Name)
