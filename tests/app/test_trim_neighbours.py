# SPDX-License-Identifier: LGPL-2.1-or-later
"""Issue 17: a face of a solid whose neighbours all meet it tangentially: B-spline faces of
axom's ``boxed_sphere.step`` (fillets, blends, a sphere half) and of PyGeM's pipe sewn into a
solid; the neighbours are re-trimmed, or the correction must vanish where they are tangent.
"""

import os

import numpy as np
import Part
import pytest

from surfcomp.app.file_route import Job, run_job
from surfcomp.app.nominal import nominal_from_face
from surfcomp.core.compensation.pipeline import Options
from surfcomp.errors import GeometryError
from tests.app.helpers import run_in_process
from tests.app.trim_cases import (
    BOXED_SPHERE,
    UM,
    brep_file,
    bump,
    flux_change,
    max_tolerance,
    measure,
    other_faces_untouched,
    pipe_solid,
    radial_field,
    raw_deviation,
    realised_ok,
    run_cli,
    z_field,
)

# -- real parts: every neighbour tangent (boxed_sphere), a sewn pipe --------------------------

@pytest.fixture(scope="module")
def boxed_sphere():
    from surfcomp.app.cadread import read_cad

    shape = read_cad(BOXED_SPHERE)
    # the file is in cm; OCCT reads it in mm: a sphere of radius 5 mm in a 10 mm box
    sphere = min(shape.Solids, key=lambda s: len(s.Faces))
    assert sphere.Volume == pytest.approx(4 / 3 * np.pi * 5.0 ** 3, rel=1e-3)
    assert shape.BoundBox.XLength == pytest.approx(10.0, abs=1e-6)
    return shape


#: a fillet (4 edges), a trimmed blend (9 edges, half of its UV box), a sphere half (two
#: poles), each meeting all its neighbours tangentially
SPHERE_FACES = ("Face5", "Face8", "Face191")


@pytest.mark.parametrize("face", SPHERE_FACES)
def test_tangent_neighbours_need_a_vanishing_correction(boxed_sphere, face, tmp_path):
    """Where the correction vanishes along the tangent edges, the face is replaced without
    re-trimming; a constant 14 um one gives the clear error, nothing is written."""
    k = int(face[4:]) - 1
    shape = boxed_sphere
    nominal = nominal_from_face(shape.Faces[k], face_name=face, shape=shape)
    P, N, U, V, d = measure(tmp_path / "bump.csv", nominal, 21, bump(nominal), margin=0.02)
    comp, rep = run_job(Job(nominal=BOXED_SPHERE, measurements=str(tmp_path / "bump.csv"),
                            face=face, output=str(tmp_path / "out.brep"),
                            options=Options(method="raw")))
    out = Part.read(str(tmp_path / "out.brep"))
    info = rep["output_shape"]
    assert info["kind"] == "shape" and info["retrimmed_faces"] == []
    assert out.isValid() and len(out.Faces) == len(shape.Faces) == 192
    assert len(out.Solids) == 2 and all(s.isClosed() for s in out.Shells)
    new = out.Faces[k]
    assert len(new.Edges) == len(shape.Faces[k].Edges)
    # the file's own tolerances (up to 0.06 mm, from Rhino) stay; nothing is added
    assert max_tolerance(new) <= max_tolerance(shape.Faces[k]) + 1e-4
    other_faces_untouched(shape, out, {k})
    # no neighbour moved: the volume change is the flux of any field of divergence 1
    # through the face (before and after), here (0, 0, z)
    exact = flux_change(shape.Faces[k], new, z_field)
    assert info["volume_change_mm3"] == pytest.approx(exact, rel=0.005)
    assert exact == pytest.approx(-info["correction_integral_mm3"], rel=0.02)
    on_face = np.array([nominal.bspline_face.isPartOfDomain(u, v)
                        for u, v in zip(U.ravel(), V.ravel())])
    assert realised_ok(new, P, N, d, on_face, reach=0.05) <= 0.1 * UM
    assert rep["corrected_face"]["max_error_at_points_mm"] <= 0.1 * UM
    # a constant correction lifts the face off its tangent neighbours
    measure(tmp_path / "const.csv", nominal, 21, lambda P, U, V: np.full(U.shape, 0.014),
            margin=0.02)
    with pytest.raises(GeometryError, match=r"Edge\d+ between %s and Face\d+ is tangent to "
                                            r"its neighbour \(0\.\d degrees\) and the "
                                            r"corrected face lies up to 14\.\d\d um off"
                       % face):
        run_job(Job(nominal=BOXED_SPHERE, measurements=str(tmp_path / "const.csv"), face=face,
                    output=str(tmp_path / "const.brep"), options=Options(method="raw")))
    assert not os.path.exists(tmp_path / "const.brep")


@pytest.fixture(scope="module")
def pipe(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("pipe")
    solid = pipe_solid()
    return solid, brep_file(solid, tmp, "pipe.brep")


def _pipe_run(pipe, k, dev, tmp_path, box=None):
    solid, src = pipe
    nominal = nominal_from_face(solid.Faces[k], face_name="Face%d" % (k + 1), shape=solid)
    P, N, U, V, d = measure(tmp_path / "m.csv", nominal, 13, dev(nominal), box=box)
    comp, rep = run_job(Job(nominal=str(src), measurements=str(tmp_path / "m.csv"),
                            face="Face%d" % (k + 1), output=str(tmp_path / "out.brep"),
                            options=Options(method="raw")))
    out = Part.read(str(tmp_path / "out.brep"))
    assert out.isValid() and len(out.Solids) == 1 and out.Shells[0].isClosed()
    assert len(out.Faces) == 6 and max_tolerance(out) <= 1e-4
    assert realised_ok(out.Faces[k], P, N, d) <= 0.1 * UM
    assert rep["corrected_face"]["max_error_at_points_mm"] <= 0.1 * UM
    return out, rep["output_shape"]


def _across(nominal, amplitude=0.014):
    """Vanishes along the quarter's long edges (tangent to the next quarters), not at its
    ends (the disks)."""
    (v0, v1) = nominal.surface.v_range
    return lambda P, U, V: amplitude * np.sin(np.pi * (V - v0) / (v1 - v0)) ** 2


def test_pipe_quarter_retrims_the_disks(pipe, tmp_path):
    solid, _ = pipe
    out, info = _pipe_run(pipe, 1, _across, tmp_path)
    assert info["retrimmed_faces"] == ["Face1", "Face3"]          # the two disks
    other_faces_untouched(solid, out, {1})
    exact = flux_change(solid.Faces[1], out.Faces[1], radial_field)
    assert exact == pytest.approx(-info["correction_integral_mm3"], rel=0.02)
    assert info["volume_change_mm3"] == pytest.approx(exact, rel=0.005)
    # the re-trimmed end of the quarter lies on OCCT's own intersection of the corrected
    # surface with the disk's plane (the reference for the Newton samples)
    disk = solid.Faces[0]
    sc = out.Faces[1].Surface
    curves = sc.intersectSS(disk.Surface, 1e-7)
    pieces = Part.Compound([c.toShape() for c in curves])
    end = [e for e in out.Faces[1].Edges if abs(e.CenterOfMass.z - disk.CenterOfMass.z) < 1.0]
    assert len(end) == 1
    dist = [pieces.distToShape(Part.Vertex(p))[0] for p in end[0].discretize(50)]
    assert max(dist) < 1e-5


def test_pipe_disk_retrims_the_four_quarters(pipe, tmp_path):
    solid, _ = pipe
    # measured inside the disk (the square inscribed in its circle)
    out, info = _pipe_run(pipe, 0, lambda nominal: lambda P, U, V: raw_deviation(P / 100.0),
                          tmp_path, box=(0.16, 0.84, 0.16, 0.84))
    assert info["retrimmed_faces"] == ["Face2", "Face4", "Face5", "Face6"]
    exact = flux_change(solid.Faces[0], out.Faces[0], z_field)
    assert exact == pytest.approx(-info["correction_integral_mm3"], rel=0.02)
    assert info["volume_change_mm3"] == pytest.approx(exact, rel=0.005)


def test_pipe_quarter_with_a_constant_correction_is_refused(pipe, tmp_path):
    solid, src = pipe
    nominal = nominal_from_face(solid.Faces[1], face_name="Face2", shape=solid)
    measure(tmp_path / "m.csv", nominal, 9, lambda P, U, V: np.full(U.shape, 0.014))
    out = run_cli("compensate", src, tmp_path / "m.csv", "--face", "Face2", "-o",
                  tmp_path / "out.brep", "--method", "raw", "--quiet")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "between Face2 and Face" in out.stderr and "14.00 um off" in out.stderr
    assert not os.path.exists(tmp_path / "out.brep")
    # the face alone is fine
    out = run_in_process("compensate", src, tmp_path / "m.csv", "--face", "Face2", "-o",
                         tmp_path / "face.brep", "--method", "raw", "--face-only", "--quiet")
    assert out.returncode == 0, out.stderr
    assert len(Part.read(str(tmp_path / "face.brep")).Faces) == 1
