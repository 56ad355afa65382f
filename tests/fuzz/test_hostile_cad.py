# SPDX-License-Identifier: LGPL-2.1-or-later
"""Hostile and borderline CAD files (issue 25, items 6 and 8): every one ends in a clear
exit 2 naming the file, or, when the face is valid, in a correct result; never a
traceback.

- B-spline surfaces of a degree above OpenCASCADE's 25 (in a BREP and in an FCStd), poles
  that are infinite (STEP ``1.E400`` and other spellings), NaN or beyond any machined part;
- a full sphere (a closed surface with a seam): refused before the work when a corrected
  face is to be written, inspected like any face;
- a cone sector with its apex in the face: compensated, the apex's normal the limit of its
  neighbours' as at a sphere's pole;
- OpenCASCADE's writers on a full disk; a ``SURFCOMP_CAD_TIMEOUT`` that is no time limit.
"""

import json
import os
import subprocess

import numpy as np
import pytest

from . import inputs as I
from .harness import EXAMPLE_STEP, Case, run_case

MEAS = I.put("m.csv", I.csv)


def _part():
    from surfcomp.app import fcenv

    fcenv.import_freecad()
    import Part

    return Part


def _brep_bspline(degree_u, pole=None):
    """BREP text of a lone B-spline face of degree ``degree_u`` x 2 over [0, 20] x [0, 20]
    mm, written by hand as OpenCASCADE's BREP format spells it (its own writer refuses a
    degree above 25); ``pole`` replaces the z text of pole (1, 1)."""
    Part = _part()
    import FreeCAD

    b = Part.BSplineSurface()
    b.buildFromPolesMultsKnots([[FreeCAD.Vector(10 * i, 10 * j, 0) for j in range(3)]
                                for i in range(3)], [3, 3], [3, 3], [0, 1], [0, 1],
                               False, False, 2, 2)
    text = _brep_text(b.toShape())
    head, rest = text.split("Surfaces 1\n")
    _, tail = rest.split("\nTriangulations 0")
    rows = ["9 0 0 0 0 %d 2 %d 3 2 2" % (degree_u, degree_u + 1)]
    for i in range(degree_u + 1):
        rows.append("  ".join("%.17g %d %s" % (20.0 * i / degree_u, 10 * j,
                                               pole if pole and i == j == 1 else "0")
                              for j in range(3)))
    body = "\n".join(rows) + "\n\n0 %d\n1 %d\n\n0 3\n1 3\n" % (degree_u + 1, degree_u + 1)
    return head + "Surfaces 1\n" + body + "\nTriangulations 0" + tail


def _brep_text(shape):
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "s.brep")
        shape.exportBrep(path)
        with open(path, encoding="ascii") as fh:
            return fh.read()


def _step_with_pole(text):
    """The example STEP with the z of one pole (``#45``, pole (1, 1)) spelled ``text``."""
    out, count = [], 0
    for line in I.step_text().split("\n"):
        if line.startswith("#45 = CARTESIAN_POINT("):
            line = line.rsplit(",", 1)[0] + ",%s));" % text
            count += 1
        out.append(line)
    assert count == 1
    return "\n".join(out)


def _measure(face, n=9, inset=0.02):
    """CSV of an n x n grid of nominal points on ``face`` with its outward normals and a
    smooth deviation (mm); points of a collapsed edge only once."""
    u0, u1, v0, v1 = face.ParameterRange
    du, dv = inset * (u1 - u0), inset * (v1 - v0)
    rows, seen = [I.HEADER], set()
    for u in np.linspace(u0 + du, u1 - du, n):
        for v in np.linspace(v0, v1 - dv, n):
            p = face.valueAt(u, v)
            key = tuple(round(x, 4) for x in p)
            if key in seen:
                continue
            seen.add(key)
            nn = face.normalAt(u, v)
            rows.append("%d,%.6f,%.6f,%.6f,%.9f,%.9f,%.9f,%.6f"
                        % (len(rows), p.x, p.y, p.z, nn.x, nn.y, nn.z,
                           0.005 * np.sin(2 * u + v)))
    return "\n".join(rows) + "\n"


def _solid_face(name, make, pick):
    """Set-up step: the face ``pick`` of the solid ``make()`` as STEP ``name`` and its
    measurements as ``m.csv``."""
    def step(sandbox):
        Part = _part()
        face = next(f for f in make(Part).Faces if pick in f.Surface.TypeId)
        face.exportStep(os.path.join(sandbox, name))
        read = Part.read(os.path.join(sandbox, name)).Faces[0]
        with open(os.path.join(sandbox, "m.csv"), "w", encoding="utf-8") as fh:
            fh.write(_measure(read))
    return step


def _cone(Part):
    import FreeCAD

    return Part.makeCone(0, 12, 9, FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(0, 0, 1), 90)


def _sphere(Part):
    return Part.makeSphere(7.5)


def _fcstd_with_brep(brep):
    """The fuzz document with every shape file replaced by the BREP text ``brep`` (which
    file holds the nominal differs between FreeCAD versions)."""
    def data():
        import io
        import zipfile

        with zipfile.ZipFile(io.BytesIO(I.document_bytes())) as z:
            shapes = [n for n in z.namelist() if n.lower().endswith((".brp", ".brep"))]
        assert shapes
        return I.rezip(drop=shapes, extra=[(n, brep.encode()) for n in shapes])
    return data


def _cases():
    deg = "a B-spline of degree above 25"
    yield Case("brep-degree-30", ("inspect", "n.brep", "m.csv", "--quiet"),
               I.setup(I.put("n.brep", lambda: _brep_bspline(30)), MEAS),
               file="n.brep", says=(deg,))
    yield Case("brep-degree-26", ("compensate", "n.brp", "m.csv", "-o", "c.step", "--quiet"),
               I.setup(I.put("n.brp", lambda: _brep_bspline(26)), MEAS),
               file="n.brp", says=(deg,))
    # FreeCAD 0.20 restores such a shape as a null shape, others may keep the face
    for obj in ((), ("--object", "Nominal")):
        yield Case("fcstd-degree-28" + "-object" * bool(obj),
                   ("inspect", "d.FCStd", "m.csv", "--quiet") + obj,
                   I.setup(I.put("d.FCStd", _fcstd_with_brep(_brep_bspline(28))), MEAS),
                   file="d.FCStd")
    for name, text in (("inf", "inf"), ("minus-inf", "-INF"), ("nan", "nan"),
                       ("1e999", "1e999")):
        yield Case("brep-pole-" + name, ("inspect", "n.brep", "m.csv", "--quiet"),
                   I.setup(I.put("n.brep", lambda text=text: _brep_bspline(3, text)), MEAS),
                   file="n.brep", says=("a pole that is NaN or infinite at pole (1, 1)",))
    yield Case("brep-pole-beyond-10-km", ("inspect", "n.brep", "m.csv", "--quiet"),
               I.setup(I.put("n.brep", lambda: _brep_bspline(3, "-3.5e11")), MEAS),
               file="n.brep", says=("a pole coordinate beyond 1e+07 mm at pole (1, 1)",))
    for name, text in (("1.E400", "1.E400"), ("-9.99E+999", "-9.99E+999"),
                       ("4.E+308", "4.E+308")):
        yield Case("step-pole-" + name, ("compensate", "n.step", "m.csv", "-o", "c.step",
                                         "--quiet"),
                   I.setup(I.put("n.step", lambda text=text: _step_with_pole(text)), MEAS),
                   file="n.step", says=("a pole that is NaN or infinite at pole (1, 1)",))
    yield Case("full-sphere-compensated", ("compensate", "s.step", "m.csv", "-o", "c.step",
                                           "--report", "r.json", "--quiet"),
               _solid_face("s.step", _sphere, "Sphere"), file="s.step",
               says=("the face has a seam", "expected an open face"))


@pytest.mark.parametrize("case", list(_cases()), ids=str)
def test_case(case, tmp_path):
    run_case(case, tmp_path / "case")


def test_full_sphere_is_inspected(tmp_path):
    """The sphere's poles (collapsed edges) and seam are no obstacle to the deviations: the
    measured 5 um sine comes back at every point."""
    res = run_case(Case("sphere-inspect", ("inspect", "s.step", "m.csv", "--report", "r.json",
                                           "--quiet"),
                        _solid_face("s.step", _sphere, "Sphere"), rc=0, writes=("r.json",)),
                   tmp_path)
    assert "Traceback" not in res.err
    with open(tmp_path / "r.json", encoding="utf-8") as fh:
        rep = json.load(fh)
    meas = np.loadtxt(tmp_path / "m.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(rep["points"]["deviation"], meas[:, 7], atol=1e-6)


def test_cone_sector_with_its_apex_is_compensated(tmp_path):
    """A 90 degree cone sector whose apex is a corner of the face (Su x Sv = 0 there):
    compensated like a face with a sphere's pole, the correction met at the measured points
    within 0.1 um."""
    run_case(Case("cone-apex", ("compensate", "k.step", "m.csv", "-o", "c.step", "--report",
                                "r.json", "--quiet"),
                  _solid_face("k.step", _cone, "Cone"), rc=0, writes=("c.step", "r.json")),
             tmp_path)
    with open(tmp_path / "r.json", encoding="utf-8") as fh:
        rep = json.load(fh)
    assert rep["corrected_face"]["max_error_at_points_mm"] < 1e-4
    meas = np.loadtxt(tmp_path / "m.csv", delimiter=",", skiprows=1)
    assert np.isclose(meas[:, 1:4], 0, atol=1e-9).all(axis=1).sum() == 1   # the apex
    np.testing.assert_allclose(rep["points"]["deviation"], meas[:, 7], atol=1e-6)
    assert np.isfinite(rep["points"]["normal"]).all()


@pytest.mark.parametrize("value", ["nan", "-inf", "", "0", "-30", "1e12", "15 min"])
def test_cad_timeout_that_is_no_time_limit(value, tmp_path, monkeypatch):
    monkeypatch.setenv("SURFCOMP_CAD_TIMEOUT", value)
    text = run_case(Case("timeout", ("inspect", "n.step", "m.csv", "--quiet"),
                         I.setup(I.copy("n.step", EXAMPLE_STEP), MEAS)), tmp_path).err
    assert "SURFCOMP_CAD_TIMEOUT=%r is not a time limit" % value in text


@pytest.fixture
def full_disk(tmp_path):
    """A 32 KB file system (tmpfs) holding the outputs; skipped where mounting is not
    allowed."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=32k", "tmpfs", str(mnt)],
                      capture_output=True).returncode:
        pytest.skip("cannot mount a small tmpfs here (needs root)")
    try:
        yield mnt
    finally:
        subprocess.run(["umount", str(mnt)], check=True)


@pytest.mark.parametrize("ext", ["iges", "brep", "step"])
def test_opencascade_writer_on_a_full_disk(ext, full_disk, tmp_path):
    """The cone's corrected face (rational, trimmed: written by OpenCASCADE, not by
    surfcomp's own STEP writer) on a file system without room: exit 2 naming the output,
    nothing left there."""
    sandbox = tmp_path / "case"
    os.makedirs(sandbox)
    _solid_face("k.step", _cone, "Cone")(str(sandbox))
    out = os.path.join(str(full_disk), "c." + ext)
    res = run_case(Case("full", ("compensate", "k.step", "m.csv", "-o", out, "--quiet"),
                        file=out, says=("OpenCASCADE could not write the %s file"
                                        % ext.upper(), "a full disk")), sandbox)
    assert "Traceback" not in res.err
    assert os.listdir(full_disk) == []


@pytest.mark.parametrize("raw", [b"n\xff\xfe.step", b"\xe9t\xe9 latin-1.stp"])
def test_nominal_whose_name_is_not_utf8(raw, tmp_path):
    """A name in another encoding than UTF-8 (Python holds its bytes as surrogates): read
    through the CAD child, the reports written, the name kept in the JSON report and shown
    with ``\\udcXX`` escapes in the HTML one."""
    name = os.fsdecode(raw)
    run_case(Case("latin-1-name", ("inspect", name, "m.csv", "--report", "r.json", "--html",
                                   "r.html", "--quiet"),
                  I.setup(I.copy(name, EXAMPLE_STEP), MEAS), rc=0,
                  writes=("r.json", "r.html")), tmp_path)
    with open(tmp_path / "r.json", encoding="utf-8") as fh:
        rep = json.load(fh)
    assert rep["inputs"]["nominal"]["path"] == os.path.join(str(tmp_path), name)
    html = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert name.encode("utf-8", "backslashreplace").decode("ascii", "replace") in html
