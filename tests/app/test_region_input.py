# SPDX-License-Identifier: LGPL-2.1-or-later
"""Region input the route must not take silently (issue 30): points beyond a face's own
border, a measurement no face takes (other units or frame), options out of their domain and
options of one face that a region does not read. Refused runs exit 2 and write nothing."""

import os

import numpy as np
import pytest

from tests.app import region_parts as rp


@pytest.fixture(scope="module")
def part(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("region_input")
    step, csv, _solid, pts, nrm, dev = rp.g1_step(tmp, 1500, seed=4)
    return tmp, step, csv, pts, nrm, dev


def test_points_beyond_the_border_of_a_face_are_on_no_face(part):
    """40 readings of 50 um 0.3 mm beside the top's edge y = 0 (in the air, beyond the
    faces' own border: their nearest point is the edge, not a foot on the face) were
    counted on Face1 and Face2 and bent the correction there."""
    tmp, step, _csv, pts, nrm, dev = part
    xs = np.linspace(1.0, 19.0, 40)
    beside = np.array([[x, -0.3, rp._h(x, -0.3)] for x in xs])
    csv = str(tmp / "beside.csv")
    rp.write_csv(csv, np.concatenate([pts, beside]),
                 np.concatenate([nrm, np.tile([0.0, 0.0, 1.0], (40, 1))]),
                 np.concatenate([dev, np.full(40, 0.05)]))
    r = rp.run(step, csv, "--faces", "Face1,Face2", "-o", str(tmp / "beside.step"))
    assert r.returncode == 0, r.stderr
    assert "points per face: Face1 1500, Face2 1500; on no face: 40" in r.stdout, r.stdout


@pytest.mark.parametrize("faces", ["auto", "Face1,Face2"])
def test_points_in_other_units_are_refused_naming_the_faces(part, faces):
    """The file's millimetres read as inches lie far from every face: refused as input
    (auto: no face's box held a point, and the run failed with an internal error)."""
    tmp, step, csv, *_ = part
    out = str(tmp / "inch.step")
    r = rp.compensate(step, csv, "--faces", faces, "--units", "in", "-o", out)
    assert r.returncode == 2, r.stderr
    assert "internal error" not in r.stderr
    want = ("--faces auto: no face of the shape has 10 points" if faces == "auto"
            else "none of Face1, Face2 has a point")
    assert want + " within --max-offset 1 mm" in r.stderr, r.stderr
    assert "units or alignment?" in r.stderr
    assert not os.path.exists(out)


@pytest.mark.parametrize("extra, message", [
    (["--max-offset", "-1"], "--max-offset -1.0: expected a length in mm"),
    (["--smoothing", "-1"], "--smoothing -1.0: expected a length in mm"),
    (["--mask", "4"], "--mask 4: expected an odd whole number"),
    (["--plan", "PLAN"], "--plan cannot be combined with --faces"),
    (["--layout", "grid"], "--layout cannot be combined with --faces"),
    (["--edge", "reflect"], "--edge cannot be combined with --faces"),
    (["--refine", "3"], "--refine cannot be combined with --faces"),
    (["--accept-stock"], "--accept-stock cannot be combined with --faces"),
    (["--max-memory", "64M"], "compensate of 3000 points needs about"),
    (["--object", "Block"], "--object applies to FCStd documents only"),
])
def test_bad_or_unread_options_exit_2_and_write_nothing(part, extra, message):
    """Out of their domain these options crashed the run (exit 1) or were taken (an even
    mask); the options of one face that a region does not read, and --max-memory, were
    ignored without a word; --object was ignored too (a STEP file has no objects)."""
    tmp, step, csv, *_ = part
    out = str(tmp / "refused.step")
    r = rp.compensate(step, csv, "--faces", "auto", "-o", out,
                      *[csv if a == "PLAN" else a for a in extra])
    assert r.returncode == 2, r.stderr
    assert message in r.stderr, r.stderr
    assert not os.path.exists(out)


def test_normals_far_off_their_face_are_reported(part):
    """One face reports a given normal more than 5 degrees off the face normal; a region
    took any (the deviation is taken along it, turned to the outward side, whatever the
    angle). 12 normals of Face1's points turned 30 degrees about x: 10 named by line, the
    rest counted."""
    tmp, step, _csv, pts, nrm, dev = part
    turned = nrm.copy()
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    on_face1 = np.flatnonzero(pts[:, 0] < 9.0)[:12]
    turned[on_face1] = turned[on_face1] @ rot.T
    csv = str(tmp / "turned.csv")
    rp.write_csv(csv, pts, turned, dev)
    r = rp.run(step, csv, "--faces", "Face1,Face2", "-o", str(tmp / "turned.step"))
    assert r.returncode == 0, r.stderr
    said = [ln for ln in r.stdout.splitlines() if "degrees off" in ln]
    assert len(said) == 11, r.stdout
    assert all(ln.startswith("warning: %s:" % csv) for ln in said), said
    assert "the given normal is 30.0 degrees off the normal of Face1 (more than 5)" in said[0]
    assert said[-1] == ("warning: %s: 2 more normals are more than 5 degrees off their "
                        "face's normal" % csv)
