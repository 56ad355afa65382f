# SPDX-License-Identifier: LGPL-2.1-or-later
"""surfcomp.io.step_face read by OpenCASCADE (Part.read and FreeCAD's Import module) against
OpenCASCADE's own STEP of the same face, and the faces that take that route."""

import FreeCAD
import numpy as np
import Part
import pytest

from surfcomp.app.convert import surface_from_part, surface_to_part
from surfcomp.app.file_route import Job, run_job
from surfcomp.app.shapes import natural_face, rebuild_face
from surfcomp.core.surface.bspline import Surface
from surfcomp.io.step_face import write_natural_face
from tests.app.helpers import EXAMPLE_CSV, EXAMPLE_STEP
from tests.pure.surfaces import quarter_cylinder, random_surface


def _sample(face, n=7):
    u0, u1, v0, v1 = face.ParameterRange
    uv = [(u, v) for u in np.linspace(u0, u1, n) for v in np.linspace(v0, v1, n)]
    points = np.array([tuple(face.valueAt(u, v)) for u, v in uv])
    normals = np.array([tuple(face.normalAt(u, v)) for u, v in uv])
    return points, normals


@pytest.mark.parametrize("reverse", [False, True])
def test_occt_reads_the_face_it_would_have_written(tmp_path, reverse):
    s = random_surface(np.random.default_rng(11), nu=40, nv=31)
    face = surface_to_part(s).toShape()
    if reverse:
        face.reverse()
    ours, theirs = tmp_path / "ours.step", tmp_path / "theirs.step"
    write_natural_face(str(ours), s, reverse, 1e-7)
    face.exportStep(str(theirs))
    a, b = Part.read(str(ours)), Part.read(str(theirs))
    assert a.isValid() and len(a.Faces) == 1 and len(a.Edges) == 4 and len(a.Vertexes) == 4
    fa, fb = a.Faces[0], b.Faces[0]
    assert fa.Orientation == fb.Orientation == ("Reversed" if reverse else "Forward")
    got = surface_from_part(fa.Surface)
    assert np.max(np.abs(got.poles - s.poles)) < 7.5e-13
    assert got.knots_u.tolist() == s.knots_u.tolist()
    assert got.knots_v.tolist() == s.knots_v.tolist()
    assert fa.ParameterRange == pytest.approx(fb.ParameterRange, abs=0)
    # against the face in memory: closer than OpenCASCADE's own file (13 digits) comes
    (p0, n0), (pa, na), (pb, _) = _sample(face), _sample(fa), _sample(fb)
    ours_err, theirs_err = np.max(np.abs(pa - p0)), np.max(np.abs(pb - p0))
    assert ours_err < 1e-11 and ours_err <= theirs_err
    assert np.max(np.abs(na - n0)) < 1e-12
    assert abs(fa.Area / face.Area - 1) < 1e-12
    assert max(e.Tolerance for e in a.Edges) <= 1e-7
    # the edges lie on the face's own boundary, end to end
    for ea in a.Edges:
        near = [e for e in face.Edges if e.distToShape(ea)[0] < 1e-9]
        assert len(near) >= 1
        assert max(min(e.distToShape(Part.Vertex(ea.valueAt(t)))[0] for e in near)
                   for t in np.linspace(*ea.ParameterRange, 9)) < 1e-11


def test_freecad_import_names_the_object_after_the_file(tmp_path):
    import Import

    s = random_surface(np.random.default_rng(5))
    path = tmp_path / "corrected blade.step"
    write_natural_face(str(path), s)
    named = tmp_path / "named.step"
    write_natural_face(str(named), s, name="Schaufel \u00e4 '3'")
    assert rb"PRODUCT('Schaufel \X2\00E4\X0\ ''3'''" in named.read_bytes()
    doc = FreeCAD.newDocument("stepface")
    try:
        Import.insert(str(path), doc.Name)
        objs = [o for o in doc.Objects if hasattr(o, "Shape") and not o.Shape.isNull()]
        assert [o.Label for o in objs] == ["corrected blade"]
        assert abs(objs[0].Shape.Area / surface_to_part(s).toShape().Area - 1) < 1e-12
        Import.insert(str(named), doc.Name)      # the encoded name comes back decoded
        assert doc.Objects[-1].Label == "Schaufel \u00e4 '3'"
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_natural_face_only_for_the_face_bounded_by_its_knot_domain():
    s = random_surface(np.random.default_rng(9))
    bs = surface_to_part(s)
    whole = bs.toShape()
    assert natural_face(whole, s)
    assert natural_face(rebuild_face(whole, bs), s)       # the corrected face's route
    u0, u1, v0, v1 = whole.ParameterRange
    assert not natural_face(bs.toShape(u0, 0.9 * u1, v0, v1), s)
    circle = Part.Geom2d.Circle2d(FreeCAD.Base.Vector2d(0.5, 0.5), 0.1)
    holed = whole.copy()
    holed = holed.cutHoles([Part.Wire(circle.toShape(bs))]) or holed
    assert len(holed.Wires) == 2 and not natural_face(holed, s)
    collapsed = Surface(s.poles.copy(), s.knots_u, s.knots_v, 3, 2)
    collapsed.poles[0, :] = collapsed.poles[0, 0]        # the side u = u0 is one point
    face = surface_to_part(collapsed).toShape()
    assert sum(e.Degenerated for e in face.Edges) == 1 and not natural_face(face, collapsed)
    rational = quarter_cylinder()
    assert not natural_face(surface_to_part(rational).toShape(), rational)
    ku = s.knots_u.copy()
    ku[0] = -0.2
    unclamped = Surface(s.poles, ku, s.knots_v, 3, 2)
    assert not natural_face(surface_to_part(unclamped).toShape(), unclamped)


def test_the_job_writes_the_example_face_from_its_poles(tmp_path):
    job = Job(command="compensate", nominal=EXAMPLE_STEP, measurements=EXAMPLE_CSV,
              output=str(tmp_path / "c.step"))
    comp, rep = run_job(job)
    data = (tmp_path / "c.step").read_bytes()
    assert b"'surfcomp " in data[:400] and b"Open CASCADE" not in data
    assert b"PRODUCT('c','c'" in data           # the file's name, not the staged file's
    assert rep["output_shape"]["file_bytes"] == len(data)
    face = Part.read(str(tmp_path / "c.step")).Faces[0]
    got = surface_from_part(face.Surface)
    assert got.poles.shape == comp.corrected.poles.shape == (49, 49, 3)
    assert np.max(np.abs(got.poles - comp.corrected.poles)) < 7.5e-13
    # the same file OpenCASCADE writes for that face, read back
    job.output = str(tmp_path / "c.brep")
    run_job(job)
    brep = Part.read(job.output).Faces[0]
    (pa, na), (pb, nb) = _sample(face), _sample(brep)
    assert np.max(np.abs(pa - pb)) < 1e-11 and np.max(np.abs(na - nb)) < 1e-10
