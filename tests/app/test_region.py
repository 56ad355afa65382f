# SPDX-License-Identifier: LGPL-2.1-or-later
"""Region compensation (issue 30): a solid whose top is two B-spline faces meeting G1, with a
field largest on their common edge, through the command line; bad input refused."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from tests.app import region_parts as rp
from tests.app.helpers import run_in_process

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _cli(*args):
    """A refused run, as a process: its exit code and message."""
    return subprocess.run([sys.executable, "-m", "surfcomp", "compensate", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)


def _run(*args):
    """A run whose results the test checks, in this process (tests/app/helpers.py)."""
    return run_in_process("compensate", *args)


@pytest.fixture(scope="module")
def g1_part(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("region")
    return (tmp,) + rp.g1_step(tmp, 3000, seed=1)


@pytest.fixture(scope="module")
def g1_run(g1_part):
    """The ridge corrected on the G1 top (``--faces auto``), the run two tests check:
    ``(result, output, report)``."""
    tmp, step, csv = g1_part[:3]
    out, rep = str(tmp / "out.step"), str(tmp / "out.json")
    return _run(step, csv, "--faces", "auto", "-o", out, "--report", rep), out, rep


def test_g1_top_continuity_fidelity_volume(g1_part, g1_run):
    import Part

    _tmp, _step, _csv, solid, _pts, _nrm, _dev = g1_part
    r, out, rep = g1_run
    assert r.returncode == 0, r.stderr
    assert "points per face: Face1 3000, Face2 3000; on no face: 0" in r.stdout
    assert "edge Face1-Face2 (G1): largest gap" in r.stdout
    data = json.load(open(rep))
    (edge,) = data["edges"]
    assert edge["g1"] and edge["nominal_angle_deg"] < 1e-6
    assert edge["max_gap_um"] <= 0.1
    assert edge["max_angle_deg"] <= 0.05
    for f in data["faces"]:
        assert f["points"] == 3000
        assert f["max_realised_minus_intended_um"] <= 0.1
        assert f["poles"][0] * f["poles"][1] <= 64 * 64
    o = data["output"]
    assert o["kind"] == "solid" and o["faces"] == 7
    assert o["edge_tolerance_mm"] <= 1e-4
    assert o["relative_error"] <= 0.02
    # the largest correction, 20 um on the common edge, moved it
    assert o["integral_mm3"] == pytest.approx(-0.64, abs=0.02)
    back = Part.read(out)
    assert len(back.Solids) == 1 and back.Solids[0].isValid()
    assert len(back.Faces) == 7
    assert back.Solids[0].Volume - solid.Volume == pytest.approx(o["change_mm3"], abs=1e-3)
    # the common edge moved inwards by the ridge's top (20 um) at its middle
    top = [f for f in back.Faces if f.Surface.TypeId == "Part::GeomBSplineSurface"]
    face = solid.Faces[0]
    p = np.array(tuple(face.Surface.value(10.0, 5.0)))
    n = np.array(tuple(face.normalAt(10.0, 5.0)))
    assert rp.ridge_field(p[None])[0] == pytest.approx(0.02, abs=1e-3)
    moved = min(f.distToShape(Part.Vertex(*(p - 0.02 * n)))[0] for f in top)
    # the mask filter and the 1.15 mm kernel flatten the 3 mm wide ridge by about 0.2 um
    assert moved <= 0.5e-3


def test_zero_correction_gives_the_nominal(g1_part):
    import Part

    tmp, step, csv, solid, pts, nrm, _dev = g1_part
    zero = str(tmp / "zero.csv")
    rp.write_csv(zero, pts, nrm, np.zeros(len(pts)))
    out = str(tmp / "zero.step")
    r = _run(step, zero, "--faces", "Face1,Face2", "-o", out)
    assert r.returncode == 0, r.stderr
    back = Part.read(out)
    assert back.Solids[0].Volume == pytest.approx(solid.Volume, abs=1e-9)
    for a in solid.Faces[:2]:
        b = min(back.Faces, key=lambda f: f.distToShape(a)[0] + abs(f.Area - a.Area))
        assert b.Surface.NbUPoles == a.Surface.NbUPoles
        assert b.Surface.NbVPoles == a.Surface.NbVPoles
        np.testing.assert_allclose(np.array([tuple(p) for r in b.Surface.getPoles() for p in r]),
                                   np.array([tuple(p) for r in a.Surface.getPoles() for p in r]),
                                   atol=1e-12)


def test_deviations_along_inward_normals_read_the_same(g1_part, g1_run):
    """A deviation is along its given normal: Face2's points given with inward normals and
    negated deviations are the same readings, and correct the faces alike (the plain
    readings' run is the one the G1 test checks, the same command)."""
    tmp, step, _csv, _solid, pts, nrm, dev = g1_part
    flip = np.where(pts[:, 0] > 10.0, -1.0, 1.0)
    inward = str(tmp / "inward.csv")
    rp.write_csv(inward, pts, nrm * flip[:, None], dev * flip)
    rep = str(tmp / "inward.json")
    r = _run(step, inward, "--faces", "auto", "-o", str(tmp / "inward.step"), "--report", rep)
    assert r.returncode == 0, r.stderr
    assert g1_run[0].returncode == 0, g1_run[0].stderr
    a, b = json.load(open(g1_run[2])), json.load(open(rep))
    assert b["output"]["change_mm3"] == pytest.approx(a["output"]["change_mm3"], abs=1e-12)
    assert b["output"]["change_mm3"] == pytest.approx(-0.64, abs=0.03)
    for fa, fb in zip(a["faces"], b["faces"]):
        assert fb["max_realised_minus_intended_um"] == pytest.approx(
            fa["max_realised_minus_intended_um"], abs=1e-9)


def test_min_coverage_names_the_face(g1_part):
    tmp, step, csv, _solid, pts, nrm, dev = g1_part
    keep = ~((pts[:, 0] > 10) & (pts[:, 1] > 3))      # Face2 measured on its y < 3 strip
    part = str(tmp / "part.csv")
    rp.write_csv(part, pts[keep], nrm[keep], dev[keep])
    out = str(tmp / "cov.step")
    r = _cli(step, part, "--faces", "Face1,Face2", "-o", out, "--min-coverage", "0.6")
    assert r.returncode == 2
    assert "Face2: the points cover" in r.stderr and "--min-coverage 60 %" in r.stderr
    assert not os.path.exists(out)


def test_straddling_step_refused(g1_part):
    tmp, step, csv, _solid, pts, nrm, dev = g1_part
    jump = dev + np.where(pts[:, 0] > 10, 0.5, 0.0)     # a 0.5 mm step at the common edge
    bad = str(tmp / "step.csv")
    rp.write_csv(bad, pts, nrm, jump)
    out = str(tmp / "jump.step")
    r = _cli(step, bad, "--faces", "auto", "-o", out, "--max-offset", "0.2")
    assert r.returncode == 2
    assert "straddling the edge between Face1 and Face2" in r.stderr
    assert not os.path.exists(out)


def test_boxed_sphere_corner_blends_and_their_fillets(tmp_path):
    """Two adjacent corner blends of boxed_sphere.step (Face8 and Face20, 23 x 23 bicubic,
    trimmed to 9 edges) and the two cylinder fillets joining them (Face12, Face24, rational),
    as a compound of the four faces; a 10 um field with a 5 um wave along the fillet runs
    across all four. The nominal blends meet the fillets at up to 0.24 deg (Rhino's
    modelling tolerance), so those edges count as sharp; the fillets meet each other G1."""
    import Part

    from tests.conftest import REALDATA

    solid = Part.read(os.path.join(REALDATA, "cad", "axom_data", "boxed_sphere.step")).Solids[0]
    faces = [solid.Faces[k - 1] for k in (8, 12, 24, 20)]
    brep = str(tmp_path / "blends.brep")
    Part.Compound(faces).exportBrep(brep)
    pts, nrm, dev = rp.sample_faces(faces, 1000, lambda p: 0.01 * (1 + 0.5 * np.sin(p[:, 1] / 3)))
    csv = str(tmp_path / "blends.csv")
    rp.write_csv(csv, pts, nrm, dev)
    out, rep = str(tmp_path / "out.brep"), str(tmp_path / "out.json")
    r = _run(brep, csv, "--faces", "auto", "-o", out, "--report", rep)
    assert r.returncode == 0, r.stderr
    assert "points per face: Face1 1000, Face2 1000, Face3 1000, Face4 1000" in r.stdout
    data = json.load(open(rep))
    edges = {tuple(e["faces"]): e for e in data["edges"]}
    assert set(edges) == {("Face1", "Face2"), ("Face2", "Face3"), ("Face3", "Face4")}
    fillets = edges[("Face2", "Face3")]
    assert fillets["g1"]
    assert fillets["max_gap_um"] <= 0.1 and fillets["max_angle_change_deg"] <= 0.05
    for key in (("Face1", "Face2"), ("Face3", "Face4")):
        e = edges[key]
        assert not e["g1"] and e["nominal_angle_deg"] == pytest.approx(0.24, abs=0.02)
        assert e["max_angle_change_deg"] <= 0.05
    # every edge closes within 0.1 um and every face meets its correction within 0.01 um
    # (the blend Face1, the solid's Face8, curves with a 0.17 mm radius next to its edge:
    # turned to the edge's miter itself it slid along itself by 8 um and missed by 0.19 um)
    for e in edges.values():
        assert e["max_gap_um"] <= 0.1
    fid = {f["face"]: f["max_realised_minus_intended_um"] for f in data["faces"]}
    for name in ("Face1", "Face2", "Face3", "Face4"):
        assert fid[name] <= 0.01
    for f in data["faces"]:
        assert f["poles"][0] * f["poles"][1] <= max(8 * f["nominal_poles"][0] *
                                                    f["nominal_poles"][1], 64 * 64)
    assert data["output"]["kind"] == "faces"
    assert len(Part.read(out).Faces) == 4


@pytest.fixture(scope="module")
def blade(tmp_path_factory):
    import Part

    from tests.conftest import REALDATA

    tmp = tmp_path_factory.mktemp("blade")
    faces = rp.blade_faces(os.path.join(REALDATA, "cad", "BladeX"))
    brep = str(tmp / "blade.brep")
    Part.Compound(faces).exportBrep(brep)
    return tmp, brep, faces


def test_blade_points_on_their_nearest_face_and_shared_edges(blade):
    """The BladeX blade's four faces: points sampled on each face are given to that face
    (also next to the knife edges, where the other side is a few um away), and the six
    edges the faces share are found although OpenCASCADE does not sew the sides."""
    import Part

    from surfcomp.app import region, region_orient

    _tmp, brep, faces = blade
    shape = Part.read(brep)
    le = rp.leading_edge(faces)
    field = rp.around_edge_field(le)
    parts = [rp.sample_faces([f], 400, field, seed=k) for k, f in enumerate(faces)]
    pts = np.concatenate([p[0] for p in parts])
    truth = np.repeat(np.arange(4), 400)
    rf = [region.region_face(shape, k) for k in range(4)]
    owner, _u, _v, normal, signed = region.locate(rf, pts, 1.0)
    np.testing.assert_array_equal(owner, truth)
    np.testing.assert_allclose(signed, 0.0, atol=1e-6)
    edges = region.shared_edges(shape, rf)
    pairs = sorted((e.a, e.b) for e in edges)
    assert pairs == [(0, 1), (0, 1), (0, 2), (0, 3), (1, 2), (1, 3)]
    # as read, the sides' normals are more than 120 deg apart along both their edges: the
    # pressure side and the tip cap face into the blade (edges run through alike by two
    # faces), and once oriented the sides meet at 22 and 143 deg at most
    assert all(e.nominal_angle > 120.0 for e in edges if (e.a, e.b) == (0, 1))
    assert region_orient.orient(shape, rf) == ["Face2", "Face3"]
    assert [f.outward for f in rf] == [1, -1, -1, 1]
    angles = sorted(e.nominal_angle for e in region.shared_edges(shape, rf) if (e.a, e.b) == (0, 1))
    assert angles == pytest.approx([22.26, 143.33], abs=0.05)


def test_orientation_of_a_compound_decided_by_its_edges_and_volume(blade):
    """The blade with every face reversed: the faces still disagree in the same pairs, and
    the enclosed volume turns the suction side and root cap back; an open set of faces
    (the boxed_sphere blends with one fillet reversed) keeps what most faces have; faces of
    one solid are left as the solid orients them."""
    import Part

    from surfcomp.app import region, region_orient
    from tests.conftest import REALDATA

    _tmp, _brep, faces = blade
    shape = Part.Compound([f.reversed() for f in faces])
    rf = [region.region_face(shape, k) for k in range(4)]
    assert region_orient.orient(shape, rf) == ["Face1", "Face4"]
    assert [f.outward for f in rf] == [1, -1, -1, 1]        # of the reversed faces
    solid = Part.read(os.path.join(REALDATA, "cad", "axom_data", "boxed_sphere.step")).Solids[0]
    blends = [solid.Faces[k - 1] for k in (8, 12, 24, 20)]
    blends[1] = blends[1].reversed()
    shape = Part.Compound(blends)
    rf = [region.region_face(shape, k) for k in range(4)]
    assert region_orient.orient(shape, rf) == ["Face2"]
    rf = [region.region_face(solid, k - 1) for k in (8, 12, 24, 20)]
    assert region_orient.orient(solid, rf) == []


def test_faces_sharing_no_edge_are_corrected_apart(blade):
    """The blade's tip and root caps (alone in their file) share no edge: the run says so
    and corrects each."""
    import Part

    tmp, _brep, faces = blade
    caps = faces[2:]
    brep = str(tmp / "caps_nominal.brep")
    Part.Compound(caps).exportBrep(brep)
    pts, nrm, dev = rp.sample_faces(caps, 600, lambda p: np.full(len(p), 0.01), seed=3)
    csv = str(tmp / "caps.csv")
    rp.write_csv(csv, pts, nrm, dev)
    out, rep = str(tmp / "caps.brep"), str(tmp / "caps.json")
    r = _run(brep, csv, "--faces", "Face1,Face2", "-o", out, "--report", rep)
    assert r.returncode == 0, r.stderr
    for name in ("Face1", "Face2"):
        assert "%s shares no edge with the other faces of the region: corrected apart" % name \
            in r.stdout
    data = json.load(open(rep))
    assert data["edges"] == []
    for f in data["faces"]:
        assert f["points"] == 600
        # known limit: the caps collapse to a point at both ends (their normals turn by up
        # to 180 deg within a few mm there: the offset of such a point is a fan, not a
        # point), where the fit is ill-conditioned: rounding-level changes of the basis move
        # this figure; measured tip 1.22 um and root 0.47 um on FreeCAD 0.20, 1.26 and
        # 1.60 um on 1.1, with the same code
        assert f["max_realised_minus_intended_um"] <= 2.0


@pytest.mark.parametrize("extra, flag", [(["--flip-normals"], "--flip-normals"),
                                         (["--tip-radius", "1"], "--tip-radius"),
                                         (["--face", "Face1"], "--face")])
def test_options_a_region_does_not_take_are_refused(g1_part, extra, flag):
    tmp, step, csv, *_ = g1_part
    out = str(tmp / "refused.step")
    r = _cli(step, csv, "--faces", "auto", "-o", out, *extra)
    assert r.returncode == 2
    assert "%s cannot be combined with --faces" % flag in r.stderr
    assert not os.path.exists(out)


def test_unknown_face_named(g1_part):
    tmp, step, csv, *_ = g1_part
    r = _cli(step, csv, "--faces", "Face1,Face9", "-o", str(tmp / "x.step"))
    assert r.returncode == 2
    assert "--faces: the shape has no Face9 (it has Face1 to Face7)" in r.stderr


def test_blade_knife_edges_and_vertices_move_as_one(blade):
    """The blade with a 30 um field around its leading edge, measured with outward normals:
    the region takes the pressure side and the tip cap against their own orientation (as
    read they face into the blade), and every shared edge stays closed to within 0.1 um
    beyond the nominal's own gap, at the edge's samples and halfway between them (before:
    the trailing edge 0.12 um, the tip cap's edges 0.34 and 2.1 um, from wrong feet of
    single edge samples, the pressure side's fold vector turning round between two samples
    and the tip cap's boundary fit; the root cap's opened by 0.5 um before the boundary
    curves were fitted on their own, the tip cap's by 4.4 um before the faces were oriented
    and 36 um with a cap's collapsed end moved by more than one vector). Beyond the zones
    where the design shortens the correction, the root cap meets it within 0.02 um; the
    sides missed by up to 0.45 um next to the trailing edge, which curls with a 0.1 mm radius
    (see docs/regions.md); with the slide's second-order term and 8 times the nominal's
    poles, within 0.1 um. Points nearer to the trailing edge than the edge slides along
    the face are counted apart (before they were beyond the zones, up to 0.88 um here)."""
    tmp, brep, faces = blade
    field = rp.around_edge_field(rp.leading_edge(faces))
    parts = [rp.sample_faces([f], k, field, seed=10 + i)
             for i, (f, k) in enumerate(zip(rp.blade_outward(faces), (2500, 2500, 200, 300)))]
    # and 8 points on each side 1 and 5 um from the trailing edge, where the 30 um
    # correction slides that edge 11.5 to 22 um into each side (delta tan(half the normals'
    # angle) for a planar wedge: about 43 to 71 deg): no corrected face lies on their
    # normal lines
    outward = rp.blade_outward(faces)
    beside = [rp.beside_edge(f, (0.22, 0.25, 0.28, 0.31), (1e-3, 5e-3)) for f in outward[:2]]
    parts += [(p, n, field(p)) for p, n in beside]
    pts, nrm, dev = (np.concatenate([p[j] for p in parts]) for j in range(3))
    csv = str(tmp / "knife.csv")
    rp.write_csv(csv, pts, nrm, dev)
    out, rep = str(tmp / "knife.brep"), str(tmp / "knife.json")
    r = _run(brep, csv, "--faces", "auto", "-o", out, "--report", rep)
    assert r.returncode == 0, r.stderr
    assert "outward normals taken against the faces' own orientation (to agree with their " \
        "neighbours'): Face2, Face3" in r.stdout
    assert "points near knife edges or vertices" in r.stdout
    data = json.load(open(rep))
    edges = data["edges"]
    assert len(edges) == 6
    sides = [e for e in edges if e["faces"] == ["Face1", "Face2"]]
    assert len(sides) == 2
    # oriented, the sides meet at 0 to 22 deg (leading edge) and 10 to 143 deg (trailing)
    assert sorted(round(e["nominal_angle_deg"]) for e in sides) == [22, 143]
    # measured (FreeCAD 0.20): beyond the nominal's gap, the trailing edge 0.0095 um, the
    # rounded edge 0.0000, the suction side - tip cap 0.0002, the pressure side - tip cap
    # 0.042 (its fold), the root cap's 0.0028 and 0.0072; the nominal faces lie 3.3 um
    # (trailing edge), 8.9, 12.3 (suction side - tip cap), 11.7, 10.7 and 10.8 um apart
    # (a wrong foot of one edge sample read 40 um before)
    bounds = {("Face1", "Face2", 143): 0.02, ("Face1", "Face2", 22): 0.001,
              ("Face1", "Face3", 14): 0.005, ("Face1", "Face4", 97): 0.01,
              ("Face2", "Face3", 179): 0.06, ("Face2", "Face4", 95): 0.015}
    for e in edges:
        key = (*e["faces"], round(e["nominal_angle_deg"]))
        assert e["max_gap_beyond_nominal_um"] <= bounds[key], e
        assert e["nominal_gap_um"] <= 13.0, e
    (trailing,) = [e for e in sides if round(e["nominal_angle_deg"]) == 143]
    assert trailing["nominal_gap_um"] == pytest.approx(3.27, abs=0.03)
    faces_rep = {f["face"]: f for f in data["faces"]}
    assert faces_rep["Face3"]["edge_zone_points"] >= 190      # the tip cap: in the zone
    # measured: 0.041, 0.053 and 0.0031 um (with 4 times the nominal's poles, 42 spanwise
    # poles on the sides, 0.311 and 0.227 um; before the second-order term of the slide
    # along a face curling next to the trailing edge 0.449 and 0.426; 1.8 and 3.5 um before
    # the edges' exactness was eased along them: the trailing edge turns from 143 to 95 deg
    # within 3.5 mm near the tip, and the displacement turned as fast)
    for name, within in (("Face1", 0.07), ("Face2", 0.08), ("Face4", 0.01)):
        f = faces_rep[name]
        assert f["edge_zone_points"] > 0
        assert f["max_realised_minus_intended_beyond_edge_zones_um"] <= within
    # the points beside the trailing edge are counted apart (region_slide.py): the check
    # reads the curl's sagitta over the rest of the slide there (measured 0.07 to 0.52 um
    # on the suction side, 0.08 to 0.63 um on the pressure side, the points 0.3 to 5.8 um
    # from the edge's sample polyline against slides of 11.5 to 21.9 um; counted beyond
    # the zones before)
    assert "points nearer to a sharp edge than the edge slides along the face" in r.stdout
    for name in ("Face1", "Face2"):
        f = faces_rep[name]
        assert f["edge_slide_points"] >= 8, f
        assert f["edge_slide_max_realised_minus_intended_um"] > 0.1
        assert f["edge_slide_max_distance_um"] < 8.0
        assert 20.0 < f["edge_slide_max_slide_um"] < 30.0
    assert faces_rep["Face3"]["edge_slide_points"] == 0
    # the 30 um inward correction exceeds the pressure side's trailing-edge curl near the
    # tip (12 to 48 um in radius at 86 to 94 % of the span): uncapped, the corrected face
    # looped over itself there (its normal turned by 179.5 deg near u 0.998, v 0.924). The
    # field is held to half the radius there (core/compensation/curl_cap.py), so no face
    # folds, and the points where the cap holds the correction short are reported
    # (measured: Face1 215, Face2 227, Face3 68 points, short by up to 25.2, 26.2 and
    # 25.9 um; the largest turns 8.0, 87.4 (u 0.951, v 0.945), 0.95 and 0.16 deg)
    assert "folds over itself" not in r.stdout
    assert "points where the face curls tighter than the correction can follow" in r.stdout
    turn = {name: f["normal_turn"] for name, f in faces_rep.items()}
    for name, most in (("Face1", 10.0), ("Face2", 90.0), ("Face3", 2.0), ("Face4", 0.5)):
        assert not turn[name]["folds"] and turn[name]["largest_normal_turn_deg"] < most
        assert not faces_rep[name]["warnings"]
    for name, (low, high) in (("Face1", (150, 300)), ("Face2", (160, 320)),
                              ("Face3", (40, 110)), ("Face4", (0, 0))):
        f = faces_rep[name]
        assert low <= f["curl_points"] <= high, f
        assert f["curl_max_shortfall_um"] <= 30.0
        assert (f["curl_max_shortfall_um"] > 20.0) == (high > 0)
