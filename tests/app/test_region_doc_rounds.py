# SPDX-License-Identifier: LGPL-2.1-or-later
"""Iterations of a region compensation in a shop document (issue 30): a second region
object stacked on the first (``--object`` naming the first), from a new measurement of the
part machined from the first round's result. Deviations are against the nominal and the
corrections add up, the same sum on both faces, so the shared G1 edge stays closed; the
users of the first round move to the second; the saved document recomputes the same; a
round on other faces, or on a Base that is not a region object, is refused."""

import os

import numpy as np
import pytest

from tests.app import region_parts as rp

#: what is left of the error on the part machined from the first round's faces
LEFT = 0.3


@pytest.fixture(scope="module")
def rounds(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("regionrounds")
    solid, tops = rp.g1_top_solid()
    path = str(tmp / "shop.FCStd")
    rp.block_document(path, solid)
    pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 2000, rp.ridge_field,
                                    seed=5)
    first, second = str(tmp / "first.csv"), str(tmp / "second.csv")
    rp.write_csv(first, pts, nrm, dev)
    rp.write_csv(second, pts, nrm, LEFT * dev)
    out1, out2 = str(tmp / "round1.FCStd"), str(tmp / "round2.FCStd")
    r1 = rp.run(path, first, "--object", "Block", "--faces", "Face1,Face2", "--replace",
                "--save", out1)
    assert r1.returncode == 0, r1.stdout + r1.stderr
    sha = rp.sha256(out1)
    r2 = rp.run(out1, second, "--object", "RegionCompensation", "--faces", "Face1,Face2",
                "--replace", "--save", out2)
    assert r2.returncode == 0, r2.stdout + r2.stderr
    assert rp.sha256(out1) == sha                     # the first round's document is untouched
    return {"tmp": tmp, "solid": solid, "pts": pts, "nrm": nrm, "dev": dev, "out1": out1,
            "out2": out2, "stdout1": r1.stdout, "stdout2": r2.stdout, "first": first,
            "second": second}


def _along_normal(solid, shape, pts, nrm, face_of):
    """Signed distance (um) of the corrected top faces from the nominal points, along
    their outward normals (negative: material removed), at the points' own (u, v): a
    corrected face keeps its nominal's parametrisation."""
    import FreeCAD

    out = np.empty(len(pts))
    for i, (p, n, k) in enumerate(zip(pts, nrm, face_of)):
        u, v = solid.Faces[k].Surface.parameter(FreeCAD.Vector(*p))
        q = shape.Faces[k].Surface.value(u, v)
        out[i] = ((q.x - p[0]) * n[0] + (q.y - p[1]) * n[1] + (q.z - p[2]) * n[2]) * 1e3
    return out


def _volume(stdout):
    line = [s for s in stdout.splitlines() if s.startswith("solid: 7 faces")][0]
    return float(line.split("volume change ")[1].split(" mm3")[0])


def test_second_round_summary(rounds):
    out = rounds["stdout2"]
    assert "round 2: stacked on RegionCompensation (the earlier rounds' correction plus this " \
           "measurement's)" in out
    assert "region compensation RegionCompensation001" in out
    assert "replaced the nominal in: Mirror.Source" in out
    assert "wrote %s" % rounds["out2"] in out
    # the corrections add up: 1.3 times the first round's volume change
    v1, v2 = _volume(rounds["stdout1"]), _volume(out)
    assert v1 == pytest.approx(-0.64, abs=0.03)
    assert v2 == pytest.approx((1 + LEFT) * v1, rel=0.01)


def test_corrections_add_up_on_both_faces(rounds):
    import FreeCAD

    doc = FreeCAD.openDocument(rounds["out2"])
    try:
        r1, r2 = doc.getObject("RegionCompensation"), doc.getObject("RegionCompensation001")
        assert r2.Base == r1 and r2.Round == 2 and r1.Round == 1
        assert r2.Label == "Block_region round 2"
        assert list(r2.RegionFaces) == ["Face1", "Face2"]
        assert doc.getObject("Mirror").Source == r2
        assert not doc.getObject("Block").Visibility and not r1.Visibility
        s1, s2 = r1.Shape.copy(), r2.Shape.copy()
        assert s2.isValid() and len(s2.Faces) == 7
        assert max(e.Tolerance for e in s2.Edges) <= 1e-4
        assert r2.MaxGap <= 0.1 and r2.MaxAngleChange <= 0.05
        # the saved document recomputes the second round from the stored fields and points
        volume = s2.Volume
        r2.touch()
        doc.recompute()
        assert "Invalid" not in r2.State
        assert r2.Shape.Volume == pytest.approx(volume, abs=1e-9)
        from surfcomp.app import replace

        replace.restore(doc, r2)
        doc.recompute()
        assert doc.getObject("Mirror").Source == r1
    finally:
        FreeCAD.closeDocument(doc.Name)
    pts, nrm, dev = rounds["pts"], rounds["nrm"], rounds["dev"]
    sel = slice(0, None, 10)
    face_of = (np.arange(len(pts)) >= len(pts) // 2).astype(int)[sel]   # 2000 per face
    d1 = _along_normal(rounds["solid"], s1, pts[sel], nrm[sel], face_of)
    d2 = _along_normal(rounds["solid"], s2, pts[sel], nrm[sel], face_of)
    ok = np.isfinite(d1) & np.isfinite(d2)
    assert ok.sum() == 400
    # the first round takes the ridge off (20 um at the common edge) ...
    ridge = dev[sel][ok] * 1e3
    # (the filter and the field's kernel smooth the ridge's flanks by up to a few um)
    miss = d1[ok] + ridge
    assert np.abs(miss).max() < 3.0 and np.sqrt(np.mean(miss ** 2)) < 1.0
    assert d1[ok].min() < -18.0
    # ... the second adds what was left: its field is LEFT times the first's (the same
    # points), so the corrected faces move by 1 + LEFT times as much
    np.testing.assert_allclose(d2[ok], (1 + LEFT) * d1[ok], atol=0.05)


def test_round_on_other_faces_is_refused(rounds):
    out1 = rounds["out1"]
    sha = rp.sha256(out1)
    bad = str(rounds["tmp"] / "bad.FCStd")
    r = rp.compensate(out1, rounds["second"], "--object", "RegionCompensation", "--faces", "Face1",
                      "--save", bad)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Block_region round 2: the region is Face1, but Base Block_region corrected " \
           "Face1,Face2 (a next round corrects what the earlier ones corrected: set --faces " \
           "to Face1,Face2)" in r.stderr
    assert not os.path.exists(bad) and rp.sha256(out1) == sha


def test_base_must_be_a_region_object(rounds):
    import FreeCAD

    from surfcomp.app import features, region_doc
    from surfcomp.errors import InputError

    doc = FreeCAD.openDocument(rounds["out1"])
    try:
        r1, block = doc.getObject("RegionCompensation"), doc.getObject("Block")
        meas = features.make_measurement(doc, rounds["second"])
        with pytest.raises(InputError, match="Mirror is not a surfcomp region compensation"):
            region_doc.make_region(doc, block, "Face1,Face2", meas,
                                   base=doc.getObject("Mirror"))
        other = doc.addObject("Part::Feature", "Other")
        other.Shape = block.Shape.copy()
        n = len(doc.Objects)
        with pytest.raises(InputError, match="Block_region compensates Block, not Other "
                                             r"\(iterations must compensate the same nominal"):
            region_doc.make_region(doc, other, "Face1,Face2", meas, base=r1)
        assert len(doc.Objects) == n                 # nothing half made
        r2 = region_doc.make_region(doc, other, "Face1,Face2", meas)
        r2.Base = r1                                 # set afterwards: the recompute refuses
        with pytest.raises(InputError, match="Base Block_region compensates Block, not Other "
                                             r"\(iterations must compensate the same nominal"):
            region_doc.compute(r2)
        r2.Base = None
        r1.Base = r1
        with pytest.raises(InputError, match="the Base chain has a cycle"):
            region_doc.chain(r1)
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_a_field_kept_as_arrays_gives_the_same_values():
    from surfcomp.core.compensation.region_field import RegionField
    from surfcomp.core.compensation.region_rounds import (
        StackedField,
        field_arrays,
        field_from_arrays,
    )
    from surfcomp.errors import InputError

    rng = np.random.default_rng(7)
    pts = rng.uniform(0, 20, (3000, 3)) * [1, 0.5, 0.1]
    values = 0.02 * np.sin(pts[:, 0] / 3.0)
    field = RegionField(pts, values, 1.5)
    again = field_from_arrays(**field_arrays(field))
    # near the points, between them and far beyond them (the fallback kernels, the mean)
    x = np.vstack([pts[:200] + 0.1, rng.uniform(-50, 70, (200, 3))])
    np.testing.assert_array_equal(again(x), field(x))
    other = RegionField(pts, np.full(len(pts), 0.005), 2.0)
    np.testing.assert_allclose(StackedField([field], other)(x), field(x) + 0.005, atol=1e-15)
    arrays = field_arrays(field)
    arrays["weights"] = arrays["weights"][:-1]
    with pytest.raises(InputError, match="Round1 holds no usable correction field"):
        field_from_arrays(**arrays, source="Round1")


def test_a_region_object_of_version_1_opens_and_is_refused_as_base_until_recomputed(rounds):
    import FreeCAD

    old = str(rounds["tmp"] / "version1.FCStd")
    doc = FreeCAD.openDocument(rounds["out1"])
    try:
        r1 = doc.getObject("RegionCompensation")
        for name in ("Round", "AlignMatrix", "Alignment", "FieldCentres", "FieldValues",
                     "FieldWeights", "FieldMean", "FieldRadius"):
            r1.removeProperty(name)
        r1.Version = 1
        r1.setEditorMode("Base", 3)
        doc.saveAs(old)
    finally:
        FreeCAD.closeDocument(doc.Name)
    doc = FreeCAD.openDocument(old)
    try:
        r1 = doc.getObject("RegionCompensation")
        assert r1.Version == 2 and r1.Round == 1 and list(r1.FieldCentres) == []
        assert r1.getEditorMode("Base") == []
    finally:
        FreeCAD.closeDocument(doc.Name)
    sha = rp.sha256(old)
    bad = str(rounds["tmp"] / "on_version1.FCStd")
    r = rp.compensate(old, rounds["second"], "--object", "RegionCompensation",
                      "--faces", "Face1,Face2",
                      "--save", bad)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "Block_region holds no correction field to stack on (not computed, or saved by an " \
           "earlier surfcomp): recompute it first" in r.stderr
    assert not os.path.exists(bad) and rp.sha256(old) == sha
