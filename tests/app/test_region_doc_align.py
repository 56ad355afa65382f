# SPDX-License-Identifier: LGPL-2.1-or-later
"""Alignment on the region document route (issue 30): measured points of a block whose two
G1 top faces carry a 20 um ridge, probed in another frame (moved by 2 degrees and half a
millimetre), brought back by a best fit on the block's planar datum faces or by the known
transform; the region then corrects what it corrects from points in the nominal's frame.
A best fit on the region's own faces says what it absorbed; bad alignment input exits 2
and writes nothing."""

import json
import os

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from surfcomp.core.measurement import align
from tests.app import region_parts as rp

#: the measuring frame: nominal -> measured
MOVE = align.rigid(Rotation.from_euler("xyz", [1.0, -0.5, 2.0], degrees=True).as_matrix(),
                   [0.5, -0.3, 0.2])
DATUM = "Face3,Face4,Face5,Face6,Face7"


def _volume(stdout):
    line = [s for s in stdout.splitlines() if s.startswith("solid: 7 faces")][0]
    return float(line.split("volume change ")[1].split(" mm3")[0])


@pytest.fixture(scope="module")
def shop(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("regionalign")
    solid, tops = rp.g1_top_solid()
    path = str(tmp / "shop.FCStd")
    rp.block_document(path, solid, mirror=False)
    pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 2000, rp.ridge_field,
                                    seed=11)
    nominal_csv = str(tmp / "nominal.csv")
    rp.write_csv(nominal_csv, pts, nrm, dev)
    walls = [f for k, f in enumerate(solid.Faces) if k not in tops]
    datum, _n, _d = rp.sample_faces(walls, 150, lambda p: np.zeros(len(p)), seed=12)
    top = pts + nrm * dev[:, None]                      # where the part's faces are
    files = {}
    for name, points in (("all", np.vstack([top, datum])), ("tops", top)):
        path_xyz = tmp / ("%s.xyz" % name)
        np.savetxt(path_xyz, align.apply(MOVE, points), fmt="%.10f", header="x y z",
                   comments="")
        files[name] = str(path_xyz)
    back = tmp / "back.json"
    back.write_text(json.dumps({"matrix": np.linalg.inv(MOVE).tolist()}))
    ref = rp.run(path, nominal_csv, "--object", "Block", "--faces", "Face1,Face2", "--save",
                 tmp / "ref.FCStd")
    assert ref.returncode == 0, ref.stderr
    return {"tmp": tmp, "doc": path, "files": files, "back": str(back), "csv": nominal_csv,
            "reference": _volume(ref.stdout), "datum_points": len(datum)}


def _region(out):
    import FreeCAD

    doc = FreeCAD.openDocument(out)
    try:
        reg = doc.getObject("RegionCompensation")
        meas = doc.getObject("Measurement")
        return {"matrix": np.reshape(reg.AlignMatrix, (4, 4)), "lines": list(reg.Alignment),
                "points": list(reg.PointsPerFace), "none": reg.PointsOnNoFace,
                "method": meas.AlignMethod, "faces": meas.AlignFaces,
                "report": json.loads(reg.Report)}
    finally:
        FreeCAD.closeDocument(doc.Name)


def test_bestfit_on_datum_faces_brings_the_points_back(shop):
    tmp = shop["tmp"]
    sha = rp.sha256(shop["doc"])
    out = tmp / "datum.FCStd"
    r = rp.run(shop["doc"], shop["files"]["all"], "--object", "Block",
               "--faces", "Face1,Face2",
               "--align", "bestfit", "--align-faces", DATUM, "--save", out)
    assert r.returncode == 0, r.stdout + r.stderr
    assert rp.sha256(shop["doc"]) == sha
    assert "Alignment:    bestfit: translation" in r.stdout
    assert "best fit on %s" % DATUM.replace(",", ", ") in r.stdout
    assert "iterations, converged" in r.stdout
    assert "%d point(s) on the datum faces served the alignment only; the deviations are " \
           "those of the 4000 point(s) on the region" % shop["datum_points"] in r.stderr
    assert "points per face: Face1 2000, Face2 2000; on no face: 0" in r.stdout
    # the region corrects the ridge as from points in the nominal's frame
    assert _volume(r.stdout) == pytest.approx(shop["reference"], rel=0.01)
    reg = _region(str(out))
    assert_allclose(reg["matrix"], np.linalg.inv(MOVE), atol=2e-5)
    assert reg["method"] == "bestfit" and reg["faces"] == DATUM
    assert reg["points"] == ["Face1 2000", "Face2 2000"] and reg["none"] == 0
    a = reg["report"]["alignment"]
    assert a["converged"] and a["absorbed"] is None
    # the datum faces are met; the region's faces keep their ridge (about 6 um RMS)
    rms = a["rms_after_um"]
    assert max(rms["Face%d" % k] for k in range(3, 8)) < 0.1
    assert 3.0 < rms["Face1"] < 10.0 and 3.0 < rms["Face2"] < 10.0
    assert reg["lines"][0].startswith("Alignment:    bestfit")


def test_known_transform_alone_works_with_faces_auto(shop):
    out = shop["tmp"] / "known.FCStd"
    r = rp.run(shop["doc"], shop["files"]["tops"], "--object", "Block", "--faces", "auto",
               "--transform", shop["back"], "--save", out)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "points per face: Face1 2000, Face2 2000; on no face: 0" in r.stdout
    assert _volume(r.stdout) == pytest.approx(shop["reference"], rel=0.005)
    reg = _region(str(out))
    assert_allclose(reg["matrix"], np.linalg.inv(MOVE), atol=1e-12)
    assert reg["report"]["alignment"]["method"] == "none"


def test_bestfit_on_the_region_itself_says_what_it_absorbed(shop):
    out = shop["tmp"] / "self.FCStd"
    r = rp.run(shop["doc"], shop["files"]["tops"], "--object", "Block",
               "--faces", "Face1,Face2",
               "--align", "bestfit", "--align-dof", "z,rx,ry", "--transform", shop["back"],
               "--save", out)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "warning: the best fit used the region's faces themselves: it absorbed a mean " \
           "offset of" in r.stderr
    a = _region(str(out))["report"]["alignment"]
    absorbed = a["absorbed"]
    assert "absorbed a mean offset of %.3f um and a tilt of %.3f um" \
        % (absorbed["mean_offset_um"], absorbed["tilt_um"]) in r.stderr
    assert "(name datum faces with --align-faces to keep it)" in r.stderr
    assert a["faces"] == ["Face1", "Face2"] and a["dof"] == ["z", "rx", "ry"]
    # the summary speaks of the region, not of one face
    assert absorbed["where"] == "region"
    assert "absorbed on the compensated region: mean offset %.3f um" \
        % absorbed["mean_offset_um"] in r.stdout
    # the robust fit weighs most of the ridge out, so it takes little of it: the deviations
    # change by the absorbed shift, and the volume removed by that shift over the 200 mm^2
    assert a["outliers"] > 500
    shift = absorbed["mean_offset_um"] * 1e-3 * 200.0
    assert _volume(r.stdout) == pytest.approx(shop["reference"] - shift, abs=0.004)


def test_bad_alignment_input_exits_2_and_writes_nothing(shop):
    tmp, doc = shop["tmp"], shop["doc"]
    sha = rp.sha256(doc)
    out = tmp / "bad.FCStd"
    cases = [
        (shop["files"]["all"], ("--faces", "auto", "--align", "bestfit", "--align-faces",
                                DATUM), "--align bestfit with --faces auto: give the region's "
                                        "FaceN names instead of auto"),
        (shop["csv"], ("--faces", "Face1,Face2", "--align", "bestfit"),
         "which are already in the nominal's frame"),
        (shop["files"]["all"], ("--faces", "Face1,Face2", "--align", "rps"),
         "needs --rps"),
    ]
    for meas, extra, message in cases:
        r = rp.compensate(doc, meas, "--object", "Block", *extra, "--save", out)
        assert r.returncode == 2, r.stdout + r.stderr
        assert message in r.stderr, r.stderr
        assert not os.path.exists(out) and rp.sha256(doc) == sha
    # the file route of --faces has no alignment: refused, not ignored
    r = rp.compensate(doc, shop["files"]["tops"], "--object", "Block", "--faces", "Face1,Face2",
                      "--transform", shop["back"], "-o", tmp / "bad.step")
    assert r.returncode == 2 and "--transform cannot be combined with --faces -o" in r.stderr
    assert not os.path.exists(tmp / "bad.step")
