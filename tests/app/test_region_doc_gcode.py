# SPDX-License-Identifier: LGPL-2.1-or-later
"""A region compensated in a shop document with a Path Job, and the Job's program posted
(issue 30): ``compensate DOC.FCStd MEAS --object Block --faces Face1,Face2 --replace --save
OUT.FCStd --gcode OUT.ngc``. The two G1 top faces of a block carry a 20 um ridge along their
common edge; a 3D Surface operation (6 mm ball end mill) runs over both. The posted program,
read by LinuxCNC's rs274, goes down by the correction where the ridge is and stays where
there is none; the summary's claims (operation regenerated, files written) are checked
against the files."""

import os

import numpy as np
import pytest
from scipy.spatial import cKDTree

from tests.app import region_parts as rp
from tests.pure.test_gcode_rs274 import rs274

POST_ARGS = "--no-show-editor --no-header --precision=4"
R = 3.0                     # the ball end mill's radius (mm)


@pytest.fixture(scope="module")
def shop(tmp_path_factory):
    import FreeCAD

    from surfcomp.app import cam, cam_job

    tmp = tmp_path_factory.mktemp("regiongcode")
    cam.setup_workbench()
    solid, tops = rp.g1_top_solid()
    assert tops == [0, 1]
    doc = FreeCAD.newDocument("regiongcode")
    try:
        block = doc.addObject("Part::Feature", "Block")
        block.Shape = solid
        doc.recompute()
        job = cam_job.create_job(doc, [block])
        tc = cam_job.ball_end_tool_controller(job, 2 * R)
        cam_job.surface_operation(job, block, ["Face1", "Face2"], tc, step_over=10.0,
                                  sample_interval=0.25, linear_deflection=0.001)
        doc.recompute()
        cam_job.model_clone(job, block).touch()      # settle Path's stock box
        doc.recompute()
        nominal_program = cam_job.post_process(job, "linuxcnc", POST_ARGS)
        path = str(tmp / "shop.FCStd")
        doc.saveAs(path)
    finally:
        FreeCAD.closeDocument(doc.Name)
    pts, nrm, dev = rp.sample_faces([solid.Faces[k] for k in tops], 3000, rp.ridge_field,
                                    seed=3)
    csv = str(tmp / "ridge.csv")
    rp.write_csv(csv, pts, nrm, dev)
    nominal_ngc = tmp / "nominal.ngc"
    nominal_ngc.write_text(nominal_program)
    return tmp, path, csv, solid, nominal_ngc


@pytest.fixture(scope="module")
def posted(shop):
    tmp, path, csv, _solid, _nominal = shop
    sha = rp.sha256(path)
    out, ngc = str(tmp / "out.FCStd"), str(tmp / "out.ngc")
    r = rp.run(path, csv, "--object", "Block",
               "--faces", "Face1,Face2", "--replace", "--save",
               out, "--gcode", ngc, "--post", "linuxcnc", "--post-args", POST_ARGS)
    assert rp.sha256(path) == sha                 # the input document is untouched
    assert r.returncode == 0, r.stdout + r.stderr
    return out, ngc, r.stdout


def feed_ends(path, tmp_path):
    moves, _raw = rs274(path, tmp_path)
    return np.array([m["end"] for m in moves if m["kind"] == "STRAIGHT_FEED"])


def contact_correction(solid, tips):
    """The ridge at the ball's contact with the nominal top faces and the normal's z there,
    for tool tips ``tips`` (N, 3) of the nominal program."""
    import FreeCAD

    out = []
    for tip in tips:
        centre = FreeCAD.Vector(*tip) + FreeCAD.Vector(0, 0, R)
        best = None
        for face in solid.Faces[:2]:
            u, v = face.Surface.parameter(centre)
            p = face.Surface.value(u, v)
            if not face.isPartOfDomain(u, v):
                continue
            d = (p - centre).Length
            if best is None or d < best[0]:
                n = face.normalAt(u, v)
                best = (d, p, n)
        out.append((float(rp.ridge_field(np.array([tuple(best[1])]))[0]), best[2].z)
                   if best and abs(best[0] - R) < 1e-3 else (np.nan, np.nan))
    return np.array(out)


def test_summary_claims_are_true(posted):
    out, ngc, stdout = posted
    assert "replaced the nominal in: Clone.Objects" in stdout
    line = [s for s in stdout.splitlines() if "Surface regenerated (" in s]
    assert len(line) == 1, stdout
    changed, total = (int(x) for x in line[0].split("(")[1].split(" commands")[0].split(" of "))
    assert 0 < changed <= total
    assert "wrote %s" % os.path.abspath(out) in stdout and os.path.isfile(out)
    with open(ngc) as fh:
        lines = fh.read().count("\n")
    assert "wrote %s (%d lines)" % (ngc, lines) in stdout.splitlines()


def test_program_goes_down_by_the_correction_along_the_ridge(shop, posted, tmp_path):
    _tmp, _path, _csv, solid, nominal_ngc = shop
    _out, ngc, _stdout = posted
    a = feed_ends(str(nominal_ngc), tmp_path)
    b = feed_ends(ngc, tmp_path)
    assert len(a) > 250 and abs(len(a) - len(b)) <= 0.02 * len(a)
    d, k = cKDTree(b[:, :2]).query(a[:, :2])
    same = d < 1e-4                          # the same drop-cutter sample in XY
    assert same.mean() > 0.95
    a, dz = a[same], (b[k[same], 2] - a[same, 2]) * 1e3       # um
    on = (a[:, 0] > 1.0) & (a[:, 0] < 19.0) & (a[:, 1] > 1.0) & (a[:, 1] < 9.0)
    ridge, nz = contact_correction(solid, a[on]).T
    ok = np.isfinite(ridge)
    assert ok.sum() > 100
    expected = -ridge[ok] * 1e3 / nz[ok]
    # where the ridge is, the tool goes down by it (20 um at the common edge)
    big = expected < -10.0
    assert big.sum() > 20
    assert dz[on][ok][big].min() < -18.0
    np.testing.assert_allclose(dz[on][ok], expected, atol=2.0)
    # no correction, no move: the tips whose contact the ridge does not reach
    quiet = np.abs(expected) < 0.2
    assert quiet.sum() > 20
    assert np.abs(dz[on][ok][quiet]).max() <= 2.0


def test_posted_program_is_the_saved_documents(posted):
    import FreeCAD

    from surfcomp.app import cam, cam_job

    out, ngc, _stdout = posted
    cam.setup_workbench()
    doc = FreeCAD.openDocument(out)
    try:
        job = doc.getObject("Job")
        region = doc.getObject("RegionCompensation")
        assert doc.getObject("Clone").Objects == [region]
        again = cam_job.post_process(job, "linuxcnc", POST_ARGS)
    finally:
        FreeCAD.closeDocument(doc.Name)
    with open(ngc) as fh:
        text = fh.read()
    a = [s for s in text.splitlines() if not s.startswith("G1 ")]
    b = [s for s in again.splitlines() if not s.startswith("G1 ")]
    assert a == b and text.count("\nG1 ") == again.count("\nG1 ") > 250


def test_gcode_without_a_job_using_the_region_exits_2_and_writes_nothing(shop):
    tmp, path, csv, *_ = shop
    sha = rp.sha256(path)
    out, ngc = str(tmp / "nojob.FCStd"), str(tmp / "nojob.ngc")
    # without --replace no Job uses the region object: nothing to post
    r = rp.compensate(path, csv, "--object", "Block", "--faces", "Face1,Face2", "--save", out,
                      "--gcode", ngc)
    assert r.returncode == 2, r.stdout + r.stderr
    assert "no Path jobs use the compensation" in r.stderr
    assert not os.path.exists(out) and not os.path.exists(ngc) and rp.sha256(path) == sha
    r = rp.compensate(path, csv, "--object", "Block", "--faces", "Face1,Face2", "--gcode", ngc)
    assert r.returncode == 2 and "needs --save OUT.FCStd" in r.stderr
    assert not os.path.exists(ngc) and rp.sha256(path) == sha
